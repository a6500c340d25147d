//! Which elements hold each node, and a colouring of the nodes such that no two nodes of one
//! colour share an element: the layout a per-node solver walks (vertex block descent, Chen et
//! al., "Vertex Block Descent", SIGGRAPH 2024, §3.3: nodes of one colour are updated in parallel
//! because none of them moves an element another one reads).
//!
//! [`NodeIncidence`] is a compressed list over the global nodes and every block (a mixed mesh's
//! blocks share nodes), in (block, element) order; each entry names the element and the node's
//! index in it, so the element's gradients `∇_X N_local(r_q)` are found without a search.

use super::Mesh;

/// One element holding a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Incidence {
    pub element: u32,
    pub block: u16,
    /// The node's index within the element (its Gmsh local number).
    pub local: u16,
}

/// For every node, the elements holding it.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeIncidence {
    /// `items[start[i] .. start[i + 1]]` hold node `i`.
    start: Vec<u32>,
    items: Vec<Incidence>,
}

impl NodeIncidence {
    pub fn new(mesh: &Mesh) -> NodeIncidence {
        let n = mesh.num_nodes();
        let mut count = vec![0u32; n + 1];
        for block in &mesh.blocks {
            for &node in &block.connectivity {
                count[node as usize + 1] += 1;
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let start = count.clone();
        let mut next = count;
        let mut items = vec![Incidence { element: 0, block: 0, local: 0 }; start[n] as usize];
        for (b, block) in mesh.blocks.iter().enumerate() {
            for (e, nodes) in block.elements().enumerate() {
                for (local, &node) in nodes.iter().enumerate() {
                    let slot = &mut next[node as usize];
                    items[*slot as usize] = Incidence { element: e as u32, block: b as u16, local: local as u16 };
                    *slot += 1;
                }
            }
        }
        NodeIncidence { start, items }
    }

    pub fn num_nodes(&self) -> usize {
        self.start.len() - 1
    }

    /// The elements holding `node`, in (block, element) order.
    pub fn of(&self, node: usize) -> &[Incidence] {
        &self.items[self.start[node] as usize..self.start[node + 1] as usize]
    }
}

/// Nodes by colour: a node takes the smallest colour that no other node of any element holding
/// it has (greedy, in node order, so the colouring is deterministic). Every node is coloured,
/// clamped ones too (a solver skips them), so a change of what is clamped needs no new colouring.
pub fn colour_nodes(mesh: &Mesh, incidence: &NodeIncidence) -> Vec<Vec<u32>> {
    greedy_colours(mesh.num_nodes(), |node, neighbour| {
        for inc in incidence.of(node) {
            for &other in mesh.blocks[inc.block as usize].element(inc.element as usize) {
                neighbour(other);
            }
        }
    })
}

/// Greedy graph colouring of the items `0..count`, in order: each takes the smallest colour that
/// none of its already coloured neighbours has (`neighbours(i, visit)` calls `visit` on each
/// neighbour of `i`; visiting `i` itself is harmless). Returns the items by colour, each list in
/// increasing order. Deterministic; at most one more colour than the largest neighbourhood.
pub fn greedy_colours(count: usize, mut neighbours: impl FnMut(usize, &mut dyn FnMut(u32))) -> Vec<Vec<u32>> {
    let mut colour_of = vec![u32::MAX; count];
    let mut taken: Vec<bool> = Vec::new();
    let mut colours: Vec<Vec<u32>> = Vec::new();
    for item in 0..count {
        taken.iter_mut().for_each(|t| *t = false);
        neighbours(item, &mut |other| {
            let c = colour_of[other as usize];
            if c != u32::MAX {
                taken[c as usize] = true;
            }
        });
        let c = taken.iter().position(|t| !t).unwrap_or(taken.len());
        if c == taken.len() {
            taken.push(false);
            colours.push(Vec::new());
        }
        colour_of[item] = c as u32;
        colours[c].push(item as u32);
    }
    colours
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::element::ElementType;
    use crate::mesh::ElementBlock;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    fn box_mesh(et: ElementType) -> Mesh {
        BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 1.0, 1.0), cells: [6, 3, 3] },
            element_type: et,
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap()
    }

    fn check(mesh: &Mesh, what: &str) {
        let incidence = NodeIncidence::new(mesh);
        // every (element, local node) once, under the right node
        let total: usize = mesh.blocks.iter().map(|b| b.connectivity.len()).sum();
        assert_eq!((0..mesh.num_nodes()).map(|i| incidence.of(i).len()).sum::<usize>(), total, "{what}");
        for node in 0..mesh.num_nodes() {
            for inc in incidence.of(node) {
                let nodes = mesh.blocks[inc.block as usize].element(inc.element as usize);
                assert_eq!(nodes[inc.local as usize] as usize, node, "{what}");
            }
        }
        let colours = colour_nodes(mesh, &incidence);
        let mut seen = vec![usize::MAX; mesh.num_nodes()];
        for (c, nodes) in colours.iter().enumerate() {
            for &n in nodes {
                assert_eq!(seen[n as usize], usize::MAX, "{what}: node {n} coloured twice");
                seen[n as usize] = c;
            }
        }
        assert!(seen.iter().all(|&c| c != usize::MAX), "{what}: a node without colour");
        for block in &mesh.blocks {
            for nodes in block.elements() {
                let mut cs: Vec<usize> = nodes.iter().map(|&n| seen[n as usize]).collect();
                cs.sort_unstable();
                cs.dedup();
                assert_eq!(cs.len(), nodes.len(), "{what}: two nodes of one element share a colour");
            }
        }
        assert!(colours.len() < 200, "{what}: {} colours", colours.len());
    }

    /// No two nodes of one element share a colour, every node has exactly one, and the incidence
    /// list finds each node at its place in every element holding it: every element type, and a
    /// mesh mixing blocks that share nodes.
    #[test]
    fn node_colours_never_hold_two_nodes_of_one_element() {
        for et in ElementType::all() {
            check(&box_mesh(et), et.name());
        }
        // two blocks sharing nodes: the P1 box's elements split into two blocks
        let p1 = box_mesh(ElementType::from_name("p1").unwrap());
        let c = &p1.blocks[0].connectivity;
        let half = c.len() / 8 * 4;
        let mixed = Mesh {
            rest_positions: p1.rest_positions.clone(),
            blocks: vec![
                ElementBlock::new(p1.blocks[0].element_type, c[..half].to_vec()),
                ElementBlock::new(p1.blocks[0].element_type, c[half..].to_vec()),
            ],
        };
        check(&mixed, "two P1 blocks");
    }
}
