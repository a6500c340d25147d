//! Meshes: rest node positions and blocks of elements of one type each (a mesh may mix types).
//!
//! Connectivity uses the element's Gmsh node order ([`crate::element`]). [`structured`] builds
//! the paper's beams; [`high_order`] adds shared edge/face/interior nodes to linear meshes;
//! [`adjacency`] lists the elements holding each node and colours the nodes. Mesh
//! files (Gmsh import, VTK export) are in [`crate::io`]. This room reads only the reference
//! elements: element shape (inverted or flat at rest) is checked by `crate::fem::geometry`,
//! which reads meshes, not the other way round.

pub mod adjacency;
pub mod high_order;
pub mod structured;

use crate::Vec3;
use crate::element::ElementType;
use std::collections::HashMap;

/// Elements of one type: `connectivity[e * n .. (e + 1) * n]` are element `e`'s nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementBlock {
    pub element_type: ElementType,
    pub connectivity: Vec<u32>,
}

impl ElementBlock {
    pub fn new(element_type: ElementType, connectivity: Vec<u32>) -> Self {
        Self { element_type, connectivity }
    }
    pub fn nodes_per_element(&self) -> usize {
        self.element_type.num_nodes()
    }
    pub fn len(&self) -> usize {
        self.connectivity.len() / self.nodes_per_element()
    }
    pub fn is_empty(&self) -> bool {
        self.connectivity.is_empty()
    }
    /// The node indices of element `e`.
    pub fn element(&self, e: usize) -> &[u32] {
        let n = self.nodes_per_element();
        &self.connectivity[e * n..(e + 1) * n]
    }
    pub fn elements(&self) -> std::slice::ChunksExact<'_, u32> {
        self.connectivity.chunks_exact(self.nodes_per_element())
    }
}

/// A volume mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Rest (material) positions `X`, metres.
    pub rest_positions: Vec<Vec3>,
    pub blocks: Vec<ElementBlock>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("the mesh has no elements")]
    Empty,
    #[error("element {element} of the {element_type} block refers to node {node}, but the mesh has {num_nodes} nodes")]
    NodeOutOfRange { element_type: String, element: usize, node: u32, num_nodes: usize },
    #[error(
        "the {element_type} block's connectivity has {len} entries, not a multiple of {per_element} nodes per element"
    )]
    RaggedConnectivity { element_type: String, len: usize, per_element: usize },
    #[error("node {node} has a non-finite coordinate {position:?}")]
    NonFiniteNode { node: usize, position: [f64; 3] },
    #[error("element {element} of the {element_type} block uses node {node} twice")]
    RepeatedNode { element_type: String, element: usize, node: u32 },
    #[error("invalid mesh request: {0}")]
    InvalidRequest(String),
}

impl Mesh {
    pub fn num_nodes(&self) -> usize {
        self.rest_positions.len()
    }

    pub fn num_elements(&self) -> usize {
        self.blocks.iter().map(ElementBlock::len).sum()
    }

    /// Checks the structure: non-empty, finite coordinates, indices in range, no repeated node
    /// within an element. (Element shape — inverted or flat — is checked by
    /// `crate::fem::geometry`, which knows the quadrature points.)
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.num_elements() == 0 {
            return Err(MeshError::Empty);
        }
        for (node, p) in self.rest_positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(MeshError::NonFiniteNode { node, position: [p.x, p.y, p.z] });
            }
        }
        let num_nodes = self.num_nodes();
        for b in &self.blocks {
            let per_element = b.nodes_per_element();
            if b.connectivity.len() % per_element != 0 {
                return Err(MeshError::RaggedConnectivity {
                    element_type: b.element_type.to_string(),
                    len: b.connectivity.len(),
                    per_element,
                });
            }
            for (element, nodes) in b.elements().enumerate() {
                for (k, &node) in nodes.iter().enumerate() {
                    if node as usize >= num_nodes {
                        return Err(MeshError::NodeOutOfRange {
                            element_type: b.element_type.to_string(),
                            element,
                            node,
                            num_nodes,
                        });
                    }
                    if nodes[..k].contains(&node) {
                        return Err(MeshError::RepeatedNode {
                            element_type: b.element_type.to_string(),
                            element,
                            node,
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Axis-aligned bounding box of the rest positions `(min, max)`.
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in &self.rest_positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// The same mesh with its nodes renumbered in order of their rest coordinate along the
    /// longest axis of the bounding box (nodes at the same coordinate keep their order); the
    /// elements and their order are unchanged.
    ///
    /// The XPBD colour sweep cuts a block into slabs along that axis
    /// ([`crate::xpbd::kernels::slab_count`]), and its node passes (prediction, velocities,
    /// the finite check) cut the nodes by index: numbered so, the nodes a thread's slabs move
    /// are the ones its node passes write, and an element's nodes lie close in memory. Measured
    /// on the 81,920-element beam: two threads over one 1.79–1.84× → 1.86–1.93× (docs/PERFORMANCE.md,
    /// sessions 28–29). Node numbers change, not the physics: the element colouring (by element
    /// order) is the same, so a step gives the same result up to the order of sums over nodes.
    pub fn with_nodes_along_longest_axis(self) -> Mesh {
        let (lo, hi) = self.bounding_box();
        let axis = (hi - lo).iamax();
        let p = &self.rest_positions;
        let mut order: Vec<u32> = (0..self.num_nodes() as u32).collect();
        order.sort_by(|&a, &b| p[a as usize][axis].total_cmp(&p[b as usize][axis]));
        self.with_nodes_in_order(&order)
    }

    /// The same mesh with node `order[k]` renumbered `k` (`order` a permutation of the nodes);
    /// the elements and their order are unchanged.
    pub fn with_nodes_in_order(&self, order: &[u32]) -> Mesh {
        let p = &self.rest_positions;
        debug_assert_eq!(order.len(), p.len(), "a permutation of the nodes");
        let mut new_of = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_of[old as usize] = new as u32;
        }
        let rest_positions = order.iter().map(|&old| p[old as usize]).collect();
        let blocks = self
            .blocks
            .iter()
            .map(|b| ElementBlock::new(b.element_type, b.connectivity.iter().map(|&n| new_of[n as usize]).collect()))
            .collect();
        Mesh { rest_positions, blocks }
    }

    /// Nodes whose rest position satisfies `predicate`.
    pub fn nodes_where(&self, predicate: impl Fn(&Vec3) -> bool) -> Vec<u32> {
        (0..self.num_nodes() as u32).filter(|&i| predicate(&self.rest_positions[i as usize])).collect()
    }

    /// Nodes that are corners (vertices) of some element, as opposed to high-order nodes.
    pub fn vertex_nodes(&self) -> Vec<bool> {
        let mut is_vertex = vec![false; self.num_nodes()];
        for b in &self.blocks {
            let nv = b.element_type.num_vertices();
            for el in b.elements() {
                for &n in &el[..nv] {
                    is_vertex[n as usize] = true;
                }
            }
        }
        is_vertex
    }

    /// The boundary faces: faces that belong to exactly one element, as
    /// `(block, element, local face index)`. Faces are matched by their sorted corner nodes.
    pub fn boundary_faces(&self) -> Vec<(usize, usize, usize)> {
        let mut count: HashMap<Vec<u32>, (usize, (usize, usize, usize))> = HashMap::new();
        for (bi, b) in self.blocks.iter().enumerate() {
            for (e, nodes) in b.elements().enumerate() {
                for (fi, face) in b.element_type.faces().iter().enumerate() {
                    let mut key: Vec<u32> = face.corners().iter().map(|&l| nodes[l]).collect();
                    key.sort_unstable();
                    count.entry(key).and_modify(|c| c.0 += 1).or_insert((1, (bi, e, fi)));
                }
            }
        }
        let mut faces: Vec<_> = count.into_values().filter(|(n, _)| *n == 1).map(|(_, f)| f).collect();
        faces.sort_unstable();
        faces
    }
}
