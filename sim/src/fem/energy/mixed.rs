//! The mixed formulation's element: the material's hydrostatic term measured over the element.
//!
//! With the material's split `ψ(F) = k_d/2 C_d(F)² + k_h/2 C_h(F)² + c`
//! ([`crate::material::SplitModel`]: for StVK `C_h = tr E`, `k_h = λ`; for Neo-Hookean
//! `C_h = ln J`), the element's energy is
//!
//! `U_e = Σ_q V_q ψ_d(F_q) + V_e k_h/2 C̄²`, `ψ_d = ψ − k_h/2 C_h²`, `C̄ = Σ_q V_q C_h(F_q) / V_e`,
//! `V_e = Σ_q V_q`:
//!
//! the displacement–pressure mixed element with one constant pressure `p = k_h C̄` per element,
//! the pressure eliminated element by element (a discontinuous pressure is condensed exactly: the
//! mean-dilatation element of Nagtegaal, Parks & Rice 1974, "On numerically accurate finite element
//! solutions in the fully plastic range", and of Simo, Taylor & Pister 1985, "Variational and
//! projection methods for the volume constraint in finite deformation elasto-plasticity", here
//! with the hydrostatic term of the material's own split in place of `ln J`). The volume
//! constraint is met once per element instead of at every quadrature point, which is what
//! releases a high-order element from volumetric locking as ν → 0.5; the pair (element, constant
//! pressure) must satisfy the inf–sup condition for that (Boffi, Brezzi & Fortin 2013, *Mixed
//! Finite Element Methods and Applications*, §8.6–8.7): P2, P3 and Q2 with a constant pressure do,
//! Q1, the prism and the pyramid with it do not (pressure checkerboards), and P1 with it is P1
//! itself (one point), so `crate::solver::SolverSettings` refuses those by name.
//!
//! - gradient: `∂U_e/∂x_i = Σ_q V_q (P_d + p G_h)(F_q) ∇_X N_i(r_q)`, `P_d = P − k_h C_h G_h`,
//!   `G_h = ∂C_h/∂F`;
//! - Hessian: `Σ_q V_q C(A_d + p H_h)(∇N_i, ∇N_j) + V_e k_h ḡ_i ⊗ ḡ_j`, `A_d = ∂P/∂F − k_h (G_h ⊗
//!   G_h + C_h H_h)`, `H_h = ∂²C_h/∂F²`, `ḡ_i = Σ_q V_q G_h ∇N_i / V_e`; projected, `A_d + p H_h`
//!   is projected to positive semi-definite at each point (the rank-one term already is).
//!
//! The deviatoric term must be stable alone (its tangent at rest positive semi-definite:
//! [`Material::with_volume_measure`] checks), since inside an element it now holds each point
//! alone: StVK's and Neo-Hookean's are; stable Neo-Hookean's carries μ at rest and is refused.

use super::PointBlocks;
use crate::Vec3;
use crate::fem::geometry::deformation_gradient;
use crate::material::{Mat3, Mat9, Material, NodeVisit, contract, project_psd};
use nalgebra::{DMatrix, Matrix3};

pub mod patch;

/// Why the mixed formulation refuses an element type, if it does: a constant pressure per element
/// is stable (inf–sup) with P2, P3 and Q2 (every element of order 2 or more); P1 has one point, so
/// its pressure is one per node instead ([`patch`], the averaged nodal pressure); Q1, the prism and
/// the pyramid with a constant pressure violate the inf–sup condition (Q1's pressures
/// checkerboard).
pub fn refusal(element: crate::element::ElementType) -> Option<String> {
    use crate::element::ReferenceShape;
    if element.order() >= 2 || element.shape() == ReferenceShape::Tetrahedron {
        return None;
    }
    Some(format!(
        "the mixed formulation's constant pressure per element violates the inf–sup condition on {element} \
         (the element pressures form a checkerboard, as Q1's do): use Q2, P2, P3 or P1 (whose pressure is one per \
         node)"
    ))
}

/// Nodes up to which the gradient's scratch is on the stack (Q2's 27).
const STACK_NODES: usize = 27;

/// One point's share: the deviatoric energy density and stress, the hydrostatic term and its
/// derivative.
struct Point {
    psi_d: f64,
    p_d: Mat3,
    c_h: f64,
    g_h: Mat3,
}

/// The hydrostatic stiffness `k_h` (Pa).
pub fn hydrostatic_stiffness_pa(material: &Material) -> f64 {
    material.split_stiffness_pa()[1]
}

fn point(material: &Material, k_h: f64, f: &Mat3) -> Point {
    let (psi, p) = material.energy_density_and_pk1(f);
    let [_, h] = material.split_terms(f);
    debug_assert_eq!(h.scale, 1.0, "a hydrostatic term is not a square root");
    Point {
        psi_d: psi - 0.5 * k_h * h.value * h.value,
        p_d: p - h.grad_f_scaled * (k_h * h.value),
        c_h: h.value,
        g_h: h.grad_f_scaled,
    }
}

/// The deviatoric energy density `ψ_d(F)` (J/m³) and its stress `P_d(F)` (Pa): what XPBD's
/// patch constraints measure at a node's averaged deformation gradient ([`patch`]).
pub fn deviatoric_density_and_stress(material: &Material, f: &Mat3) -> (f64, Mat3) {
    let pt = point(material, hydrostatic_stiffness_pa(material), f);
    (pt.psi_d, pt.p_d)
}

/// The tangent `β A_d + p H_h` of one point, `β` the deviatoric term's share (1 but on P1's
/// patches, [`patch`]), projected to positive semi-definite when asked.
fn point_tangent(
    material: &Material,
    k_h: f64,
    deviatoric_share: f64,
    pressure_pa: f64,
    f: &Mat3,
    pt: &Point,
    projected: bool,
) -> Mat9 {
    let g = nalgebra::SVector::<f64, 9>::from_column_slice(pt.g_h.as_slice());
    let hh = material.hydrostatic_hessian(f);
    let a_d = material.dpdf(f) - g * g.transpose() * k_h - hh * (k_h * pt.c_h);
    let c = a_d * deviatoric_share + hh * pressure_pa;
    if projected { project_psd(&c) } else { (c + c.transpose()) * 0.5 }
}

/// [`point_tangent`] (not projected) contracted with one node's gradient, `C(β A_d + p H_h)(g, g)`,
/// from the model's node blocks (`C(g, g)`, `H_h(g, g)`: three directional derivatives each where
/// the 9 × 9 tangents take nine; a P1 node's vertex block descent visit, [`patch`]).
fn point_node_block(
    material: &Material,
    k_h: f64,
    deviatoric_share: f64,
    pressure_pa: f64,
    f: &Mat3,
    pt: &Point,
    g: &Vec3,
) -> Matrix3<f64> {
    let hh = material.hydrostatic_node_block(f, g);
    let gh = pt.g_h * g;
    let a_d = material.node_block(f, g) - (gh * gh.transpose() + hh * pt.c_h) * k_h;
    a_d * deviatoric_share + hh * pressure_pa
}

/// The element's `V_e` and `C̄` from its points' `F_q`.
fn mean_hydrostatic(material: &Material, points: impl Iterator<Item = (Mat3, f64)>) -> (f64, f64) {
    let (mut v_e, mut sum) = (0.0, 0.0);
    for (f, v) in points {
        v_e += v;
        sum += v * material.split_terms(&f)[1].value;
    }
    (v_e, if v_e > 0.0 { sum / v_e } else { 0.0 })
}

fn points<'a>(
    x: &'a [Vec3],
    rest: &'a [Vec3],
    grads: &'a [Vec3],
    volumes: &'a [f64],
) -> impl Iterator<Item = (Mat3, f64)> + Clone + 'a {
    let n = x.len();
    volumes.iter().enumerate().map(move |(q, &v)| (deformation_gradient(x, rest, &grads[q * n..(q + 1) * n]), v))
}

/// `U_e` (as [`super::element_energy`]'s arguments).
pub fn element_energy(x: &[Vec3], rest: &[Vec3], grads: &[Vec3], volumes: &[f64], material: &Material) -> f64 {
    energy_of(material, points(x, rest, grads, volumes))
}

/// `U_e = Σ_q V_q ψ_d(F_q) + V_e k_h/2 C̄²` of an element's points `(F_q, V_q)`: the one sum.
fn energy_of(material: &Material, pts: impl Iterator<Item = (Mat3, f64)>) -> f64 {
    let k_h = hydrostatic_stiffness_pa(material);
    let (mut u, mut v_e, mut sum) = (0.0, 0.0, 0.0);
    for (f, v) in pts {
        let pt = point(material, k_h, &f);
        u += v * pt.psi_d;
        v_e += v;
        sum += v * pt.c_h;
    }
    let c_bar = if v_e > 0.0 { sum / v_e } else { 0.0 };
    u + 0.5 * v_e * k_h * c_bar * c_bar
}

/// The element's pressure `p = k_h C̄` (Pa): the one value of its constant pressure field.
pub fn element_pressure_pa(x: &[Vec3], rest: &[Vec3], grads: &[Vec3], volumes: &[f64], material: &Material) -> f64 {
    hydrostatic_stiffness_pa(material) * mean_hydrostatic(material, points(x, rest, grads, volumes)).1
}

/// `U_e` and `∂U_e/∂x_i` into `grad_out` (as [`super::element_energy_and_gradient`]).
pub fn element_energy_and_gradient(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    grad_out: &mut [Vec3],
) -> f64 {
    let n = x.len();
    let k_h = hydrostatic_stiffness_pa(material);
    // Σ_q V_q G_h ∇N_i, scaled by the pressure once it is known (on the stack for every
    // built-in element)
    let (mut stack, mut heap) = ([Vec3::zeros(); STACK_NODES], Vec::new());
    let hydro: &mut [Vec3] = if n <= STACK_NODES {
        &mut stack[..n]
    } else {
        heap.resize(n, Vec3::zeros());
        &mut heap
    };
    grad_out.iter_mut().for_each(|g| *g = Vec3::zeros());
    let (mut u, mut v_e, mut sum) = (0.0, 0.0, 0.0);
    for (q, (f, v)) in points(x, rest, grads, volumes).enumerate() {
        let pt = point(material, k_h, &f);
        u += v * pt.psi_d;
        v_e += v;
        sum += v * pt.c_h;
        let (vp, vg) = (pt.p_d * v, pt.g_h * v);
        for ((out, h), gi) in grad_out.iter_mut().zip(hydro.iter_mut()).zip(&grads[q * n..(q + 1) * n]) {
            *out += vp * gi;
            *h += vg * gi;
        }
    }
    let c_bar = if v_e > 0.0 { sum / v_e } else { 0.0 };
    let pressure = k_h * c_bar;
    for (out, h) in grad_out.iter_mut().zip(hydro.iter()) {
        *out += h * pressure;
    }
    u + 0.5 * v_e * k_h * c_bar * c_bar
}

/// The element's deviatoric share alone, `Σ_q V_q ψ_d(F_q)`, and its gradient
/// `Σ_q V_q P_d(F_q) ∇_X N_i(r_q)` into `grad_out`: what XPBD keeps per element when the pressure
/// is one per node patch ([`patch`]; XPBD's `crate::xpbd::patch`).
pub fn deviatoric_energy_and_gradient(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    grad_out: &mut [Vec3],
) -> f64 {
    let n = x.len();
    let k_h = hydrostatic_stiffness_pa(material);
    grad_out.iter_mut().for_each(|g| *g = Vec3::zeros());
    let mut u = 0.0;
    for (q, (f, v)) in points(x, rest, grads, volumes).enumerate() {
        let pt = point(material, k_h, &f);
        u += v * pt.psi_d;
        let vp = pt.p_d * v;
        for (out, gi) in grad_out.iter_mut().zip(&grads[q * n..(q + 1) * n]) {
            *out += vp * gi;
        }
    }
    u
}

/// The element Hessian (as [`super::element_hessian`]).
pub fn element_hessian(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    projected: bool,
) -> DMatrix<f64> {
    let n = x.len();
    let k_h = hydrostatic_stiffness_pa(material);
    let (v_e, c_bar) = mean_hydrostatic(material, points(x, rest, grads, volumes));
    let pressure = k_h * c_bar;
    let mut blocks = PointBlocks::new(n);
    let mut g_bar = vec![Vec3::zeros(); n];
    for (q, (f, v)) in points(x, rest, grads, volumes).enumerate() {
        let pt = point(material, k_h, &f);
        let g = &grads[q * n..(q + 1) * n];
        blocks.add(&point_tangent(material, k_h, 1.0, pressure, &f, &pt, projected), g, v);
        for (gb, gi) in g_bar.iter_mut().zip(g) {
            *gb += pt.g_h * gi * (v / v_e);
        }
    }
    let mut h = blocks.finish();
    let scale = v_e * k_h;
    for (i, gi) in g_bar.iter().enumerate() {
        for (j, gj) in g_bar.iter().enumerate() {
            for a in 0..3 {
                for b in 0..3 {
                    h[(3 * i + a, 3 * j + b)] += scale * gi[a] * gj[b];
                }
            }
        }
    }
    h
}

/// One node's gradient and diagonal Hessian block (as [`super::element_node_gradient_and_block`]).
pub fn element_node_gradient_and_block(
    x: &[Vec3],
    rest: &[Vec3],
    grads: &[Vec3],
    volumes: &[f64],
    material: &Material,
    a: usize,
    projected: bool,
) -> (Vec3, Matrix3<f64>) {
    let n = x.len();
    let pts = points(x, rest, grads, volumes).enumerate().map(move |(q, (f, v))| (f, grads[q * n + a], v));
    node_share(material, pts, projected)
}

/// [`super::node_visit`] for the mixed formulation: the node's gradient and its diagonal block
/// (not projected: vertex block descent projects the node's sum).
pub fn node_visit(material: &Material, visit: NodeVisit<'_>) -> (Vec3, Matrix3<f64>) {
    node_share(material, visit_points(visit), false)
}

/// [`super::visit_energy`] for the mixed formulation: `U_e` from the visit's `F_q`.
pub fn visit_energy(material: &Material, visit: NodeVisit<'_>) -> f64 {
    energy_of(material, visit_points(visit).map(|(f, _, v)| (f, v)))
}

/// A visit's points `(F_q, ∇N_a, V_q)`, its padding skipped.
fn visit_points(visit: NodeVisit<'_>) -> impl Iterator<Item = (Mat3, Vec3, f64)> + Clone + '_ {
    visit
        .volumes
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(move |(p, _)| visit.point(p / visit.width, p % visit.width))
}

/// `(Σ_q V_q (P_d + p G_h) g_q, Σ_q V_q C(A_d + p H_h)(g_q, g_q) + V_e k_h ḡ ḡᵀ)` over the element's
/// points `(F_q, g_q = ∇N_a(r_q), V_q)`.
fn node_share(
    material: &Material,
    pts: impl Iterator<Item = (Mat3, Vec3, f64)> + Clone,
    projected: bool,
) -> (Vec3, Matrix3<f64>) {
    let k_h = hydrostatic_stiffness_pa(material);
    let (v_e, c_bar) = mean_hydrostatic(material, pts.clone().map(|(f, _, v)| (f, v)));
    let pressure = k_h * c_bar;
    let (mut grad, mut block, mut g_bar) = (Vec3::zeros(), Matrix3::zeros(), Vec3::zeros());
    for (f, g, v) in pts {
        let pt = point(material, k_h, &f);
        grad += (pt.p_d + pt.g_h * pressure) * g * v;
        block += contract(&point_tangent(material, k_h, 1.0, pressure, &f, &pt, projected), &g, &g) * v;
        g_bar += pt.g_h * g * v;
    }
    if v_e > 0.0 {
        block += g_bar * g_bar.transpose() * (k_h / v_e);
    }
    (grad, (block + block.transpose()) * 0.5)
}

#[cfg(test)]
mod tests;
