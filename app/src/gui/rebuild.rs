//! Work a configuration change hands to the background so that the window stays responsive
//! (issue #57): new meshes built ([`Build`]; 655,360 elements built in place froze the window
//! for minutes), and a lesson's static step's equilibrium solved again for the values typed
//! ([`StaticJobs`]; the old shape stayed labelled "static equilibrium"). Both are polled by the
//! model, which installs what is still wanted.

use super::background::{Background, Pending};
use super::config::{self, Config, Invalidates};
use super::cost;
use super::session::Session;
use hox_sim::Vec3;
use hox_sim::element::ElementType;

/// Whether `new` applies to `s` at once, in place (well under a second): a change of settings;
/// a new material on a mesh of at most [`cost::IN_PLACE_NODE_VISITS`] element–node pairs (another ν
/// or model has the guard visit every element again: 4 s on 655,360 P1 elements, issue #57);
/// a new mesh estimated at most as large (its elements from `s`'s: the grid's cells, ×8 per
/// refinement level). The others are prepared in the background ([`Build`]).
pub fn builds_at_once(s: &Session, new: &Config) -> bool {
    let visits = |elements: f64, element: ElementType| elements * element.reference().num_nodes() as f64;
    let mesh = s.instance.sim.mesh();
    match s.config.invalidated_by(new) {
        Invalidates::Mesh => {
            let cells = |g: &[usize; 3]| g.iter().map(|&n| n.max(1) as f64).product::<f64>();
            let ratio =
                cells(&new.grid) / cells(&s.config.grid) * 8f64.powi(new.refine as i32 - s.config.refine as i32);
            visits(mesh.num_elements() as f64 * ratio, new.element) <= cost::IN_PLACE_NODE_VISITS
        }
        Invalidates::Material => {
            cost::element_node_pairs(&s.instance.sim) <= cost::IN_PLACE_NODE_VISITS
                || !needs_guard_again(&s.config, new)
        }
        Invalidates::Settings | Invalidates::Nothing => true,
    }
}

/// Whether a new material has the stability guard visit every element again (another model
/// or Poisson ratio; E and ρ only scale it).
fn needs_guard_again(old: &Config, new: &Config) -> bool {
    (old.material, old.poisson_ratio) != (new.material, new.poisson_ratio)
}

/// A change held back until the user says: the control, the configuration, what it will cost,
/// and the meshes already built for it (installed as they are if the answer is yes).
pub struct PendingChange {
    pub control: String,
    pub config: Config,
    pub estimate: String,
    pub built: Option<Built>,
}

/// What was prepared in the background for a change: `(session, its new configuration, what
/// it needs)` for each session it changes ([`Prepared`]).
pub type Built = Vec<(usize, Config, Prepared)>;

/// What a change needs, prepared in the background for one session.
pub enum Prepared {
    /// Its new mesh, built.
    Built(Box<hox_scenes::Instance>),
    /// The rest ω² of its new material on its mesh (the stability guard's).
    Guard(hox_sim::solver::stability::RestOmega2),
    /// Nothing (a change the session takes at once: the other configuration's linked field).
    Nothing,
}

impl Prepared {
    /// Applies `config` to `s` with what was prepared for it.
    pub fn install(self, s: &mut Session, config: Config) -> Result<Invalidates, String> {
        match self {
            Prepared::Built(instance) => s.apply_with(config, Some(*instance)),
            Prepared::Guard(omega2) => {
                s.instance.sim.seed_rest_omega2(omega2);
                s.apply(config)
            }
            Prepared::Nothing => s.apply(config),
        }
    }
}

/// A job of [`Build`]'s for one session.
enum Work {
    Build(Box<hox_scenes::Scene>),
    Guard(Box<dyn FnOnce() -> Result<hox_sim::solver::stability::RestOmega2, hox_sim::solver::SimError> + Send>),
    Nothing,
}

/// A change whose meshes or stability guards take long, prepared in the background; estimated
/// once built (`ask`: asked first when slow), then installed.
pub struct Build {
    pub control: String,
    pub ask: bool,
    /// `(session, its new configuration)` for each session the change changes.
    configs: Vec<(usize, Config)>,
    /// Whether a new mesh is built (else only stability guards are computed).
    meshes: bool,
    prepared: Pending<Result<Vec<Prepared>, String>>,
}

impl Build {
    /// Starts preparing `configs` (`(session, new configuration)`) of `sessions` on
    /// `background`, each checked against the table first: a refusal names the session's
    /// configuration (`active`'s plainly, the other's as the other's).
    pub fn start(
        control: &str,
        ask: bool,
        configs: Vec<(usize, Config)>,
        sessions: &[Session],
        active: usize,
        background: Background,
    ) -> Result<Build, String> {
        let mut work = Vec::new();
        for (j, c) in &configs {
            let s = &sessions[*j];
            let scene = match config::resolve(c, &s.base) {
                Ok(scene) => scene,
                Err(reason) if *j == active => return Err(reason),
                Err(reason) => return Err(format!("the other configuration refused it: {reason}")),
            };
            work.push(match s.config.invalidated_by(c) {
                Invalidates::Mesh => Work::Build(Box::new(scene)),
                Invalidates::Material if needs_guard_again(&s.config, c) => {
                    Work::Guard(Box::new(s.instance.sim.rest_omega2_job(&scene.material())))
                }
                _ => Work::Nothing,
            });
        }
        let meshes = work.iter().any(|w| matches!(w, Work::Build(_)));
        let prepared = background.run(move || {
            work.into_iter()
                .map(|w| match w {
                    Work::Build(scene) => hox_scenes::Instance::new(*scene)
                        .map(|i| Prepared::Built(Box::new(i)))
                        .map_err(|e| e.to_string()),
                    Work::Guard(job) => job().map(Prepared::Guard).map_err(|e| e.to_string()),
                    Work::Nothing => Ok(Prepared::Nothing),
                })
                .collect()
        });
        Ok(Build { control: control.to_string(), ask, configs, meshes, prepared })
    }

    /// "building P1 32×2×2 for grid…" ("preparing … for poisson…" when no mesh is built: the
    /// stability guard's element loop), for the status line.
    pub fn status(&self, base: &hox_scenes::Scene) -> String {
        let what: Vec<String> = self.configs.iter().map(|(_, c)| config::label(c, base)).collect();
        let verb = if self.meshes { "building" } else { "preparing" };
        format!("{verb} {} for {}…", what.join(" and "), self.control)
    }

    pub fn is_ready(&self) -> bool {
        self.prepared.is_ready()
    }

    /// What was prepared, with its sessions and configurations; or why not.
    pub fn finish(self) -> Result<Built, String> {
        let prepared =
            self.prepared.take().unwrap_or_else(|| Err("preparing the change stopped unexpectedly".into()))?;
        Ok(self.configs.into_iter().zip(prepared).map(|((k, c), p)| (k, c, p)).collect())
    }
}

/// The static equilibrium of a session's configuration, solved in the background; shown once
/// ready if the session still has that configuration and mesh, else dropped.
struct StaticJob {
    session: usize,
    config: Config,
    build: u64,
    positions: Pending<Result<Vec<Vec3>, String>>,
}

/// The static equilibria being solved ([`StaticJob`]).
#[derive(Default)]
pub struct StaticJobs(Vec<StaticJob>);

impl StaticJobs {
    /// Solves the static equilibrium of session `k`'s configuration on `background`; until it
    /// is shown, its readout and the lesson's numbers say so.
    pub fn start(&mut self, k: usize, s: &mut Session, background: Background) {
        let (scene, mesh) = (s.instance.scene.clone(), s.instance.sim.mesh().clone());
        s.solving_static = true;
        let positions = background.run(move || super::session::static_positions(&scene, &mesh));
        self.0.push(StaticJob { session: k, config: s.config.clone(), build: s.revisions().build, positions });
    }

    /// Shows the equilibria solved since where the configuration is still theirs: whether any
    /// was shown, and a message if one failed.
    pub fn poll(&mut self, sessions: &mut [Session]) -> (bool, Option<String>) {
        let (mut shown, mut message) = (false, None);
        for job in std::mem::take(&mut self.0) {
            if !job.positions.is_ready() {
                self.0.push(job);
                continue;
            }
            let Some(s) = sessions.get_mut(job.session) else { continue };
            if s.config != job.config || s.revisions().build != job.build {
                continue;
            }
            s.solving_static = false;
            match job.positions.take() {
                Some(Ok(positions)) => s.show_static_solution(&positions),
                Some(Err(e)) => message = Some(format!("the static equilibrium of {}: {e}", s.label())),
                None => message = Some("solving the static equilibrium stopped unexpectedly".into()),
            }
            shown = true;
        }
        (shown, message)
    }
}

/// The second configuration compare mode starts with, for `first`: P2 is compared with P1
/// refined once (the same nodes), P1 with P2; a part meshed per element type at the other
/// order (P1's facets against P2's curved faces); else a copy.
pub fn compare_partner(first: &Session) -> Result<Session, String> {
    use hox_sim::element::ElementType;
    let mut c = first.config.clone();
    let other = match c.element.name() {
        "p2" => Some(("p1", 1)),
        "p1" => Some(("p2", 0)),
        _ => None,
    };
    if let Some((name, refine)) = other
        && let Some(element) = ElementType::from_name(name)
    {
        if first.base.is_box() {
            c.element = element;
            c.refine = refine;
        }
        if first.base.mesh_kind() == hox_scenes::params::MeshKind::Files {
            c.element = element;
        }
    }
    Session::new(first.base.clone(), c).or_else(|_| Session::new(first.base.clone(), first.config.clone()))
}

/// One session per `overrides` on `base`'s own configuration (the text that asked for each
/// names it in a refusal).
pub fn configured(
    base: &hox_scenes::Scene,
    overrides: &[(Option<String>, hox_scenes::SceneOverrides)],
) -> Result<Vec<Session>, String> {
    let mut sessions = Vec::new();
    for (spec, o) in overrides {
        let scene = base.with_overrides(o).map_err(|e| match spec {
            Some(spec) => format!("--compare '{spec}': {e}"),
            None => e.to_string(),
        })?;
        sessions.push(Session::new(base.clone(), scene.params().clone())?);
    }
    Ok(sessions)
}

/// The sessions of a scene loaded with the `saved` configurations (at most two), or its own; a
/// saved configuration the scene no longer accepts falls back to the scene's own.
pub fn loaded(base: &hox_scenes::Scene, saved: Option<Vec<Config>>) -> Result<Vec<Session>, String> {
    let defaults = config::from_scene(base);
    let wanted = saved.filter(|c| !c.is_empty()).unwrap_or_else(|| vec![defaults.clone()]);
    let mut sessions = Vec::new();
    for c in wanted.into_iter().take(2) {
        sessions.push(Session::new(base.clone(), c).or_else(|_| Session::new(base.clone(), defaults.clone()))?);
    }
    Ok(sessions)
}

/// Whether a change from `old` to `new` changes how a configuration is drawn (a `[display]`
/// parameter of the table).
pub fn redraws(old: &Config, new: &Config) -> bool {
    old.changed_keys(new)
        .iter()
        .any(|k| hox_scenes::params::by_key(k).is_some_and(|p| p.group == hox_scenes::params::Group::Display))
}

/// The question about meshes `built` for a change, if one would be slower than the machine
/// plays ([`cost::too_slow_built`]).
pub fn question(built: &Built, sessions: &[Session], rates: &cost::Rates, draw_ms: f64) -> Option<String> {
    built.iter().find_map(|(k, c, p)| {
        let s = sessions.get(*k)?;
        match p {
            Prepared::Built(i) => cost::too_slow_built(s, &i.sim, rates, draw_ms),
            Prepared::Guard(w) => cost::too_slow_material(s, c, Some(w.per_e_over_rho.0), rates, draw_ms),
            Prepared::Nothing => None,
        }
    })
}

/// The other configuration `other` after the linked fields of a change from `old` to `new`.
pub fn follow(links: &super::links::Links, old: &Config, new: &Config, other: &Config) -> Config {
    let mut follow = other.clone();
    for f in old.changed_keys(new) {
        if links.linked(f) {
            follow.copy_from(new, f);
        }
    }
    follow
}
