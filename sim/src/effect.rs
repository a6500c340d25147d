//! Effects: opt-in units a scene lists (gravity, clamps, …). The solver runs only the effects
//! it was given, so a scene without gravity does no gravity work and one without contact never
//! tests for contact.
//!
//! An effect may pin nodes (their inverse mass becomes 0: the solver's constraints never move
//! them) and hooks into the substep at three places:
//! 1. [`Effect::before_prediction`]: external accelerations (`v += h a`);
//! 2. [`Effect::after_prediction`]: positions of pinned or driven nodes at the new time;
//! 3. [`Effect::after_projection`]: constraints of its own after each solver iteration (contact);
//! 4. [`Effect::after_velocity_update`]: velocity changes (damping).

use crate::Vec3;
use crate::mesh::Mesh;

/// The part of the solver state an effect may read and change during a substep.
pub struct EffectState<'a> {
    /// Time at the end of the substep being taken, seconds.
    pub time_secs: f64,
    /// Substep length, seconds.
    pub dt_secs: f64,
    pub rest_positions: &'a [Vec3],
    pub positions: &'a mut [Vec3],
    pub prev_positions: &'a [Vec3],
    pub velocities: &'a mut [Vec3],
    pub inv_mass: &'a [f64],
}

/// An opt-in effect. Every hook defaults to doing nothing.
pub trait Effect: Send + Sync {
    /// A short name for counters, logs and error messages ("gravity", "clamp", …).
    fn name(&self) -> &'static str;
    /// Nodes this effect positions itself (clamped or driven): the solver gives them zero
    /// inverse mass.
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        Vec::new()
    }
    fn before_prediction(&mut self, _state: &mut EffectState<'_>) {}
    fn after_prediction(&mut self, _state: &mut EffectState<'_>) {}
    fn after_projection(&mut self, _state: &mut EffectState<'_>) {}
    fn after_velocity_update(&mut self, _state: &mut EffectState<'_>) {}
    /// Work done so far (for example nodes accelerated or contact tests made), for the tests
    /// that show an effect not called for costs nothing.
    fn work_count(&self) -> u64 {
        0
    }
}

/// Uniform gravity: `v += h g` for every free node.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    pub acceleration_m_s2: Vec3,
    nodes_accelerated: u64,
}

impl Gravity {
    pub fn new(acceleration_m_s2: Vec3) -> Self {
        Self { acceleration_m_s2, nodes_accelerated: 0 }
    }
}

impl Effect for Gravity {
    fn name(&self) -> &'static str {
        "gravity"
    }
    fn before_prediction(&mut self, s: &mut EffectState<'_>) {
        let dv = self.acceleration_m_s2 * s.dt_secs;
        for (v, w) in s.velocities.iter_mut().zip(s.inv_mass) {
            if *w > 0.0 {
                *v += dv;
            }
        }
        self.nodes_accelerated += s.velocities.len() as u64;
    }
    fn work_count(&self) -> u64 {
        self.nodes_accelerated
    }
}

/// Clamps nodes at their rest positions.
#[derive(Clone, Debug, PartialEq)]
pub struct Clamp {
    pub nodes: Vec<u32>,
}

impl Effect for Clamp {
    fn name(&self) -> &'static str {
        "clamp"
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

/// Velocity damping `v ← v e^{−c h}` with rate `c` (1/s): motion decays as `e^{−c t}`.
#[derive(Clone, Debug, PartialEq)]
pub struct Damping {
    pub rate_per_sec: f64,
}

impl Effect for Damping {
    fn name(&self) -> &'static str {
        "damping"
    }
    fn after_velocity_update(&mut self, s: &mut EffectState<'_>) {
        let factor = (-self.rate_per_sec * s.dt_secs).exp();
        for v in s.velocities.iter_mut() {
            *v *= factor;
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
    fn pinned_nodes(&self, _mesh: &Mesh) -> Vec<u32> {
        self.nodes.clone()
    }
    fn after_prediction(&mut self, s: &mut EffectState<'_>) {
        for &n in &self.nodes {
            s.positions[n as usize] = self.target(&s.rest_positions[n as usize], s.time_secs);
        }
    }
}

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
    fn work_count(&self) -> u64 {
        self.tests
    }
}

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
    fn after_prediction(&mut self, _s: &mut EffectState<'_>) {
        self.lambda = 0.0;
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

    fn state<'a>(
        t: f64,
        rest: &'a [Vec3],
        x: &'a mut [Vec3],
        prev: &'a [Vec3],
        v: &'a mut [Vec3],
        w: &'a [f64],
    ) -> EffectState<'a> {
        EffectState {
            time_secs: t,
            dt_secs: 0.01,
            rest_positions: rest,
            positions: x,
            prev_positions: prev,
            velocities: v,
            inv_mass: w,
        }
    }

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
