//! Scalar fields on the display surface: what a body is coloured by in the app and in recordings.
//!
//! Every display vertex is a material point `r` of the elements whose boundary faces hold it
//! ([`Surface::samples`]). A field that depends on the deformation is evaluated there with each
//! element's own shape functions — not interpolated from quadrature points:
//!
//! `F(r) = I + Σ_i (x_i − X_i) ⊗ ∇_X N_i(r)`, `∇_X N_i = J⁻ᵀ ∇_r N_i`, `J = Σ_i X_i ⊗ ∇_r N_i`
//!
//! (the map the solver integrates, [`crate::fem::geometry`]). `F` jumps between elements, so at a
//! vertex shared by several elements the field is the mean of the elements' values. The fields:
//!
//! | name | quantity | unit |
//! |---|---|---|
//! | `displacement` | `|u| = |x − X|` | m |
//! | `von-mises` | `σ_vM = √(3/2 s:s)`, `s = σ − ⅓ tr σ I`, Cauchy `σ = P Fᵀ / det F` | Pa |
//! | `strain` | equivalent Green–Lagrange strain `√(2/3 e:e)`, `e = E − ⅓ tr E I`, `E = ½ (FᵀF − I)` | 1 |
//! | `det-f` | volume ratio `det F` (1: unchanged) | 1 |
//! | `energy-density` | strain energy density `ψ(F)` of the material | J/m³ |
//! | `error` | `|u − u_ref|` against a reference displacement field | m |
//!
//! The von Mises stress and the equivalent strain are the usual scalar measures of
//! finite-element post-processing (e.g. Bonet & Wood, *Nonlinear Continuum Mechanics for Finite
//! Element Analysis*, 2nd ed., §5.5); `P` is the material's first Piola–Kirchhoff stress
//! ([`crate::material`]).

use crate::Vec3;
use crate::fem::energy::for_each_element;
use crate::fem::geometry::{BlockGeometry, deformation_gradient, deformation_gradient_from, jacobian};
use crate::material::Material;
use crate::measure::surface::Surface;
use crate::mesh::Mesh;
use nalgebra::Matrix3;

/// A scalar field a surface can be coloured by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Field {
    Displacement,
    VonMises,
    Strain,
    DetF,
    EnergyDensity,
    Error,
}

impl Field {
    /// Every field, in the order menus list them.
    pub const ALL: [Field; 6] =
        [Field::Displacement, Field::VonMises, Field::Strain, Field::DetF, Field::EnergyDensity, Field::Error];

    /// The name on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Field::Displacement => "displacement",
            Field::VonMises => "von-mises",
            Field::Strain => "strain",
            Field::DetF => "det-f",
            Field::EnergyDensity => "energy-density",
            Field::Error => "error",
        }
    }

    pub fn from_name(name: &str) -> Option<Field> {
        Field::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Every name, comma-separated.
    pub fn names() -> String {
        Field::ALL.map(Field::name).join(", ")
    }

    /// A title for legends: "von Mises stress".
    pub fn title(self) -> &'static str {
        match self {
            Field::Displacement => "displacement |u|",
            Field::VonMises => "von Mises stress",
            Field::Strain => "equivalent strain",
            Field::DetF => "volume ratio det F",
            Field::EnergyDensity => "strain energy density",
            Field::Error => "error |u − u_ref|",
        }
    }

    /// The unit of its values ("" for ratios).
    pub fn unit(self) -> &'static str {
        match self {
            Field::Displacement | Field::Error => "m",
            Field::VonMises => "Pa",
            Field::Strain | Field::DetF => "",
            Field::EnergyDensity => "J/m³",
        }
    }

    /// What it is, in one line.
    pub fn description(self) -> &'static str {
        match self {
            Field::Displacement => "displacement magnitude |x − X|, metres",
            Field::VonMises => "von Mises stress √(3/2 s:s) of the Cauchy stress σ = P F^T/det F, pascals",
            Field::Strain => "equivalent Green–Lagrange strain √(2/3 e:e), e the deviator of E = (F^T F − I)/2",
            Field::DetF => "volume ratio det F: 1 unchanged, below 1 compressed, ≤ 0 inverted",
            Field::EnergyDensity => "strain energy density ψ(F) of the material model, J/m³",
            Field::Error => {
                "distance |u − u_ref| from the reference solution's displacement, metres (where one exists)"
            }
        }
    }

    /// The value of no deformation: 1 for det F, else 0.
    pub fn neutral(self) -> f64 {
        if self == Field::DetF { 1.0 } else { 0.0 }
    }

    /// Whether values lie on both sides of [`Field::neutral`] (det F), so a colour range is
    /// centred on it; every other field is non-negative and ranges from 0.
    pub fn two_sided(self) -> bool {
        self == Field::DetF
    }

    /// Whether the field needs `F` at the display points.
    pub fn needs_gradient(self) -> bool {
        matches!(self, Field::VonMises | Field::Strain | Field::DetF | Field::EnergyDensity)
    }

    /// The value of a deformation-gradient field at `f` (NaN for the others).
    pub fn of_deformation_gradient(self, material: &Material, f: &Matrix3<f64>) -> f64 {
        match self {
            Field::VonMises => von_mises_pa(material, f),
            Field::Strain => equivalent_strain(f),
            Field::DetF => f.determinant(),
            Field::EnergyDensity => material.energy_density(f),
            Field::Displacement | Field::Error => f64::NAN,
        }
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The von Mises stress of the Cauchy stress `σ = P Fᵀ / det F`, Pa (NaN when det F ≤ 0).
pub fn von_mises_pa(material: &Material, f: &Matrix3<f64>) -> f64 {
    let j = f.determinant();
    if j <= 0.0 {
        return f64::NAN;
    }
    let sigma = material.pk1(f) * f.transpose() / j;
    let dev = sigma - Matrix3::identity() * (sigma.trace() / 3.0);
    (1.5 * dev.norm_squared()).sqrt()
}

/// The equivalent Green–Lagrange strain `√(2/3 e:e)`, `e` the deviator of `E = ½(FᵀF − I)`:
/// equals the stretch strain of a uniaxial isochoric extension to first order.
pub fn equivalent_strain(f: &Matrix3<f64>) -> f64 {
    let e = 0.5 * (f.transpose() * f - Matrix3::identity());
    let dev = e - Matrix3::identity() * (e.trace() / 3.0);
    (2.0 / 3.0 * dev.norm_squared()).sqrt()
}

/// A deformation-gradient field ([`Field::needs_gradient`]) per element: its volume average
/// `Σ_q f(F_q) V_q / Σ_q V_q` over the element's quadrature points (the points the solver
/// integrates at), block by block in element order — the cell data of a VTK file and what the
/// Python package reads per element. A point where the field has no value (`det F ≤ 0` for the
/// stress) is left out; an element left with none is NaN.
pub fn element_means(
    field: Field,
    mesh: &Mesh,
    geometry: &[BlockGeometry],
    material: &Material,
    positions: &[Vec3],
) -> Vec<f64> {
    let mut out = Vec::with_capacity(mesh.num_elements());
    for_each_element(mesh, geometry, positions, |el| {
        let (mut sum, mut volume) = (0.0, 0.0);
        for (q, &v) in el.volumes().iter().enumerate() {
            let f = deformation_gradient(el.x, el.rest, el.geometry.gradients(el.element, q));
            let value = field.of_deformation_gradient(material, &f);
            if value.is_finite() {
                sum += value * v;
                volume += v;
            }
        }
        out.push(if volume > 0.0 { sum / volume } else { f64::NAN });
    });
    out
}

/// The rest volume of every element, `Σ_q V_q` over its quadrature points (m³), block by block.
pub fn element_volumes_m3(mesh: &Mesh, geometry: &[BlockGeometry]) -> Vec<f64> {
    let mut out = Vec::with_capacity(mesh.num_elements());
    for_each_element(mesh, geometry, &mesh.rest_positions, |el| out.push(el.volumes().iter().sum()));
    out
}

/// The material gradients `∇_X N_i` at every display vertex's element points, computed once.
#[derive(Clone, Debug, Default)]
pub struct SurfaceGradients {
    /// Per vertex, its samples `vertex_samples[v]..vertex_samples[v + 1]`.
    vertex_samples: Vec<u32>,
    /// Per sample, its nodes `sample_nodes[s]..sample_nodes[s + 1]`.
    sample_nodes: Vec<u32>,
    nodes: Vec<u32>,
    grad_in_material: Vec<Vec3>,
}

/// How far a sample where a shape function's gradient has no value (the pyramid's apex) moves
/// toward its element's centre, as a fraction of the way.
const APEX_NUDGE: f64 = 1e-6;

impl SurfaceGradients {
    /// The gradients at the samples of `surface`, a surface of `mesh`. A sample whose rest
    /// Jacobian is not positive (an inverted rest element, which the solver refuses anyway) is
    /// left out; a vertex left with no sample has NaN fields.
    pub fn new(mesh: &Mesh, surface: &Surface) -> SurfaceGradients {
        let mut out = SurfaceGradients { vertex_samples: vec![0], sample_nodes: vec![0], ..Default::default() };
        let mut grad_ref = Vec::new();
        for samples in &surface.samples {
            for &(b, e, r) in samples {
                let block = &mesh.blocks[b as usize];
                let element = block.element_type.reference();
                let nodes = block.element(e as usize);
                grad_ref.resize(element.num_nodes(), [0.0; 3]);
                element.shape_gradients(&r, &mut grad_ref);
                if grad_ref.iter().flatten().any(|g| !g.is_finite()) {
                    let c = element.shape().centroid();
                    let moved: [f64; 3] = std::array::from_fn(|k| r[k] + APEX_NUDGE * (c[k] - r[k]));
                    element.shape_gradients(&moved, &mut grad_ref);
                }
                let j = jacobian(&mesh.rest_positions, nodes, &grad_ref);
                let Some(j_inv_t) = (j.determinant() > 0.0).then(|| j.try_inverse()).flatten().map(|m| m.transpose())
                else {
                    continue;
                };
                out.nodes.extend_from_slice(nodes);
                out.grad_in_material.extend(grad_ref.iter().map(|g| j_inv_t * Vec3::from(*g)));
                out.sample_nodes.push(out.nodes.len() as u32);
            }
            out.vertex_samples.push(out.sample_nodes.len() as u32 - 1);
        }
        out
    }

    pub fn num_vertices(&self) -> usize {
        self.vertex_samples.len() - 1
    }

    /// The deformation gradient of sample `s` at node positions `x` (rest positions `rest`).
    fn deformation_gradient(&self, s: usize, x: &[Vec3], rest: &[Vec3]) -> Matrix3<f64> {
        let (a, b) = (self.sample_nodes[s] as usize, self.sample_nodes[s + 1] as usize);
        let nodes = self.nodes[a..b].iter().map(|&n| x[n as usize] - rest[n as usize]);
        deformation_gradient_from(nodes.zip(&self.grad_in_material[a..b]))
    }

    /// Every deformation gradient of vertex `v` (one per element meeting there).
    pub fn deformation_gradients(&self, v: usize, x: &[Vec3], rest: &[Vec3]) -> Vec<Matrix3<f64>> {
        let (a, b) = (self.vertex_samples[v] as usize, self.vertex_samples[v + 1] as usize);
        (a..b).map(|s| self.deformation_gradient(s, x, rest)).collect()
    }

    /// A deformation-gradient field ([`Field::needs_gradient`]) at every vertex: the mean over
    /// the elements meeting there of the field at each element's own `F`, written to `out`.
    pub fn values_into(&self, field: Field, material: &Material, x: &[Vec3], rest: &[Vec3], out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.vertex_samples.windows(2).map(|w| {
            let (a, b) = (w[0] as usize, w[1] as usize);
            if a == b {
                return f64::NAN;
            }
            let sum: f64 =
                (a..b).map(|s| field.of_deformation_gradient(material, &self.deformation_gradient(s, x, rest))).sum();
            sum / (b - a) as f64
        }));
    }
}

#[cfg(test)]
mod tests;
