//! The displacement field of a reference solution, for the error field `|u − u_ref|` drawn on a
//! body ([`hox_sim::measure::field::Field::Error`]).
//!
//! - **Lattice**: a static solution on triquadratic hexahedra (Q2) of a structured box grid of
//!   `n_x × n_y × n_z` cells. Its nodes are the lattice of `(2n + 1)` points per direction, and
//!   on straight cells the Q2 interpolant is the tensor product of the 1-D quadratic Lagrange
//!   polynomials on the points `0, ½, 1` of a cell:
//!   `L₀(ξ) = 2(ξ − ½)(ξ − 1)`, `L₁(ξ) = −4ξ(ξ − 1)`, `L₂(ξ) = 2ξ(ξ − ½)`, so
//!   `u(X) = Σ_{a,b,c} L_a(ξ) L_b(η) L_c(ζ) U[2i + a, 2j + b, 2k + c]` in cell `(i, j, k)`.
//! - **Nodes**: one displacement per node of the scene's own mesh (its own static solution),
//!   interpolated with that mesh's shape functions.

use hox_sim::Vec3;
use hox_sim::mesh::Mesh;

/// A reference displacement field.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceField {
    /// Q2 on a structured box grid: displacements at the lattice points, x fastest, metres.
    Lattice { box_min_m: [f64; 3], box_max_m: [f64; 3], cells: [usize; 3], displacements_m: Vec<[f64; 3]> },
    /// One displacement per node of the scene's own mesh, metres.
    Nodes { displacements_m: Vec<[f64; 3]> },
}

impl ReferenceField {
    /// The lattice field of a solution `positions` on `mesh`, a mesh of the box
    /// `[box_min_m, box_max_m]` whose nodes are lattice points of `cells` (Q2: all of them; P2 on
    /// the five-tetrahedron split: all but the cell centres, whose displacement is then its
    /// shape functions' where the point lies); None when a node is off the lattice (a biased or
    /// unstructured mesh) or a missing point is in no element.
    pub fn lattice(
        mesh: &Mesh,
        positions: &[Vec3],
        box_min_m: [f64; 3],
        box_max_m: [f64; 3],
        cells: [usize; 3],
    ) -> Option<ReferenceField> {
        let points = cells.map(|n| 2 * n + 1);
        let mut displacements_m = vec![[f64::NAN; 3]; points[0] * points[1] * points[2]];
        for (rest, x) in mesh.rest_positions.iter().zip(positions) {
            let mut index = [0usize; 3];
            for d in 0..3 {
                let step = (box_max_m[d] - box_min_m[d]) / (2 * cells[d]) as f64;
                let f = (rest[d] - box_min_m[d]) / step;
                let k = f.round();
                if (f - k).abs() > 1e-6 || k < 0.0 || k as usize >= points[d] {
                    return None;
                }
                index[d] = k as usize;
            }
            let u = x - rest;
            displacements_m[index[0] + points[0] * (index[1] + points[1] * index[2])] = [u.x, u.y, u.z];
        }
        for (i, u) in displacements_m.iter_mut().enumerate().filter(|(_, u)| u[0].is_nan()) {
            let index = [i % points[0], (i / points[0]) % points[1], i / (points[0] * points[1])];
            let at = Vec3::from_fn(|d, _| {
                box_min_m[d] + (box_max_m[d] - box_min_m[d]) * index[d] as f64 / (2 * cells[d]) as f64
            });
            let probe = hox_sim::measure::probe::Probe::locate(mesh, "lattice", at).ok()?;
            *u = probe.displacement(positions, &mesh.rest_positions).into();
        }
        Some(ReferenceField::Lattice { box_min_m, box_max_m, cells, displacements_m })
    }

    /// The reference displacement at the material points whose rest positions are `rest_m`
    /// and, for a [`ReferenceField::Nodes`] field, whose node weights `map` gives on the
    /// scene's own mesh. None when the field does not fit (another mesh's node count).
    pub fn at_points(
        &self,
        rest_m: &[Vec3],
        map: &hox_sim::measure::surface::PointMap,
        num_nodes: usize,
    ) -> Option<Vec<Vec3>> {
        match self {
            ReferenceField::Lattice { .. } => Some(rest_m.iter().map(|x| self.lattice_at(x)).collect()),
            ReferenceField::Nodes { displacements_m } => {
                if displacements_m.len() != num_nodes {
                    return None;
                }
                let u: Vec<Vec3> = displacements_m.iter().map(|u| Vec3::from(*u)).collect();
                let mut out = Vec::new();
                map.eval_into(&u, &mut out);
                Some(out)
            }
        }
    }

    /// The lattice field at `x` (clamped into the box); NaN for a node field.
    pub fn lattice_at(&self, x: &Vec3) -> Vec3 {
        let ReferenceField::Lattice { box_min_m, box_max_m, cells, displacements_m } = self else {
            return Vec3::repeat(f64::NAN);
        };
        let points = cells.map(|n| 2 * n + 1);
        let mut cell = [0usize; 3];
        let mut weights = [[0.0; 3]; 3];
        for d in 0..3 {
            let h = (box_max_m[d] - box_min_m[d]) / cells[d] as f64;
            let f = ((x[d] - box_min_m[d]) / h).clamp(0.0, cells[d] as f64);
            cell[d] = (f.floor() as usize).min(cells[d] - 1);
            let xi = f - cell[d] as f64;
            weights[d] = [2.0 * (xi - 0.5) * (xi - 1.0), -4.0 * xi * (xi - 1.0), 2.0 * xi * (xi - 0.5)];
        }
        let mut u = Vec3::zeros();
        for (c, wc) in weights[2].iter().enumerate() {
            for (b, wb) in weights[1].iter().enumerate() {
                for (a, wa) in weights[0].iter().enumerate() {
                    let i = 2 * cell[0] + a + points[0] * (2 * cell[1] + b + points[1] * (2 * cell[2] + c));
                    u += Vec3::from(displacements_m[i]) * (wa * wb * wc);
                }
            }
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hox_sim::element::ElementType;
    use hox_sim::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};

    /// A quadratic displacement is reproduced exactly by the lattice field anywhere in the box
    /// (Q2 holds every polynomial of degree two per direction), and a mesh off the lattice has
    /// no lattice field.
    #[test]
    fn the_lattice_field_reproduces_a_quadratic_displacement() {
        let (lo, hi, cells) = ([0.0, 0.0, 0.0], [2.0, 0.5, 0.5], [4, 1, 1]);
        let mesh = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::from(lo), max_m: Vec3::from(hi), cells },
            element_type: ElementType::from_name("q2").unwrap(),
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        let u = |p: &Vec3| Vec3::new(0.1 * p.x * p.x, -0.2 * p.x * p.z, 0.05 * p.y * p.y - 0.3 * p.x);
        let x: Vec<Vec3> = mesh.rest_positions.iter().map(|p| p + u(p)).collect();
        let field = ReferenceField::lattice(&mesh, &x, lo, hi, cells).expect("on the lattice");
        for p in [Vec3::new(0.3, 0.1, 0.45), Vec3::new(1.99, 0.25, 0.0), Vec3::new(0.0, 0.5, 0.5)] {
            assert!((field.lattice_at(&p) - u(&p)).norm() < 1e-12, "{p}");
        }
        assert!(ReferenceField::lattice(&mesh, &x, lo, hi, [3, 1, 1]).is_none());
        // P2 on the five-tetrahedron split has no node at the cell centres: its shape functions
        // give them, and P2 holds the quadratic exactly too
        let p2 = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::from(lo), max_m: Vec3::from(hi), cells },
            element_type: ElementType::from_name("p2").unwrap(),
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        let x: Vec<Vec3> = p2.rest_positions.iter().map(|p| p + u(p)).collect();
        let field = ReferenceField::lattice(&p2, &x, lo, hi, cells).expect("on the lattice");
        for p in [Vec3::new(0.3, 0.1, 0.45), Vec3::new(1.75, 0.25, 0.25), Vec3::new(0.0, 0.5, 0.5)] {
            assert!((field.lattice_at(&p) - u(&p)).norm() < 1e-12, "{p}");
        }
    }
}
