//! A node pulled towards a target by a compliant XPBD distance constraint ([`Attachment`]).

use super::{Effect, EffectState};
use crate::Vec3;

/// The least compliance an attachment has as a spring under the implicit solvers, m/N.
pub const MIN_SPRING_COMPLIANCE_M_PER_N: f64 = 1e-9;

/// Pulls one node towards a target point through a compliant distance constraint
/// `C = |x − target|` with compliance `α` (m/N), solved by the XPBD update
/// ([`crate::xpbd::constraint::xpbd_step`]). The app creates one while a node is dragged.
#[derive(Clone, Debug, PartialEq)]
pub struct Attachment {
    pub node: u32,
    pub target_m: Vec3,
    pub compliance_m_per_n: f64,
    lambda: f64,
}

impl Attachment {
    pub fn new(node: u32, target_m: Vec3, compliance_m_per_n: f64) -> Self {
        Self { node, target_m, compliance_m_per_n, lambda: 0.0 }
    }
}

impl Effect for Attachment {
    fn name(&self) -> &'static str {
        "attachment"
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Potential
    }
    /// For the implicit solvers, the attachment is the spring of stiffness `1/α` (α at least
    /// [`MIN_SPRING_COMPLIANCE_M_PER_N`], so a rigid attachment stays a finite spring).
    fn spring(&self) -> Option<super::NodeSpring> {
        Some(super::NodeSpring {
            node: self.node,
            target_m: self.target_m,
            stiffness_n_per_m: 1.0 / self.compliance_m_per_n.max(MIN_SPRING_COMPLIANCE_M_PER_N),
        })
    }
    fn after_prediction(&mut self, _s: &mut EffectState<'_>) {
        self.lambda = 0.0;
    }
    /// Its node's distance to the target: a drag may carry the node (and the body) that far.
    fn reach_m(&self, positions: &[Vec3], _rest_positions: &[Vec3], _time_secs: f64, _dt_secs: f64) -> f64 {
        positions.get(self.node as usize).map_or(0.0, |x| (x - self.target_m).norm())
    }
    fn after_projection(&mut self, s: &mut EffectState<'_>) {
        let i = self.node as usize;
        let w = s.inv_mass[i];
        let d = s.positions[i] - self.target_m;
        let c = d.norm();
        if w == 0.0 || c == 0.0 {
            return;
        }
        let alpha_tilde = self.compliance_m_per_n / (s.dt_secs * s.dt_secs);
        if let Some((d_lambda, step)) = crate::xpbd::constraint::xpbd_step(c, 1.0, w, alpha_tilde, self.lambda) {
            self.lambda += d_lambda;
            s.positions[i] += d / c * (step * w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::test_state as state;

    #[test]
    fn a_stiff_attachment_brings_its_node_to_the_target() {
        let mut a = Attachment::new(0, Vec3::new(1.0, 2.0, 3.0), 0.0);
        let rest = [Vec3::zeros()];
        let mut x = [Vec3::zeros()];
        let prev = x;
        let mut v = [Vec3::zeros()];
        let w = [0.5];
        a.after_projection(&mut state(0.0, &rest, &mut x, &prev, &mut v, &w));
        assert!((x[0] - Vec3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
    }
}
