//! Structured box meshes: the paper's beams.
//!
//! A box is cut into an `nx × ny × nz` grid of hexahedra; each hexahedron is then
//! - cut into 5 tetrahedra, the decomposition mirrored from one cell to the next (by the
//!   parity of `i + j + k`) so that face diagonals match: conforming, "unbiased";
//! - or cut into 6 tetrahedra around the same body diagonal (0,0,0)–(1,1,1) in every cell:
//!   "biased", the paper's tension and torsion beams;
//! - or cut into 2 prisms (the bottom quad split along its (0,0)–(1,1) diagonal, extruded in z);
//! - or cut into 6 pyramids, one per face, around a node added at the cell centre;
//! - or kept as Q1/Q2 hexahedra.
//!
//! Tetrahedral meshes can be refined 1-to-8 (each tetrahedron into four corner tetrahedra and
//! four around the shortest diagonal of the inner octahedron) before P2/P3 nodes are added by
//! [`super::high_order::raise_order`]. Every element is oriented to a positive Jacobian.
//! The nodes of the finished mesh are numbered along the box's longest axis
//! ([`Mesh::with_nodes_along_longest_axis`]): where the colour sweep cuts its slabs.

use super::high_order::raise_order;
use super::{ElementBlock, Mesh, MeshError};
use crate::Vec3;
use crate::element::{ElementType, ReferenceShape};
use std::collections::HashMap;

/// How hexahedral cells are cut into tetrahedra.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum TetSplit {
    /// 5 tetrahedra, alternating orientation (unbiased, conforming).
    #[default]
    Five,
    /// 6 tetrahedra around the same body diagonal everywhere (biased).
    Six,
}

impl TetSplit {
    pub fn name(self) -> &'static str {
        match self {
            Self::Five => "five",
            Self::Six => "six",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "five" | "5" => Some(Self::Five),
            "six" | "6" => Some(Self::Six),
            _ => None,
        }
    }
}

/// A box `[min, max]` cut into `cells` hexahedral cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxGrid {
    pub min_m: Vec3,
    pub max_m: Vec3,
    pub cells: [usize; 3],
}

/// What to build on a [`BoxGrid`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxMeshSpec {
    pub grid: BoxGrid,
    pub element_type: ElementType,
    pub split: TetSplit,
    /// Number of 1-to-8 refinements of the linear tetrahedra (tetrahedral types only).
    pub refine: usize,
}

// Corners of a unit cell in Gmsh hexahedron order.
const CELL: [[usize; 3]; 8] = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]];

// Five tetrahedra: corner tetrahedra at cell corners 0, 2, 5, 7 and the central one, and the
// mirror decomposition with corners at 1, 3, 4, 6.
const FIVE_EVEN: [[usize; 4]; 5] = [[0, 1, 3, 4], [2, 3, 1, 6], [5, 1, 4, 6], [7, 4, 3, 6], [1, 3, 4, 6]];
const FIVE_ODD: [[usize; 4]; 5] = [[1, 0, 2, 5], [3, 2, 0, 7], [4, 5, 7, 0], [6, 7, 5, 2], [0, 2, 5, 7]];
// Six tetrahedra around the diagonal 0–6.
const SIX: [[usize; 4]; 6] = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]];
const PRISMS: [[usize; 6]; 2] = [[0, 1, 2, 4, 5, 6], [0, 2, 3, 4, 6, 7]];

/// Elements of `shape` one hexahedral cell of a box is cut into (before any refinement).
pub fn elements_per_cell(shape: ReferenceShape, split: TetSplit) -> usize {
    match shape {
        ReferenceShape::Tetrahedron => match split {
            TetSplit::Five => FIVE_EVEN.len(),
            TetSplit::Six => SIX.len(),
        },
        ReferenceShape::Hexahedron => 1,
        ReferenceShape::Prism => PRISMS.len(),
        ReferenceShape::Pyramid => ReferenceShape::Hexahedron.faces().len(),
    }
}

impl BoxMeshSpec {
    pub fn build(&self) -> Result<Mesh, MeshError> {
        let [nx, ny, nz] = self.grid.cells;
        if nx == 0 || ny == 0 || nz == 0 {
            return Err(MeshError::InvalidRequest(format!("the grid {nx}x{ny}x{nz} has an empty direction")));
        }
        let size = self.grid.max_m - self.grid.min_m;
        if !size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(MeshError::InvalidRequest(format!(
                "the box from {:?} to {:?} must have positive finite size",
                self.grid.min_m.as_slice(),
                self.grid.max_m.as_slice()
            )));
        }
        let shape = self.element_type.shape();
        if self.refine > 0 && shape != ReferenceShape::Tetrahedron {
            return Err(MeshError::InvalidRequest(format!(
                "refinement applies to tetrahedra only, not to {}",
                self.element_type
            )));
        }
        let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let t = Vec3::new(i as f64 / nx as f64, j as f64 / ny as f64, k as f64 / nz as f64);
                    positions.push(self.grid.min_m + size.component_mul(&t));
                }
            }
        }
        let vid = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
        let cells = (0..nz).flat_map(|k| (0..ny).flat_map(move |j| (0..nx).map(move |i| (i, j, k))));
        let corners = |(i, j, k): (usize, usize, usize)| CELL.map(|[a, b, c]| vid(i + a, j + b, k + c));
        // the box is cut into the linear element of the shape, then raised to the element's order
        let linear = ElementType::linear(shape).ok_or_else(|| {
            MeshError::InvalidRequest(format!(
                "cannot mesh a box of {}: no linear (order-1) {shape:?} element is registered",
                self.element_type
            ))
        })?;
        let mut mesh = match shape {
            ReferenceShape::Tetrahedron => {
                let mut conn = Vec::new();
                for cell in cells {
                    let v = corners(cell);
                    let tets: &[[usize; 4]] = match self.split {
                        TetSplit::Five if (cell.0 + cell.1 + cell.2) % 2 == 0 => &FIVE_EVEN,
                        TetSplit::Five => &FIVE_ODD,
                        TetSplit::Six => &SIX,
                    };
                    for t in tets {
                        conn.extend(t.iter().map(|&c| v[c]));
                    }
                }
                let mut m = Mesh { rest_positions: positions, blocks: vec![ElementBlock::new(linear, conn)] };
                orient_positively(&mut m);
                for _ in 0..self.refine {
                    m = refine_tetrahedra(&m);
                }
                m
            }
            ReferenceShape::Hexahedron => {
                let conn = cells.flat_map(corners).collect();
                Mesh { rest_positions: positions, blocks: vec![ElementBlock::new(linear, conn)] }
            }
            ReferenceShape::Prism => {
                let mut conn = Vec::new();
                for cell in cells {
                    let v = corners(cell);
                    for p in PRISMS {
                        conn.extend(p.iter().map(|&c| v[c]));
                    }
                }
                Mesh { rest_positions: positions, blocks: vec![ElementBlock::new(linear, conn)] }
            }
            ReferenceShape::Pyramid => {
                let mut conn = Vec::new();
                for cell in cells {
                    let v = corners(cell);
                    let centre: Vec3 = v.iter().map(|&n| positions[n as usize]).sum::<Vec3>() / 8.0;
                    positions.push(centre);
                    let apex = (positions.len() - 1) as u32;
                    for face in ReferenceShape::Hexahedron.faces() {
                        // outward quad, reversed: counter-clockwise seen from the apex inside
                        conn.extend(face.iter().rev().map(|&c| v[c]));
                        conn.push(apex);
                    }
                }
                Mesh { rest_positions: positions, blocks: vec![ElementBlock::new(linear, conn)] }
            }
        };
        orient_positively(&mut mesh);
        let mesh = raise_order(&mesh, self.element_type)?.with_nodes_along_longest_axis();
        mesh.validate()?;
        Ok(mesh)
    }
}

/// Signed volume of the linear tetrahedron (a, b, c, d), times 6.
fn tet_volume6(p: &[Vec3], t: &[u32]) -> f64 {
    let [a, b, c, d] = [0, 1, 2, 3].map(|k| p[t[k] as usize]);
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Reorders the nodes of negatively oriented linear elements (tetrahedra, prisms, pyramids)
/// so that every element has a positive Jacobian.
pub fn orient_positively(mesh: &mut Mesh) {
    let p = &mesh.rest_positions;
    for b in &mut mesh.blocks {
        let n = b.nodes_per_element();
        let shape = b.element_type.shape();
        for el in b.connectivity.chunks_exact_mut(n) {
            let negative = match shape {
                ReferenceShape::Tetrahedron => tet_volume6(p, el) < 0.0,
                ReferenceShape::Prism => tet_volume6(p, &[el[0], el[1], el[2], el[3]]) < 0.0,
                ReferenceShape::Pyramid => tet_volume6(p, &[el[0], el[1], el[3], el[4]]) < 0.0,
                ReferenceShape::Hexahedron => false,
            };
            if negative {
                match shape {
                    ReferenceShape::Tetrahedron => el.swap(1, 2),
                    ReferenceShape::Prism => {
                        el.swap(1, 2);
                        el.swap(4, 5);
                    }
                    ReferenceShape::Pyramid => el.swap(1, 3),
                    ReferenceShape::Hexahedron => {}
                }
            }
        }
    }
}

/// One 1-to-8 refinement of the linear tetrahedra of `mesh` (Bey's red refinement with the
/// inner octahedron cut along its shortest diagonal). Nodes: V + E; elements: 8×.
pub fn refine_tetrahedra(mesh: &Mesh) -> Mesh {
    let mut positions = mesh.rest_positions.clone();
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
        let key = (a.min(b), a.max(b));
        *midpoints.entry(key).or_insert_with(|| {
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            (positions.len() - 1) as u32
        })
    };
    let mut blocks = Vec::new();
    for b in &mesh.blocks {
        if b.element_type.shape() != ReferenceShape::Tetrahedron || b.element_type.order() != 1 {
            blocks.push(b.clone());
            continue;
        }
        let mut conn = Vec::with_capacity(8 * b.connectivity.len());
        for t in b.elements() {
            let [v0, v1, v2, v3] = [t[0], t[1], t[2], t[3]];
            let m01 = mid(v0, v1, &mut positions);
            let m02 = mid(v0, v2, &mut positions);
            let m03 = mid(v0, v3, &mut positions);
            let m12 = mid(v1, v2, &mut positions);
            let m13 = mid(v1, v3, &mut positions);
            let m23 = mid(v2, v3, &mut positions);
            conn.extend([v0, m01, m02, m03]);
            conn.extend([m01, v1, m12, m13]);
            conn.extend([m02, m12, v2, m23]);
            conn.extend([m03, m13, m23, v3]);
            // inner octahedron: pick the shortest of its three diagonals
            let diagonals = [(m01, m23), (m02, m13), (m03, m12)];
            let len = |(a, b): (u32, u32)| (positions[a as usize] - positions[b as usize]).norm();
            let (a, b) = diagonals.into_iter().min_by(|x, y| len(*x).total_cmp(&len(*y))).expect("three diagonals");
            // the four other octahedron vertices, in cyclic order around the diagonal
            let ring: [u32; 4] = if (a, b) == (m01, m23) {
                [m02, m03, m13, m12]
            } else if (a, b) == (m02, m13) {
                [m01, m12, m23, m03]
            } else {
                [m01, m02, m23, m13]
            };
            for k in 0..4 {
                conn.extend([a, b, ring[k], ring[(k + 1) % 4]]);
            }
        }
        blocks.push(ElementBlock::new(b.element_type, conn));
    }
    let mut refined = Mesh { rest_positions: positions, blocks };
    orient_positively(&mut refined);
    refined
}

#[cfg(test)]
mod tests;
