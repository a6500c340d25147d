//! Nodes held or moved by prescription: [`Clamp`] (held at rest) and [`Prescribed`] (rest
//! position rotated and translated, ramped in by [`smooth_ramp`]).

use super::{Effect, EffectState};
use crate::Vec3;
use crate::mesh::Mesh;

/// Clamps nodes at their rest positions.
#[derive(Clone, Debug, PartialEq)]
pub struct Clamp {
    pub nodes: Vec<u32>,
}

impl Effect for Clamp {
    fn name(&self) -> &'static str {
        "clamp"
    }
    fn does_no_work(&self) -> bool {
        true
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Hooks
    }
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        self.nodes.clone()
    }
    fn after_prediction(&mut self, s: &mut EffectState<'_>) {
        for &n in &self.nodes {
            s.positions[n as usize] = s.rest_positions[n as usize];
            s.velocities[n as usize] = Vec3::zeros();
        }
    }
}

/// Smooth ramp from 0 at t = 0 to 1 at `t = ramp_secs` (quintic "smootherstep": zero velocity and
/// acceleration at both ends), then held at 1.
pub fn smooth_ramp(time_secs: f64, ramp_secs: f64) -> f64 {
    if ramp_secs <= 0.0 {
        return 1.0;
    }
    let s = (time_secs / ramp_secs).clamp(0.0, 1.0);
    s * s * s * (s * (6.0 * s - 15.0) + 10.0)
}

/// A rotation about an axis through a point.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisRotation {
    /// Unit axis (right-handed).
    pub axis: Vec3,
    pub origin_m: Vec3,
    pub angle_rad: f64,
}

/// Prescribed motion of a set of nodes: at time t, node X goes to
/// `origin + R(s θ)(X − origin) + s · translation`, with `s` = [`smooth_ramp`]`(t, ramp_secs)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Prescribed {
    pub nodes: Vec<u32>,
    pub translation_m: Vec3,
    pub rotation: Option<AxisRotation>,
    pub ramp_secs: f64,
}

impl Prescribed {
    /// Where rest point `rest` is driven at `time_secs`.
    pub fn target(&self, rest: &Vec3, time_secs: f64) -> Vec3 {
        let s = smooth_ramp(time_secs, self.ramp_secs);
        let mut p = *rest;
        if let Some(r) = &self.rotation {
            let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(r.axis), s * r.angle_rad);
            p = r.origin_m + rot * (p - r.origin_m);
        }
        p + self.translation_m * s
    }
}

impl Effect for Prescribed {
    fn name(&self) -> &'static str {
        "prescribed"
    }
    fn implicit_role(&self) -> super::ImplicitRole {
        super::ImplicitRole::Hooks
    }
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        self.nodes.clone()
    }
    fn after_prediction(&mut self, s: &mut EffectState<'_>) {
        for &n in &self.nodes {
            s.positions[n as usize] = self.target(&s.rest_positions[n as usize], s.time_secs);
        }
    }
    /// The farthest its nodes travel in the step (their targets' chord).
    fn reach_m(&self, _positions: &[Vec3], rest_positions: &[Vec3], time_secs: f64, dt_secs: f64) -> f64 {
        self.nodes
            .iter()
            .map(|&n| {
                let rest = &rest_positions[n as usize];
                (self.target(rest, time_secs + dt_secs) - self.target(rest, time_secs)).norm()
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_is_smooth_and_held() {
        assert_eq!(smooth_ramp(0.0, 1.0), 0.0);
        assert_eq!(smooth_ramp(1.0, 1.0), 1.0);
        assert_eq!(smooth_ramp(5.0, 1.0), 1.0);
        assert!((smooth_ramp(0.5, 1.0) - 0.5).abs() < 1e-15);
        // zero slope at both ends
        assert!(smooth_ramp(1e-3, 1.0) < 1e-8 && 1.0 - smooth_ramp(1.0 - 1e-3, 1.0) < 1e-8);
    }

    #[test]
    fn prescribed_rotation_is_right_handed_and_ramped() {
        let p = Prescribed {
            nodes: vec![0],
            translation_m: Vec3::zeros(),
            rotation: Some(AxisRotation {
                axis: Vec3::x(),
                origin_m: Vec3::new(1.0, 0.25, 0.25),
                angle_rad: std::f64::consts::FRAC_PI_2,
            }),
            ramp_secs: 1.0,
        };
        // +90° about +x takes +y to +z: the corner (1, 0.5, 0.25) goes to (1, 0.25, 0.5)
        let got = p.target(&Vec3::new(1.0, 0.5, 0.25), 2.0);
        assert!((got - Vec3::new(1.0, 0.25, 0.5)).norm() < 1e-12, "{got}");
        assert_eq!(p.target(&Vec3::new(1.0, 0.5, 0.25), 0.0), Vec3::new(1.0, 0.5, 0.25));
    }
}
