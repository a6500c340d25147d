//! The display surface of a mesh: its boundary faces tessellated into triangles, element edges
//! as polylines, and any material points (quadrature points, probes) followed through the
//! deformation.
//!
//! Every displayed point is a fixed material point `r` of some element, so its position is the
//! element's own isoparametric map `x(r) = Σ_i N_i(r) x_i` — the map the solver integrates over.
//! A P2, P3 or Q2 face therefore bends on screen exactly as the element bends, not as the flat
//! triangle between its corners. The weights `N_i(r)` are computed once ([`PointMap`]); a frame
//! costs one weighted sum per displayed point.
//!
//! A reference face is flat, so its sample points are the face's corner map in reference space:
//! `r(s, t) = c0 + s (c1 − c0) + t (c2 − c0)` on a triangle (`s + t ≤ 1`), the bilinear map
//! of the four corners on a quadrilateral. Each face edge is cut into `segments` pieces; a mesh
//! of linear tetrahedra only (P1) has flat faces and keeps one triangle per face.
//! Samples shared by neighbouring faces (corners, edge points) become one vertex, keyed by
//! global node numbers, so the surface is watertight and vertex normals are smooth.

use crate::Vec3;
use crate::element::FaceShape;
use crate::mesh::Mesh;
use std::collections::HashMap;

/// Material points as fixed weighted sums of element nodes (compressed rows).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointMap {
    offsets: Vec<u32>,
    nodes: Vec<u32>,
    weights: Vec<f64>,
}

impl PointMap {
    /// The map for reference points `r` of elements `(block, element)`.
    pub fn from_reference_points(mesh: &Mesh, points: impl IntoIterator<Item = (usize, usize, [f64; 3])>) -> PointMap {
        let mut map = PointMap { offsets: vec![0], ..Default::default() };
        let mut n = Vec::new();
        for (b, e, r) in points {
            let block = &mesh.blocks[b];
            map.push(block.element_type.reference(), block.element(e), &r, &mut n);
        }
        map
    }

    fn push(&mut self, element: &dyn crate::element::ReferenceElement, nodes: &[u32], r: &[f64; 3], n: &mut Vec<f64>) {
        n.resize(element.num_nodes(), 0.0);
        element.shape_functions(r, n);
        // A node's own position: exactly that node (also where a rational shape function, the
        // pyramid's at its apex, has only a limit).
        let at_node = element.nodes().iter().position(|p| (0..3).all(|k| (p[k] - r[k]).abs() < 1e-12));
        if let Some(i) = at_node.or_else(|| n.iter().any(|w| !w.is_finite()).then_some(0)) {
            self.nodes.push(nodes[i]);
            self.weights.push(1.0);
        } else {
            for (&node, &w) in nodes.iter().zip(n.iter()) {
                if w != 0.0 {
                    self.nodes.push(node);
                    self.weights.push(w);
                }
            }
        }
        self.offsets.push(self.nodes.len() as u32);
    }

    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The node point `p` coincides with, if it is exactly one mesh node.
    pub fn single_node(&self, p: usize) -> Option<u32> {
        let (a, b) = (self.offsets[p] as usize, self.offsets[p + 1] as usize);
        (b - a == 1 && self.weights[a] == 1.0).then(|| self.nodes[a])
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `Σ_i N_i(r_p) v_i` for every point `p`, for node values `v` (positions, displacements…).
    pub fn eval_into(&self, node_values: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(self.offsets.windows(2).map(|w| {
            let (a, b) = (w[0] as usize, w[1] as usize);
            self.nodes[a..b]
                .iter()
                .zip(&self.weights[a..b])
                .fold(Vec3::zeros(), |acc, (&n, &wt)| acc + node_values[n as usize] * wt)
        }));
    }

    /// The displacement `x(r_p) − X(r_p)` of every point, metres.
    pub fn displacements_into(&self, positions: &[Vec3], rest_positions: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(self.offsets.windows(2).map(|w| {
            let (a, b) = (w[0] as usize, w[1] as usize);
            self.nodes[a..b]
                .iter()
                .zip(&self.weights[a..b])
                .fold(Vec3::zeros(), |acc, (&n, &wt)| acc + (positions[n as usize] - rest_positions[n as usize]) * wt)
        }));
    }
}

/// Where a sample point sits, to share it between the faces that meet there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum SampleKey {
    Node(u32),
    /// `k`-th of `segments` steps along the edge from the smaller global corner node.
    Edge {
        from: u32,
        to: u32,
        k: usize,
        segments: usize,
    },
    /// Inside face `face` (index into the boundary-face list), grid point `(i, j)`.
    Interior {
        face: usize,
        i: usize,
        j: usize,
    },
}

/// The boundary of a mesh as a triangle surface with element edges, for display.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Display vertices as material points.
    pub vertices: PointMap,
    /// Outward-facing triangles (counter-clockwise seen from outside), vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Boundary element edges as polylines of vertex indices (curved for high-order elements).
    pub edges: Vec<Vec<u32>>,
    /// Whether each vertex is a mesh node and, if so, a corner (vertex) node of its element.
    pub node_kind: Vec<Option<NodeKind>>,
    /// Pieces per face edge for curved and quadrilateral faces.
    pub segments: usize,
    /// Every element face a vertex lies on, as the material point `(block, element, r)` it is
    /// in that element (one per element, in the order the faces were met): the points a field
    /// that depends on `F` is evaluated at ([`crate::measure::field`]).
    pub samples: Vec<Vec<(u32, u32, [f64; 3])>>,
}

/// The kind of mesh node a display vertex coincides with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// A corner of an element.
    Corner,
    /// An edge, face or interior node of a high-order element.
    HighOrder,
}

impl Surface {
    /// Tessellates the boundary faces of `mesh`, cutting each curved or quadrilateral face edge
    /// into `segments` pieces (at least 1).
    pub fn new(mesh: &Mesh, segments: usize) -> Surface {
        let segments_wanted = segments.max(1);
        let is_corner = mesh.vertex_nodes();
        let faces = mesh.boundary_faces();
        // Linear tetrahedra have flat faces: one triangle each. Any other element may curve (or
        // have a bilinear face), and neighbouring faces must be cut alike to meet without gaps.
        let all_flat = mesh.blocks.iter().all(|b| {
            b.element_type.shape() == crate::element::ReferenceShape::Tetrahedron && b.element_type.order() == 1
        });
        let mut vertices = PointMap { offsets: vec![0], ..Default::default() };
        let mut node_kind = Vec::new();
        let mut samples: Vec<Vec<(u32, u32, [f64; 3])>> = Vec::new();
        let mut index: HashMap<SampleKey, u32> = HashMap::new();
        let mut triangles = Vec::new();
        let mut edges = Vec::new();
        let mut edge_seen: HashMap<(u32, u32), ()> = HashMap::new();
        let mut scratch = Vec::new();
        for (fi, &(b, e, f)) in faces.iter().enumerate() {
            let block = &mesh.blocks[b];
            let element = block.element_type.reference();
            let nodes = block.element(e);
            let face = &element.faces()[f];
            let corners: Vec<[f64; 3]> = face.corners().iter().map(|&l| element.nodes()[l]).collect();
            let corner_nodes: Vec<u32> = face.corners().iter().map(|&l| nodes[l]).collect();
            let l = if all_flat { 1 } else { segments_wanted };
            // the sample (i, j) of this face: its key and reference point
            let sample = |i: usize, j: usize| -> (SampleKey, [f64; 3]) {
                let (s, t) = (i as f64 / l as f64, j as f64 / l as f64);
                let r: [f64; 3] = match face.shape {
                    FaceShape::Triangle => std::array::from_fn(|k| {
                        corners[0][k] + s * (corners[1][k] - corners[0][k]) + t * (corners[2][k] - corners[0][k])
                    }),
                    FaceShape::Quadrilateral => std::array::from_fn(|k| {
                        (1.0 - s) * (1.0 - t) * corners[0][k]
                            + s * (1.0 - t) * corners[1][k]
                            + s * t * corners[2][k]
                            + (1.0 - s) * t * corners[3][k]
                    }),
                };
                // which corner or edge of the face the grid point lies on
                let on_edge = |a: usize, c: usize, k: usize| -> SampleKey {
                    let (na, nc) = (corner_nodes[a], corner_nodes[c]);
                    if k == 0 {
                        SampleKey::Node(na)
                    } else if k == l {
                        SampleKey::Node(nc)
                    } else if na < nc {
                        SampleKey::Edge { from: na, to: nc, k, segments: l }
                    } else {
                        SampleKey::Edge { from: nc, to: na, k: l - k, segments: l }
                    }
                };
                let key = match face.shape {
                    FaceShape::Triangle if j == 0 => on_edge(0, 1, i),
                    FaceShape::Triangle if i == 0 => on_edge(0, 2, j),
                    FaceShape::Triangle if i + j == l => on_edge(1, 2, j),
                    FaceShape::Quadrilateral if j == 0 => on_edge(0, 1, i),
                    FaceShape::Quadrilateral if i == l => on_edge(1, 2, j),
                    FaceShape::Quadrilateral if j == l => on_edge(3, 2, i),
                    FaceShape::Quadrilateral if i == 0 => on_edge(0, 3, j),
                    _ => SampleKey::Interior { face: fi, i, j },
                };
                (key, r)
            };
            let mut vertex = |i: usize, j: usize| -> u32 {
                let (key, r) = sample(i, j);
                let v = *index.entry(key).or_insert_with(|| {
                    vertices.push(element, nodes, &r, &mut scratch);
                    let v = vertices.len() - 1;
                    let a = vertices.offsets[v] as usize;
                    let kind = (vertices.offsets[v + 1] as usize - a == 1 && vertices.weights[a] == 1.0).then(|| {
                        if is_corner[vertices.nodes[a] as usize] { NodeKind::Corner } else { NodeKind::HighOrder }
                    });
                    node_kind.push(kind);
                    v as u32
                });
                let (b32, e32) = (b as u32, e as u32);
                if samples.len() <= v as usize {
                    samples.resize(v as usize + 1, Vec::new());
                }
                if !samples[v as usize].iter().any(|&(sb, se, _)| sb == b32 && se == e32) {
                    samples[v as usize].push((b32, e32, r));
                }
                v
            };
            let grid: Vec<Vec<u32>> = match face.shape {
                FaceShape::Triangle => (0..=l).map(|i| (0..=l - i).map(|j| vertex(i, j)).collect()).collect(),
                FaceShape::Quadrilateral => (0..=l).map(|i| (0..=l).map(|j| vertex(i, j)).collect()).collect(),
            };
            for i in 0..l {
                match face.shape {
                    FaceShape::Triangle => {
                        for j in 0..l - i {
                            triangles.push([grid[i][j], grid[i + 1][j], grid[i][j + 1]]);
                            if i + j + 1 < l {
                                triangles.push([grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]]);
                            }
                        }
                    }
                    FaceShape::Quadrilateral => {
                        for j in 0..l {
                            triangles.push([grid[i][j], grid[i + 1][j], grid[i + 1][j + 1]]);
                            triangles.push([grid[i][j], grid[i + 1][j + 1], grid[i][j + 1]]);
                        }
                    }
                }
            }
            // the face's edges as polylines, each shared edge once
            let n_corners = corner_nodes.len();
            for a in 0..n_corners {
                let c = (a + 1) % n_corners;
                let key = (corner_nodes[a].min(corner_nodes[c]), corner_nodes[a].max(corner_nodes[c]));
                if edge_seen.insert(key, ()).is_some() {
                    continue;
                }
                let line: Vec<u32> = (0..=l)
                    .map(|k| match (face.shape, a) {
                        (FaceShape::Triangle, 0) => grid[k][0],
                        (FaceShape::Triangle, 1) => grid[l - k][k],
                        (FaceShape::Triangle, _) => grid[0][l - k],
                        (FaceShape::Quadrilateral, 0) => grid[k][0],
                        (FaceShape::Quadrilateral, 1) => grid[l][k],
                        (FaceShape::Quadrilateral, 2) => grid[l - k][l],
                        (FaceShape::Quadrilateral, _) => grid[0][l - k],
                    })
                    .collect();
                edges.push(line);
            }
        }
        Surface { vertices, triangles, edges, node_kind, segments: segments_wanted, samples }
    }

    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// The element edges (indices into [`Surface::edges`]) whose two end nodes are both in
    /// `nodes` (flags by node): the edges of faces a clamp holds or a drive moves.
    pub fn edges_between(&self, nodes: &[bool]) -> Vec<usize> {
        let held = |v: u32| self.vertices.single_node(v as usize).is_some_and(|n| nodes.get(n as usize) == Some(&true));
        (0..self.edges.len())
            .filter(|&k| {
                let e = &self.edges[k];
                e.len() >= 2 && held(e[0]) && held(e[e.len() - 1])
            })
            .collect()
    }

    /// Area-weighted vertex normals of the surface at `vertex_positions` (unit length).
    pub fn vertex_normals(&self, vertex_positions: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        out.resize(vertex_positions.len(), Vec3::zeros());
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| vertex_positions[i as usize]);
            let n = (b - a).cross(&(c - a));
            for &i in t {
                out[i as usize] += n;
            }
        }
        for n in out.iter_mut() {
            let len = n.norm();
            if len > 0.0 {
                *n /= len;
            }
        }
    }
}

/// The quadrature points of every element as material points, in block, element, point order.
pub fn quadrature_points(mesh: &Mesh, geometry: &[crate::fem::geometry::BlockGeometry]) -> PointMap {
    let points = mesh.blocks.iter().zip(geometry).enumerate().flat_map(|(b, (block, g))| {
        (0..block.len()).flat_map(move |e| g.quadrature.points.iter().map(move |r| (b, e, *r)))
    });
    PointMap::from_reference_points(mesh, points)
}

#[cfg(test)]
mod tests;
