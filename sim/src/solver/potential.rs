//! Implicit Euler's incremental potential over the free nodes,
//!
//! `E(x) = Σ_i m_i/(2h²) |x_i − y_i|² + Σ_e U_e(x) + Σ_k k_k/2 |x_{n_k} − t_k|²`,
//!
//! `y` the inertial prediction (gravity included), the last term the springs of potential
//! effects (a dragged node's attachment); its gradient is zero on held nodes, whose reactions it
//! reports instead. Newton's implicit Euler minimises it (`newton.rs`), VBD's coarse correction
//! takes its gradient (`vbd/coarse.rs`).

use super::step::StepInput;
use crate::Vec3;
use crate::effect::NodeSpring;
use crate::fem::energy::total_energy_and_gradient;

/// The incremental potential and its gradient (free nodes only; held ones get a zero gradient);
/// also VBD's coarse correction's gradient (`vbd/coarse.rs`).
pub(crate) struct Potential<'a> {
    pub input: &'a StepInput<'a>,
    pub y: &'a [Vec3],
    pub springs: &'a [NodeSpring],
    /// `1/h²`.
    pub w: f64,
}

impl Potential<'_> {
    /// `E(x)` and `∇E(x)` (zero on held nodes), and the reactions `‖∇U − m a‖` at the held nodes.
    pub fn eval(&self, x: &[Vec3], grad: &mut [Vec3]) -> (f64, f64) {
        let s = self.input;
        let mut e = total_energy_and_gradient(s.mesh, s.geometry, s.material, x, grad);
        let mut reactions = 0.0;
        for (i, g) in grad.iter_mut().enumerate() {
            if s.inv_mass[i] == 0.0 {
                reactions += (*g - s.body_acceleration * s.masses_kg[i]).norm_squared();
                *g = Vec3::zeros();
                continue;
            }
            let d = x[i] - self.y[i];
            e += 0.5 * s.masses_kg[i] * self.w * d.norm_squared();
            *g += d * (s.masses_kg[i] * self.w);
        }
        for sp in self.springs {
            let i = sp.node as usize;
            let d = x[i] - sp.target_m;
            e += 0.5 * sp.stiffness_n_per_m * d.norm_squared();
            if s.inv_mass[i] > 0.0 {
                grad[i] += d * sp.stiffness_n_per_m;
            }
        }
        (e, reactions.sqrt())
    }

    /// The diagonal of `E`'s Hessian beyond the elastic part, one value per free degree of
    /// freedom (`dof_of`: global DOF → free DOF, `usize::MAX` held; `free_dofs` of them):
    /// `m_i/h²` plus the stiffness of every spring on the node.
    pub fn hessian_diagonal(&self, dof_of: &[usize], free_dofs: usize) -> Vec<f64> {
        let s = self.input;
        let mut d = vec![0.0; free_dofs];
        for (dof, &k) in dof_of.iter().enumerate() {
            if k != usize::MAX {
                d[k] = s.masses_kg[dof / 3] * self.w;
            }
        }
        for sp in self.springs {
            for a in 0..3 {
                let k = dof_of[3 * sp.node as usize + a];
                if k != usize::MAX {
                    d[k] += sp.stiffness_n_per_m;
                }
            }
        }
        d
    }

    /// The load the step's residual is measured against (with the reactions), newtons: the body
    /// force `Σ_i m_i |a|`, never below [`super::residual::load_floor_n`].
    pub fn load_n(&self) -> f64 {
        let s = self.input;
        let body_force: f64 = s.masses_kg.iter().map(|m| m * s.body_acceleration.norm()).sum();
        let (lo, hi) = s.mesh.bounding_box();
        let size = (hi - lo).norm();
        body_force.max(super::residual::load_floor_n(s.material.lame().mu_pa, size))
    }
}
