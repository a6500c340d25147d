//! Contact with a moving plane, with Coulomb-like positional friction ([`ContactPlane`]).

use super::{Effect, EffectState};
use crate::Vec3;

/// Contact with a plane that may move: the body stays on the side `normal` points to. The plane
/// passes through `point_m + velocity_m_s · min(t, move_secs)`. Penetrating nodes are projected
/// back onto the plane after every solver iteration, with Coulomb-like positional friction:
/// tangential motion during the substep is cancelled up to `friction ×` the penetration depth.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPlane {
    pub point_m: Vec3,
    /// Unit normal pointing into the allowed half-space.
    pub normal: Vec3,
    pub velocity_m_s: Vec3,
    pub move_secs: f64,
    pub friction: f64,
    tests: u64,
}

impl ContactPlane {
    pub fn new(point_m: Vec3, normal: Vec3, velocity_m_s: Vec3, move_secs: f64, friction: f64) -> Self {
        Self { point_m, normal: normal.normalize(), velocity_m_s, move_secs, friction, tests: 0 }
    }
    /// The plane's point at `time_secs`.
    pub fn point_at(&self, time_secs: f64) -> Vec3 {
        self.point_m + self.velocity_m_s * time_secs.min(self.move_secs)
    }
}

impl Effect for ContactPlane {
    fn name(&self) -> &'static str {
        "contact"
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Projection
    }
    fn after_projection(&mut self, s: &mut EffectState<'_>) {
        let p = self.point_at(s.time_secs);
        let n = self.normal;
        for ((x, w), prev) in s.positions.iter_mut().zip(s.inv_mass).zip(s.prev_positions) {
            if *w == 0.0 {
                continue;
            }
            let depth = -(*x - p).dot(&n);
            if depth <= 0.0 {
                continue;
            }
            *x += n * depth;
            if self.friction > 0.0 {
                let moved = *x - prev;
                let tangential = moved - n * moved.dot(&n);
                let t_len = tangential.norm();
                let limit = self.friction * depth;
                *x -= if t_len <= limit { tangential } else { tangential * (limit / t_len) };
            }
        }
        self.tests += s.positions.len() as u64;
    }
    /// How far the plane travels in the step.
    fn reach_m(&self, _positions: &[Vec3], _rest_positions: &[Vec3], time_secs: f64, dt_secs: f64) -> f64 {
        (self.point_at(time_secs + dt_secs) - self.point_at(time_secs)).norm()
    }
    fn work_count(&self) -> u64 {
        self.tests
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effect::test_state as state;

    #[test]
    fn contact_pushes_penetrating_nodes_out_and_counts_its_tests() {
        let mut c = ContactPlane::new(Vec3::zeros(), Vec3::z(), Vec3::zeros(), f64::INFINITY, 0.0);
        let rest = [Vec3::zeros(); 2];
        let mut x = [Vec3::new(0.0, 0.0, -0.1), Vec3::new(1.0, 0.0, 0.2)];
        let prev = x;
        let mut v = [Vec3::zeros(); 2];
        let w = [1.0, 1.0];
        c.after_projection(&mut state(0.0, &rest, &mut x, &prev, &mut v, &w));
        assert_eq!(x[0], Vec3::zeros());
        assert_eq!(x[1], Vec3::new(1.0, 0.0, 0.2));
        assert_eq!(c.work_count(), 2);
    }
}
