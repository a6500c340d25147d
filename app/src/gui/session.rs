//! One running configuration in the app (the run, part of the model): the simulation, its
//! history for the plots, its reference solution and its readout against it
//! ([`super::readout`]), the *Settle* action and the drag. How it is drawn (its display
//! surface, held nodes, colour field) is its view, kept by the viewport
//! ([`super::session_view::SessionView`]), which follows the revisions counted here.
//!
//! A configuration change rebuilds only what it invalidates ([`Invalidates`]): a material or
//! solver change keeps the current positions and velocities; a mesh change rebuilds from rest.

use super::config::{self, Config, Invalidates};
use super::readout::{Readout, ReferenceState, last_oscillation};
use hox_scenes::reference::physics_key;
use hox_scenes::study::motion::Motion;
use hox_scenes::{Instance, Scene};
use hox_scenes::{RestWatch, SettleState, Settler};
use hox_sim::Vec3;
use hox_sim::effect::Attachment;
use hox_sim::measure::field::Field;
use std::sync::atomic::{AtomicU64, Ordering};
use web_time::Instant;

/// Samples kept for the time plots (older ones are dropped).
const HISTORY_LEN: usize = 20_000;

/// Time series of one session, for the plots.
#[derive(Clone, Debug, Default)]
pub struct History {
    pub time_secs: Vec<f64>,
    /// First probe's displacement components, metres.
    pub probe_m: Vec<[f64; 3]>,
    pub kinetic_j: Vec<f64>,
    pub elastic_j: Vec<f64>,
}

impl History {
    fn push(&mut self, t: f64, probe: [f64; 3], kinetic: f64, elastic: f64) {
        if self.time_secs.len() >= HISTORY_LEN {
            let drop = HISTORY_LEN / 10;
            self.time_secs.drain(..drop);
            self.probe_m.drain(..drop);
            self.kinetic_j.drain(..drop);
            self.elastic_j.drain(..drop);
        }
        self.time_secs.push(t);
        self.probe_m.push(probe);
        self.kinetic_j.push(kinetic);
        self.elastic_j.push(elastic);
    }
}

/// A node being dragged with the mouse: an attachment effect that exists only meanwhile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drag {
    pub node: u32,
    pub target_m: Vec3,
}

/// Compliance of the mouse attachment, m/N (stiff, but not rigid).
const DRAG_COMPLIANCE_M_PER_N: f64 = 1e-6;

/// The labels of `sessions`, told apart where they would read the same
/// ([`config::distinct_labels`]).
pub fn labels(sessions: &[Session]) -> Vec<String> {
    match sessions.first() {
        Some(first) => config::distinct_labels(&sessions.iter().map(|s| &s.config).collect::<Vec<_>>(), &first.base),
        None => Vec::new(),
    }
}

/// The static equilibrium of `scene` on `mesh` (hox's static solver): the positions a lesson's
/// static step shows. Pure, so that it runs in the background as well as here.
pub fn static_positions(scene: &hox_scenes::scene::Scene, mesh: &hox_sim::mesh::Mesh) -> Result<Vec<Vec3>, String> {
    hox_scenes::solve_static(scene, mesh, 1e-9, 10, &mut |_, _, _| {}).map(|s| s.positions).map_err(|e| e.to_string())
}

/// Mesh builds, numbered across every session (a view is of one build).
static BUILDS: AtomicU64 = AtomicU64::new(1);

/// What a view of a session follows: the mesh build, and revisions of the solver settings (the
/// quadrature points drawn) and of the reference (the error field's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Revisions {
    pub build: u64,
    pub settings: u64,
    pub reference: u64,
}

/// How many frames' wall times a session keeps ([`Session::frame_ms`]).
pub const FRAME_MS_KEPT: usize = 10_000;

pub struct Session {
    pub base: Scene,
    pub config: Config,
    pub instance: Instance,
    pub history: History,
    /// The reference of the physics on screen (committed, computing or computed).
    pub reference: ReferenceState,
    /// Quiet frames and frames in equilibrium (what the readout calls settled).
    pub rest: RestWatch,
    /// The *Settle* action under way (settle damping added until at rest).
    pub settler: Option<Settler>,
    /// How the last *Settle* ended.
    pub settle_outcome: Option<SettleState>,
    /// Simulated time until which prescribed motion is under way (nothing counts as at rest).
    driven_until_secs: f64,
    /// The readout as of the last change (step, reset, configuration, reference): the UI reads
    /// it several times a frame, the history scan it needs runs once.
    readout: Readout,
    /// Wall time of the last frames' stepping, exponentially averaged, milliseconds.
    pub ms_per_frame: f64,
    /// Wall time of every frame stepped since the last reset (at most [`FRAME_MS_KEPT`]), ms: a
    /// lesson's "ms per frame" is their median, as `hox lesson`'s.
    pub frame_ms: Vec<f64>,
    /// The smallest det F over every quadrature point since the last reset, when
    /// `watch_min_det_f` (a lesson measuring it; each frame costs a pass over the elements).
    pub min_det_f: f64,
    pub watch_min_det_f: bool,
    /// The static equilibrium was solved and is shown, not stepped since.
    pub shown_static: bool,
    /// The simulated time of the last change of the physics (material, solver settings) since
    /// the body was last at rest, solved or reset: what is on screen then is not the state of
    /// the parameters shown, and the readout says so until it is again (issue #57: ν typed in a
    /// static step left the old shape labelled "static equilibrium").
    pub changed_at_secs: Option<f64>,
    /// The static equilibrium of the parameters shown is being solved in the background (a
    /// lesson's static step after a change); set and cleared by the model.
    pub solving_static: bool,
    /// The app is paused (set by the app every frame): a swing not yet complete reads "paused".
    pub paused: bool,
    /// The static residual at the last frame: the unbalanced force on the free nodes relative to
    /// the load ([`hox_sim::solver::StaticResidual`]).
    pub residual: f64,
    /// Why the simulation stopped (the NaN guard), until reset.
    pub failure: Option<String>,
    pub drag: Option<Drag>,
    /// The attachment currently in the simulation (follows `drag` at the next step).
    attached: Option<Drag>,
    /// What its view follows ([`Revisions`]).
    revisions: Revisions,
}

impl Session {
    /// A short label of the configuration, e.g. `P2 8×2×2 five` (or "mesh file").
    pub fn label(&self) -> String {
        config::label(&self.config, &self.base)
    }

    /// The configuration `config` of `base`, drawn with `config.tessellation` pieces per face
    /// edge.
    pub fn new(base: Scene, config: Config) -> Result<Session, String> {
        let scene = config::resolve(&config, &base)?;
        let instance = Instance::new(scene).map_err(|e| e.to_string())?;
        let field = crate::display::fields(&config)[0];
        let reference = ReferenceState::for_scene(&instance.scene, field == Field::Error);
        let rest = RestWatch::new(&instance);
        let driven_until_secs = hox_scenes::driven_until_secs(&instance.scene.file.effects);
        let mut s = Session {
            base,
            config,
            instance,
            history: History::default(),
            reference,
            rest,
            settler: None,
            settle_outcome: None,
            driven_until_secs,
            readout: Readout::NotStarted,
            ms_per_frame: 0.0,
            frame_ms: Vec::new(),
            min_det_f: f64::INFINITY,
            watch_min_det_f: false,
            shown_static: false,
            changed_at_secs: None,
            solving_static: false,
            paused: true,
            residual: f64::NAN,
            failure: None,
            drag: None,
            attached: None,
            revisions: Revisions::default(),
        };
        s.mesh_changed();
        s.residual = s.force_residual();
        s.refresh_readout();
        Ok(s)
    }

    /// Applies `new`, rebuilding only what it invalidates. On refusal nothing changes and the
    /// reason is returned.
    pub fn apply(&mut self, new: Config) -> Result<Invalidates, String> {
        self.apply_with(new, None)
    }

    /// [`Session::apply`], with the new mesh's instance already `built` (in the background) when
    /// the change rebuilds it.
    pub fn apply_with(&mut self, new: Config, built: Option<Instance>) -> Result<Invalidates, String> {
        if new == self.config {
            return Ok(Invalidates::Nothing);
        }
        let what = self.config.invalidated_by(&new);
        // every change is checked against the table, a display one too
        let scene = config::resolve(&new, &self.base)?;
        match what {
            Invalidates::Mesh => {
                self.instance = match built {
                    Some(instance) => instance,
                    None => Instance::new(scene).map_err(|e| e.to_string())?,
                };
                self.history = History::default();
                self.failure = None;
                self.drag = None;
                self.attached = None;
                self.settler = None;
                self.settle_outcome = None;
                self.rest = RestWatch::new(&self.instance);
                // the old mesh's frame time says nothing of the new one's
                self.ms_per_frame = 0.0;
                self.frame_ms.clear();
                self.driven_until_secs = hox_scenes::driven_until_secs(&self.instance.scene.file.effects);
                self.mesh_changed();
                self.residual = self.force_residual();
            }
            Invalidates::Material => {
                self.instance.sim.set_material(scene.material()).map_err(|e| e.to_string())?;
                self.instance.sim.set_settings(scene.settings()).map_err(|e| e.to_string())?;
                self.instance.scene = scene;
                self.physics_changed();
            }
            Invalidates::Settings => {
                self.instance.sim.set_settings(scene.settings()).map_err(|e| e.to_string())?;
                self.instance.scene = scene;
                self.revisions.settings += 1;
                self.physics_changed();
            }
            Invalidates::Nothing => self.instance.scene = scene,
        }
        self.config = new;
        // another ν, E, ρ or model: another equilibrium, another reference
        let field = crate::display::fields(&self.config)[0];
        self.reference.follow(&self.instance.scene, field == Field::Error);
        self.revisions.reference += 1;
        self.refresh_readout();
        Ok(what)
    }

    /// After a change of the physics on the same mesh: the state on screen (solved, settled or
    /// swinging) was of the old parameters; nothing is called at rest, settled or in
    /// equilibrium until it is again for the new ones.
    fn physics_changed(&mut self) {
        self.shown_static = false;
        self.rest = RestWatch::new(&self.instance);
        self.settle_outcome = None;
        self.changed_at_secs = Some(self.instance.sim.time_secs());
        self.residual = self.force_residual();
    }

    /// After a (re)build: a new build for the views, the first history sample.
    fn mesh_changed(&mut self) {
        self.changed_at_secs = None;
        self.shown_static = false;
        self.revisions.build = BUILDS.fetch_add(1, Ordering::Relaxed);
        self.record();
    }

    /// What a view of this session follows.
    pub fn revisions(&self) -> Revisions {
        self.revisions
    }

    /// Back to the rest state at t = 0.
    pub fn reset(&mut self) {
        self.instance.sim.reset();
        self.instance.sim.remove_effects_named("attachment");
        self.instance.sim.remove_effects_named(hox_scenes::SETTLE_DAMPING_NAME);
        self.drag = None;
        self.attached = None;
        self.failure = None;
        self.settler = None;
        self.settle_outcome = None;
        self.rest = RestWatch::new(&self.instance);
        self.history = History::default();
        self.frame_ms.clear();
        self.min_det_f = f64::INFINITY;
        self.shown_static = false;
        self.changed_at_secs = None;
        self.watch();
        self.record();
        self.refresh_readout();
    }

    /// Takes the smallest det F in, when watched.
    pub fn watch(&mut self) {
        if self.watch_min_det_f {
            let sim = &self.instance.sim;
            if let Some(m) = hox_sim::measure::min_det_f(sim.mesh(), sim.geometry(), &sim.positions) {
                self.min_det_f = self.min_det_f.min(m.det_f);
            }
        }
    }

    /// Steps `frames` frames (stopping at a failure).
    pub fn step(&mut self, frames: usize) {
        if self.failure.is_some() {
            return;
        }
        self.sync_drag();
        self.shown_static &= frames == 0;
        for _ in 0..frames {
            let t0 = Instant::now();
            let result = self.instance.sim.step_frame();
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            self.ms_per_frame = if self.ms_per_frame == 0.0 { ms } else { 0.9 * self.ms_per_frame + 0.1 * ms };
            if self.frame_ms.len() < FRAME_MS_KEPT {
                self.frame_ms.push(ms);
            }
            if let Err(e) = result {
                self.failure = Some(format!("{e} — press Reset (R)"));
                self.settler = None;
                break;
            }
            self.watch();
            self.record();
            let driving = self.instance.sim.time_secs() < self.driven_until_secs || self.drag.is_some();
            self.rest.observe(&self.instance, driving);
            if let Some(settler) = &mut self.settler {
                let state = settler.check(&self.instance);
                if state != SettleState::Running {
                    if let Some(s) = self.settler.take() {
                        s.stop(&mut self.instance);
                    }
                    self.settle_outcome = Some(state);
                    break;
                }
            }
        }
        self.residual = self.force_residual();
        self.refresh_readout();
    }

    /// Takes a reference computed in the background in (non-blocking), and with it the readout.
    pub fn poll_reference(&mut self) {
        if self.reference.poll() {
            self.revisions.reference += 1;
            self.refresh_readout();
        }
    }

    /// Shows the static equilibrium of the configuration (hox's static solver), at rest: what
    /// settling tends to, at once (a lesson's `"static"` step).
    pub fn show_static_equilibrium(&mut self) -> Result<(), String> {
        let positions = static_positions(&self.instance.scene, self.instance.sim.mesh())?;
        self.show_static_solution(&positions);
        Ok(())
    }

    /// Shows `positions`, the static equilibrium of the configuration on screen (solved by
    /// [`static_positions`], here or in the background), at rest.
    pub fn show_static_solution(&mut self, positions: &[Vec3]) {
        self.instance.sim.warm_start(positions, 0.0);
        self.history = History::default();
        self.shown_static = true;
        self.solving_static = false;
        self.changed_at_secs = None;
        self.settle_outcome = None;
        self.rest = RestWatch::new(&self.instance);
        self.record();
        self.residual = self.force_residual();
        self.refresh_readout();
    }

    /// Starts the *Settle* action: the scene's settle damping until the body is at rest (as
    /// `hox simulate --settle`), then the damping is removed again.
    pub fn start_settle(&mut self) {
        if self.failure.is_some() || self.settler.is_some() {
            return;
        }
        self.settle_outcome = None;
        match Settler::start(&mut self.instance, hox_scenes::SETTLE_CAP_SECS) {
            Ok(s) => self.settler = Some(s),
            Err(e) => self.failure = Some(e.to_string()),
        }
    }

    /// The probe readout against the reference: settled, or the mean and amplitude of the
    /// motion ([`Readout`]); while the reference is being computed, its progress.
    pub fn readout(&self) -> Readout {
        match (&self.readout, self.reference.reference()) {
            (_, None) => self.reference_pending(),
            // taken in since the last refresh (a test waiting on the computation)
            (Readout::NoReference { .. }, Some(_)) => self.measure_readout(),
            (Readout::Starting { .. }, Some(_)) => Readout::Starting { paused: self.paused },
            (Readout::Changed { .. }, Some(_)) => Readout::Changed { paused: self.paused },
            (r, Some(_)) => r.clone(),
        }
    }

    /// While a provisional reference is in use, what it is: "reference ± 3.98 %, refining
    /// (level 4 of 6)".
    pub fn provisional_note(&self) -> Option<String> {
        self.reference.reference().filter(|r| r.refining.is_some()).and(self.reference.short_status())
    }

    /// The readout under a body's label, and on a line of its own what the reference is while
    /// it is still being refined.
    pub fn readout_label(&self) -> String {
        let readout = self.readout().short_text();
        match self.provisional_note() {
            Some(note) => format!("{readout}\n{note}"),
            None => readout,
        }
    }

    fn reference_pending(&self) -> Readout {
        Readout::NoReference {
            short: self.reference.short_status().unwrap_or_else(|| "no reference".into()),
            why: self.reference.status(),
        }
    }

    fn refresh_readout(&mut self) {
        self.readout = self.measure_readout();
    }

    fn measure_readout(&self) -> Readout {
        let Some(r) = self.reference.reference() else {
            return self.reference_pending();
        };
        if self.shown_static {
            let now = self.instance.probe_displacements();
            return match (r.error_m(&now), r.error_pct(&now)) {
                (Some(error_m), Some(error_pct)) => Readout::Static { error_m, error_pct },
                _ => Readout::missing("the reference has none of this scene's probes"),
            };
        }
        if self.rest.at_rest() {
            let now = self.instance.probe_displacements();
            return match (r.error_m(&now), r.error_pct(&now)) {
                (Some(error_m), Some(error_pct)) => {
                    Readout::Settled { error_m, error_pct, in_equilibrium: self.rest.settled() }
                }
                _ => Readout::missing("the reference has none of this scene's probes"),
            };
        }
        let Some(first) = self.instance.probes.first() else {
            return Readout::missing("the scene has no probes");
        };
        if self.instance.sim.time_secs() == 0.0 && self.changed_at_secs.is_none() {
            return Readout::NotStarted;
        }
        // only the motion since the last change of the physics is of the parameters shown
        let h = &self.history;
        let since = self.changed_at_secs.map_or(0, |t| h.time_secs.partition_point(|&s| s < t));
        let Some((mean, amplitude_m, period_secs, before)) =
            last_oscillation(&h.time_secs[since..], &h.probe_m[since..])
        else {
            return match self.changed_at_secs {
                Some(_) => Readout::Changed { paused: self.paused },
                None => Readout::Starting { paused: self.paused },
            };
        };
        let one = |u: [f64; 3]| vec![(first.name.clone(), u)];
        match (r.error_m(&one(mean)), r.error_pct(&one(mean))) {
            (Some(error_m), Some(error_pct)) => Readout::Moving {
                error_m,
                error_pct,
                amplitude_m,
                period_secs,
                drift_m: before.map(|b| (Vec3::from(mean) - Vec3::from(b)).norm()),
            },
            _ => Readout::missing(&format!("the reference has no probe '{}'", first.name)),
        }
    }
    /// Makes the simulation's mouse attachment match `drag`: replaced when the target moved,
    /// removed on release, untouched otherwise (no effect churn on the stepping path).
    fn sync_drag(&mut self) {
        if self.attached == self.drag {
            return;
        }
        if self.attached.is_some() {
            self.instance.sim.remove_effects_named("attachment");
        }
        if let Some(d) = self.drag {
            let _ =
                self.instance.sim.add_effect(Box::new(Attachment::new(d.node, d.target_m, DRAG_COMPLIANCE_M_PER_N)));
        }
        self.attached = self.drag;
    }

    fn record(&mut self) {
        if self.changed_at_secs.is_some() && self.rest.at_rest() {
            // at rest again, for the parameters shown
            self.changed_at_secs = None;
        }
        let sim = &self.instance.sim;
        let probe = self.instance.probe_displacements().first().map(|p| p.1).unwrap_or_default();
        self.history.push(sim.time_secs(), probe, sim.kinetic_energy_j(), sim.elastic_energy_j());
    }

    /// |f_int + f_ext| / |f_ext| over the free nodes (gravity as the external load); 0 at an
    /// equilibrium, about 1 far from it.
    /// The static residual: the unbalanced force on the free nodes relative to the load, the
    /// measure `hox static` converges on and `--settle` stops on.
    fn force_residual(&self) -> f64 {
        self.instance.sim.static_residual().relative
    }

    /// The reference motion of the bending beam's tip released from rest (Newmark on Q2
    /// 16×4×4, `assets/reference/bending-motion.json`), when it applies to this session: the
    /// built-in bending scene with its own material, gravity and no added damping.
    pub fn reference_motion(&self) -> Option<&'static Motion> {
        static MOTION: std::sync::OnceLock<Option<Motion>> = std::sync::OnceLock::new();
        static BENDING: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
        let bending = BENDING.get_or_init(|| hox_scenes::by_name("bending").ok().map(|b| physics_key(&b)));
        // the same physics as the built-in beam (whatever its mesh or solver), and no damping
        let scene = &self.instance.scene;
        let applies = bending.as_deref() == Some(physics_key(scene).as_str())
            && scene.params().damping_per_sec == 0.0
            && !scene.file.effects.iter().any(|e| matches!(e, hox_scenes::scene::EffectSpec::Damping { .. }));
        if !applies {
            return None;
        }
        MOTION.get_or_init(|| hox_scenes::study::motion::reference_motion().ok()).as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bending() -> Session {
        let scene = hox_scenes::by_name("bending").unwrap();
        let config = config::from_scene(&scene);
        Session::new(scene, Config { tessellation: 2, ..config }).unwrap()
    }

    #[test]
    fn material_change_keeps_positions_mesh_change_rebuilds() {
        let mut s = bending();
        s.step(10);
        let moved = s.instance.sim.positions.clone();
        let mut c = s.config.clone();
        c.youngs_modulus_pa *= 2.0;
        assert_eq!(s.apply(c.clone()), Ok(Invalidates::Material));
        assert_eq!(s.instance.sim.positions, moved, "a material change keeps the state");
        assert_eq!(s.instance.sim.material().youngs_modulus_pa, c.youngs_modulus_pa);
        c.element = hox_sim::element::ElementType::from_name("q2").unwrap();
        c.grid = [4, 1, 1];
        assert_eq!(s.apply(c), Ok(Invalidates::Mesh));
        assert_eq!(s.instance.sim.mesh().num_nodes(), 9 * 3 * 3);
        assert_eq!(s.instance.sim.time_secs(), 0.0);
    }

    /// The reference motion (issue #19) is offered for the bending beam as built, and withdrawn
    /// once the material or the damping makes it another beam.
    #[test]
    fn the_reference_motion_is_offered_only_for_the_beam_it_was_computed_for() {
        let mut s = bending();
        let m = s.reference_motion().expect("bending has a reference motion");
        assert!(m.tip_z_m.len() > 100 && m.tip_z_m[0] == 0.0);
        let mut c = s.config.clone();
        c.youngs_modulus_pa *= 2.0;
        s.apply(c).unwrap();
        assert!(s.reference_motion().is_none(), "a stiffer beam moves otherwise");
        let mut other = bending();
        let mut c = other.config.clone();
        c.damping_per_sec = 1.0;
        other.apply(c).unwrap();
        assert!(other.reference_motion().is_none(), "a damped beam moves otherwise");
        let element = bending();
        let mut c = element.config.clone();
        c.element = hox_sim::element::ElementType::from_name("q2").unwrap();
        let mut element = element;
        element.apply(c).unwrap();
        assert!(element.reference_motion().is_some(), "another mesh of the same beam is compared with it");
    }

    /// Issue #57: a state solved or settled for one value of ν kept its "static equilibrium" or
    /// "settled" label, with the old numbers, once another value was typed.
    #[test]
    fn a_changed_value_never_keeps_the_settled_or_equilibrium_label() {
        let claims = |s: &Session| {
            let said = [s.readout_label(), s.readout().text(), s.readout().error_text()].join(" | ");
            said.contains("equilibrium (") || said.contains("equilibrium:") || said.contains("settled")
        };
        let mut s = bending();
        s.show_static_equilibrium().unwrap();
        assert!(claims(&s), "{}", s.readout_label());
        let mut c = s.config.clone();
        c.poisson_ratio = 0.45;
        s.apply(c.clone()).unwrap();
        s.reference.wait();
        s.poll_reference();
        assert!(!claims(&s), "the old shape under ν 0.45: {}", s.readout().text());
        assert_eq!(s.readout(), Readout::Changed { paused: true });
        // settled at 0.45, then 0.35 typed back: not settled for 0.35 until it is again
        s.start_settle();
        for _ in 0..3000 {
            if s.settle_outcome.is_some() {
                break;
            }
            s.step(1);
        }
        assert!(s.settle_outcome.is_some() && claims(&s), "{}", s.readout().text());
        c.poisson_ratio = 0.35;
        s.apply(c).unwrap();
        assert!(s.reference.reference().is_some(), "the committed reference of ν 0.35");
        assert!(!claims(&s), "{}", s.readout().text());
        // played on, it comes to rest at the new values and says so again
        s.start_settle();
        for _ in 0..3000 {
            if s.settle_outcome.is_some() {
                break;
            }
            s.step(1);
        }
        assert!(claims(&s), "{}", s.readout().text());
    }

    /// Issue #57: "± 0.00 % (refining, 6 of 6)" under a reference at its last level.
    #[test]
    fn a_reference_at_its_last_level_does_not_read_refining_zero_percent() {
        let mut s = bending();
        let mut c = s.config.clone();
        c.poisson_ratio = 0.41;
        s.apply(c).unwrap();
        let mut seen: Vec<String> = Vec::new();
        for _ in 0..40_000 {
            if let Some(note) = s.provisional_note()
                && !seen.contains(&note)
            {
                seen.push(note);
            }
            if !matches!(s.reference, ReferenceState::Computing { .. }) {
                break;
            }
            s.poll_reference();
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        assert!(!seen.is_empty(), "a provisional reference was shown while refining");
        assert!(seen.iter().all(|n| !n.contains("± 0.00 %")), "{seen:?}");
        for n in &seen {
            let at = n.rsplit(", ").next().unwrap_or_default().trim_end_matches(')');
            if let Some((a, b)) = at.split_once(" of ") {
                assert_eq!(n.contains("refining"), a != b, "{n}");
            }
        }
    }

    #[test]
    fn refused_change_changes_nothing() {
        let mut s = bending();
        let before = s.config.clone();
        let mut c = before.clone();
        c.poisson_ratio = 0.7;
        assert!(s.apply(c).is_err());
        assert_eq!(s.config, before);
    }

    /// A display parameter changes only the drawing: checked against the table, stored, the
    /// surface re-tessellated, the simulation's state kept (regression: such a change used to be
    /// dropped without being stored or checked).
    #[test]
    fn a_display_change_is_checked_kept_and_redraws_only() {
        let mut s = bending();
        s.step(3);
        let positions = s.instance.sim.positions.clone();
        let mut view = super::super::session_view::SessionView::new(&s);
        let vertices = view.surface.vertices.len();
        let mut c = s.config.clone();
        c.tessellation = 6;
        c.quadrature_points = true;
        assert_eq!(s.apply(c.clone()), Ok(Invalidates::Nothing));
        assert_eq!(s.config, c);
        view.follow(&s);
        assert!(view.surface.vertices.len() > vertices, "{} vs {vertices}", view.surface.vertices.len());
        assert_eq!(view.rest_vertices.len(), view.surface.vertices.len());
        assert_eq!(s.instance.sim.positions, positions);
        let mut bad = c.clone();
        bad.tessellation = 0;
        let err = s.apply(bad).unwrap_err();
        assert!(err.starts_with("Face segments = 0: "), "the control's label names it: {err}");
        assert_eq!(s.config, c);
    }

    #[test]
    fn dragging_pulls_the_node_and_leaves_no_effect_behind() {
        let mut s = bending();
        let tip =
            s.instance.sim.mesh().rest_positions.iter().enumerate().max_by(|a, b| a.1.x.total_cmp(&b.1.x)).unwrap().0
                as u32;
        let target = s.instance.sim.mesh().rest_positions[tip as usize] + Vec3::new(0.0, 0.0, 0.3);
        s.drag = Some(Drag { node: tip, target_m: target });
        s.step(60);
        assert!((s.instance.sim.positions[tip as usize] - target).norm() < 0.05);
        s.drag = None;
        s.step(1);
        assert!(s.instance.sim.effects().iter().all(|e| e.name() != "attachment"));
    }
}
