//! Graph colouring of elements for parallel projection: elements that share a node never get
//! the same colour, so the elements of one colour can be projected concurrently without two
//! threads touching the same node. Greedy colouring in element order (each element takes the
//! smallest colour none of its node-neighbours has): deterministic, and close to the maximum
//! number of elements around a node.

use crate::mesh::ElementBlock;

/// The elements of `block` grouped by colour (element indices in increasing order per colour).
pub fn colour_elements(block: &ElementBlock, num_nodes: usize) -> Vec<Vec<u32>> {
    // node → elements
    let mut start = vec![0usize; num_nodes + 1];
    for el in block.elements() {
        for &n in el {
            start[n as usize + 1] += 1;
        }
    }
    for i in 0..num_nodes {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut adjacent = vec![0u32; start[num_nodes]];
    for (e, el) in block.elements().enumerate() {
        for &n in el {
            adjacent[fill[n as usize]] = e as u32;
            fill[n as usize] += 1;
        }
    }
    crate::mesh::adjacency::greedy_colours(block.len(), |e, neighbour| {
        for &n in block.element(e) {
            for &other in &adjacent[start[n as usize]..start[n as usize + 1]] {
                neighbour(other);
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::element::ElementType;
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    #[test]
    fn elements_of_one_colour_share_no_node_and_every_element_is_coloured_once() {
        for et in ElementType::all() {
            let mesh = BoxMeshSpec {
                grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [6, 3, 3] },
                element_type: et,
                split: TetSplit::Five,
                refine: 0,
            }
            .build()
            .unwrap();
            let block = &mesh.blocks[0];
            let colours = colour_elements(block, mesh.num_nodes());
            let mut seen = vec![0; block.len()];
            for colour in &colours {
                let mut owner = vec![false; mesh.num_nodes()];
                for &e in colour {
                    seen[e as usize] += 1;
                    for &n in block.element(e as usize) {
                        assert!(!owner[n as usize], "{et}: node {n} twice in one colour");
                        owner[n as usize] = true;
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{et}");
            assert!(colours.len() < 80, "{et}: {} colours", colours.len());
        }
    }
}
