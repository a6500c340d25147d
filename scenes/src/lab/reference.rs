//! What an error is measured against: the reference solution of the configuration at hand.
//!
//! A reference is the static equilibrium (probe displacements) of a scene's *physics* — its
//! geometry, material, loads, boundary conditions and probes; not its mesh, solver, quadrature
//! or damping, which do not change the exact equilibrium ([`physics_key`]). Three origins:
//!
//! - **committed**: the physics of a paper scene as built. The fine Q2 solution in
//!   `assets/reference/SCENE-fine.json`, its mesh error estimated from the committed coarse and
//!   medium levels as below.
//! - **computed**: any other physics on a box mesh (another ν, E, ρ or model, a scene file's own
//!   loads). hox's static solver ([`crate::instance::solve_static`]) on triquadratic hexahedra (Q2) at
//!   six levels ([`compute`]): the finest ([`levels`]; bending 32×8×8) and ¼, ⅜, ½, ⅝ and ¾ as
//!   many cells per direction, with provisional estimates on the way. The final reference uses
//!   four of them (¼, ½, ¾, 1): it is the finest level extrapolated
//!   (below) with the order the three finest levels show; its uncertainty is its distance from
//!   the extrapolation by the halving levels (¼, ½, 1) — two independent estimates of the limit.
//! - **own mesh**: a scene on a mesh file. The static solution of that same mesh: it measures
//!   what the solver costs, not what the mesh costs, and is labelled so.
//!
//! **Mesh error of a reference** (Richardson extrapolation; Roache, "Perspective: a method for
//! uniform reporting of grid refinement studies", J. Fluids Eng. 116, 1994): with the
//! largest probe differences `d₁ = |u₁ − u₂|` and `d₂ = |u₂ − u₃|` between levels of cell sizes
//! `h₁ > h₂ > h₃`, the observed order `p` solves `d₁/d₂ = (h₁ᵖ − h₂ᵖ)/(h₂ᵖ − h₃ᵖ)` (for a
//! ratio `r` each time, `p = log_r(d₁/d₂)`), and the finest level's error is
//! `e₃ ≈ d₂ h₃ᵖ/(h₂ᵖ − h₃ᵖ)` (`d₂/(rᵖ − 1)`); the extrapolated limit is
//! `u₃ + (u₃ − u₂) h₃ᵖ/(h₂ᵖ − h₃ᵖ)`. When the levels do not converge monotonically
//! (`d₁ ≤ d₂`) the estimate falls back to `d₂`, the finest level is the reference, and the
//! estimate says so.
//!
//! Computed references are cached by their physics key, in memory and on disk (`HOX_CACHE_DIR`,
//! else `$XDG_CACHE_HOME/hox` or `~/.cache/hox`, folder `references/`), so a configuration is
//! solved once per machine; the page reads the references its site was built with as well
//! ([`read_only_cache`]).

pub mod compute;
pub mod field;

pub use compute::{LEVELS, OnEstimate, Progress, compute_with, grids, level_scene, own_mesh, provisional};
pub use field::ReferenceField;

use crate::error::SceneError;
use crate::params::MeshKind;
use crate::scene::EffectSpec;
use crate::scene::Scene;
use hox_sim::Vec3;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Probe displacements by probe name, metres.
pub type Probes = BTreeMap<String, [f64; 3]>;

/// Where a reference comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// A committed fine solution (`assets/reference/`).
    Committed,
    /// Computed on a fine Q2 mesh of the same box, for the physics at hand.
    Computed,
    /// The static solution of the scene's own mesh (a mesh file): solver error only.
    OwnMesh,
    /// The static solution of the part's highest-order file (a scene with one mesh file per
    /// element type, `[mesh] files`): lower orders measure their mesh error against it.
    HighestOrder,
}

/// A reference solution and how good it is.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reference {
    pub origin: Origin,
    /// The probes' displacements, metres.
    pub probes: Probes,
    /// The mesh it was solved on, e.g. "Q2 32×8×8".
    pub mesh: String,
    /// Estimated mesh error of the reference itself (None for the own-mesh case, whose mesh
    /// error is not what it measures), metres.
    pub estimated_error_m: Option<f64>,
    /// How the estimate was made, e.g. "from three levels, observed order 1.56".
    pub estimate: String,
    /// The Poisson ratio it was solved with (shown in the label).
    pub poisson_ratio: f64,
    /// The displacement field of its finest solution, for the error field (None for the
    /// committed references, which hold probes only, until [`Lookup::with_field`] solves it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<ReferenceField>,
    /// A provisional estimate while finer levels are being solved ([`compute::provisional`]);
    /// None for a finished reference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refining: Option<Refining>,
}

/// How far a computed reference has got: levels solved of levels to solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Refining {
    pub levels_done: usize,
    pub levels: usize,
}

impl Reference {
    /// The largest reference probe displacement, metres: what percentages are relative to.
    pub fn size_m(&self) -> f64 {
        self.probes.values().map(|u| Vec3::from(*u).norm()).fold(0.0, f64::max)
    }

    /// The estimated mesh error in % of [`Reference::size_m`].
    pub fn estimated_error_pct(&self) -> Option<f64> {
        self.estimated_error_m.map(|e| 100.0 * e / self.size_m().max(f64::MIN_POSITIVE))
    }

    /// The largest distance between `probes` and the reference's (matched by name; a probe the
    /// reference lacks is ignored), metres; None when no probe matches.
    pub fn error_m(&self, probes: &[(String, [f64; 3])]) -> Option<f64> {
        probes
            .iter()
            .filter_map(|(name, u)| self.probes.get(name).map(|r| (Vec3::from(*u) - Vec3::from(*r)).norm()))
            .reduce(f64::max)
    }

    /// [`Reference::error_m`] in % of the reference's size.
    pub fn error_pct(&self, probes: &[(String, [f64; 3])]) -> Option<f64> {
        self.error_m(probes).map(|e| 100.0 * e / self.size_m().max(f64::MIN_POSITIVE))
    }

    /// One line for a user: "static, Q2 32×8×8, ν = 0.49, ± 0.31 % (from three levels, observed order 1.6)".
    pub fn label(&self) -> String {
        let refining;
        let what = match (self.origin, self.refining) {
            (_, Some(r)) => {
                refining = format!("provisional, levels 1–{} of {} solved, refining", r.levels_done, r.levels);
                refining.as_str()
            }
            (Origin::Committed, None) => "static (committed)",
            (Origin::Computed, None) => "static, computed",
            (Origin::OwnMesh, None) => "static solution of this mesh",
            (Origin::HighestOrder, None) => "static solution of the part's highest order",
        };
        let estimate = match self.estimated_error_pct() {
            Some(pct) => format!(", ± {pct:.2} % ({})", self.estimate),
            None => format!(" ({})", self.estimate),
        };
        format!("{what}, {}, ν = {}{estimate}", self.mesh, self.poisson_ratio)
    }

    /// The JSON `simulate --json` and `static --json` report under "reference".
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "origin": self.origin,
            "label": self.label(),
            "mesh": self.mesh,
            "poisson_ratio": self.poisson_ratio,
            "probes": self.probes,
            "estimated_error_m": self.estimated_error_m,
            "estimated_error_pct": self.estimated_error_pct(),
            "estimate": self.estimate,
            "provisional": self.refining.is_some(),
        })
    }
}

/// Everything that determines a scene's exact static equilibrium, as canonical text: the box
/// (or the mesh file's path and size), the material, every effect but damping, and the probes.
/// The mesh resolution, element, solver, quadrature, damping and display do not enter.
pub fn physics_key(scene: &Scene) -> String {
    let p = scene.params();
    let geometry = match &scene.mesh {
        crate::scene::SceneMesh::Box(_) => format!("box {:?} {:?}", p.box_min_m, p.box_max_m),
        // a part meshed per element type has one reference whichever file is on screen
        crate::scene::SceneMesh::File { .. } if scene.mesh_kind() == MeshKind::Files => {
            format!("part {:?}", scene.file.mesh_files)
        }
        crate::scene::SceneMesh::File { path, imported } => {
            format!("file {} ({} nodes)", path.display(), imported.mesh.num_nodes())
        }
    };
    let effects: Vec<String> = scene
        .file
        .effects
        .iter()
        .filter(|e| !matches!(e, EffectSpec::Damping { .. }))
        .map(|e| format!("{e:?}"))
        .collect();
    let probes: Vec<String> = scene.file.probes.iter().map(|q| format!("{}@{:?}", q.name, q.point_m)).collect();
    format!(
        "{geometry}; material {} E={:e} nu={:e} rho={:e}; effects [{}]; probes [{}]",
        p.material,
        p.youngs_modulus_pa,
        p.poisson_ratio,
        p.density_kg_m3,
        effects.join(", "),
        probes.join(", ")
    )
}

/// The committed levels of the paper scenes: (scene, [(grid, JSON text)] coarse to fine).
const COMMITTED: [(&str, [([usize; 3], &str); 3]); 3] = [
    (
        "bending",
        [
            ([8, 2, 2], include_str!("../../../assets/reference/bending-coarse.json")),
            ([16, 4, 4], include_str!("../../../assets/reference/bending-medium.json")),
            ([32, 8, 8], include_str!("../../../assets/reference/bending-fine.json")),
        ],
    ),
    (
        "tension",
        [
            ([4, 2, 2], include_str!("../../../assets/reference/tension-coarse.json")),
            ([12, 6, 6], include_str!("../../../assets/reference/tension-medium.json")),
            ([24, 12, 12], include_str!("../../../assets/reference/tension-fine.json")),
        ],
    ),
    (
        "torsion",
        [
            ([4, 2, 2], include_str!("../../../assets/reference/torsion-coarse.json")),
            ([12, 6, 6], include_str!("../../../assets/reference/torsion-medium.json")),
            ([24, 12, 12], include_str!("../../../assets/reference/torsion-fine.json")),
        ],
    ),
];

pub(crate) fn parse_probes(text: &str, source_name: &str) -> Result<Probes, SceneError> {
    let bad = |m: &str| SceneError::Parse { source_name: source_name.to_string(), message: m.to_string() };
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(&e.to_string()))?;
    let probes = v["probes"].as_object().ok_or_else(|| bad("no probes"))?;
    probes
        .iter()
        .map(|(name, u)| {
            let c: Vec<f64> =
                u.as_array().ok_or_else(|| bad("probe is not an array"))?.iter().filter_map(|x| x.as_f64()).collect();
            match c[..] {
                [x, y, z] if c.iter().all(|v| v.is_finite()) => Ok((name.clone(), [x, y, z])),
                _ => Err(bad("a probe needs three finite components")),
            }
        })
        .collect()
}

/// The committed reference of `scene`, if its physics are a paper scene's as built, whatever
/// the scene is called (a lesson's beam with the paper's physics has the paper's reference).
pub fn committed(scene: &Scene) -> Result<Option<Reference>, SceneError> {
    if !scene.is_box() {
        return Ok(None);
    }
    static KEYS: std::sync::OnceLock<Vec<Option<String>>> = std::sync::OnceLock::new();
    let keys = KEYS.get_or_init(|| {
        COMMITTED.iter().map(|(n, _)| crate::scene::builtin::by_name(n).ok().map(|s| physics_key(&s))).collect()
    });
    let key = physics_key(scene);
    let Some(((name, levels), _)) = COMMITTED.iter().zip(keys).find(|(_, k)| k.as_deref() == Some(key.as_str())) else {
        return Ok(None);
    };
    let mut solved = Vec::new();
    for (k, (grid, text)) in levels.iter().enumerate() {
        let level = ["coarse", "medium", "fine"][k];
        let probes = parse_probes(text, &format!("assets/reference/{name}-{level}.json"))?;
        solved.push((compute::cell_size(scene, *grid), probes));
    }
    let (error_m, estimate) = mesh_error(&solved);
    let fine = levels[2].0;
    Ok(Some(Reference {
        origin: Origin::Committed,
        probes: solved.pop().map(|(_, p)| p).unwrap_or_default(),
        mesh: format!("Q2 {}×{}×{}", fine[0], fine[1], fine[2]),
        estimated_error_m: Some(error_m),
        estimate,
        poisson_ratio: scene.params().poisson_ratio,
        field: None,
        refining: None,
    }))
}

/// The largest number of Q2 cells of a computed reference's finest level (the committed
/// bending reference's 32×8×8).
pub const FINEST_CELLS: usize = 2048;

/// The three Q2 grids of a computed reference on a box, coarse to fine: the finest has cells as
/// near cubic as a multiple of four per direction allows and about `finest_cells` cells (at
/// least four per direction); the others have a half and a quarter as many per direction (bending with [`FINEST_CELLS`]: 8×2×2, 16×4×4, 32×8×8).
pub fn levels(box_min_m: [f64; 3], box_max_m: [f64; 3], finest_cells: usize) -> [[usize; 3]; 3] {
    let extent: Vec<f64> = (0..3).map(|d| (box_max_m[d] - box_min_m[d]).abs()).collect();
    let volume: f64 = extent.iter().product();
    // cells per metre for `finest_cells` cubic cells
    let per_m = (finest_cells as f64 / volume.max(f64::MIN_POSITIVE)).cbrt();
    let mut fine = [0usize; 3];
    for d in 0..3 {
        fine[d] = 4 * ((per_m * extent[d] / 4.0).round() as usize).clamp(1, 16);
    }
    let coarse = fine.map(|n| n / 4);
    let medium = fine.map(|n| n / 2);
    [coarse, medium, fine]
}

/// Largest probe distance between two solutions, metres.
fn distance(a: &Probes, b: &Probes) -> f64 {
    a.iter().filter_map(|(n, u)| b.get(n).map(|v| (Vec3::from(*u) - Vec3::from(*v)).norm())).fold(0.0, f64::max)
}

/// The observed order of convergence of three levels `(cell size, probes)`, coarse to fine
/// (module docs); None when they do not converge monotonically (the differences shrink and keep
/// their direction: `Σ (u₂ − u₁)·(u₃ − u₂) > 0` over the probes) or the finest two agree.
/// Regression: P2 mixed at ν = 0.499 turned back between 24×6×6 and 32×8×8 by 6e-5 of the sag
/// after shrinking by 1e-3; fitted by the differences' lengths alone, the order (6.3) carried the
/// limit further the wrong way with a stated error a fifth of the true one.
pub fn observed_order(levels: &[(f64, Probes); 3]) -> Option<f64> {
    let [(h1, u1), (h2, u2), (h3, u3)] = levels;
    let (d1, d2) = (distance(u1, u2), distance(u2, u3));
    if d2 == 0.0 || d1 <= d2 || turns(u1, u2, u3) {
        return None;
    }
    // d1/d2 = (h1^p − h2^p)/(h2^p − h3^p) grows with p: bisection
    let ratio = |p: f64| (h1.powf(p) - h2.powf(p)) / (h2.powf(p) - h3.powf(p));
    let (mut lo, mut hi) = (1e-3, 12.0);
    if ratio(hi) < d1 / d2 {
        lo = hi;
    } else if ratio(lo) > d1 / d2 {
        hi = lo;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < d1 / d2 { lo = mid } else { hi = mid }
    }
    Some(0.5 * (lo + hi))
}

/// Whether the probes' change from `u1` to `u2` and from `u2` to `u3` point apart on the whole:
/// `Σ (u₂ − u₁)·(u₃ − u₂) ≤ 0` over the probes the three share.
fn turns(u1: &Probes, u2: &Probes, u3: &Probes) -> bool {
    let along: f64 = u1
        .iter()
        .filter_map(|(n, a)| {
            let (b, c) = (u2.get(n)?, u3.get(n)?);
            Some((Vec3::from(*b) - Vec3::from(*a)).dot(&(Vec3::from(*c) - Vec3::from(*b))))
        })
        .sum();
    along <= 0.0
}

/// Richardson's extrapolation of two levels with order `p`:
/// `u₃ + (u₃ − u₂) h₃ᵖ/(h₂ᵖ − h₃ᵖ)` per probe component.
pub fn extrapolate((h2, u2): &(f64, Probes), (h3, u3): &(f64, Probes), p: f64) -> Probes {
    let w = h3.powf(p) / (h2.powf(p) - h3.powf(p));
    u3.iter()
        .map(|(n, f)| {
            let m = u2.get(n).copied().unwrap_or(*f);
            (n.clone(), [0, 1, 2].map(|d| f[d] + (f[d] - m[d]) * w))
        })
        .collect()
}

/// The mesh error of the finest of three levels `(cell size, probes)`, coarse to fine, and how
/// it was estimated (module docs).
pub fn mesh_error(levels: &[(f64, Probes)]) -> (f64, String) {
    let [a, b, c] = levels else {
        return (f64::NAN, "needs three levels".into());
    };
    let d2 = distance(&b.1, &c.1);
    if d2 == 0.0 {
        return (0.0, "the two finest levels agree exactly".into());
    }
    match observed_order(&[a.clone(), b.clone(), c.clone()]) {
        Some(p) => (distance(&extrapolate(b, c, p), &c.1), format!("from three levels, observed order {p:.2}")),
        None => (d2, "the difference of the two finest levels; they do not yet converge monotonically".into()),
    }
}

/// Whether a scene's computed reference is cached on disk: a box's (levels of Q2 solves) and a
/// built-in part's (a P3 static solve of seconds); a user's own mesh file may change under its name.
fn on_disk(scene: &Scene) -> bool {
    scene.mesh_kind() != MeshKind::File
}

/// Why a scene has no reference, if it has none: no probes, or contact (no static counterpart).
pub fn unavailable(scene: &Scene) -> Option<String> {
    if scene.file.probes.is_empty() {
        return Some("the scene has no probes".into());
    }
    if scene.file.effects.iter().any(|e| matches!(e, EffectSpec::Contact { .. })) {
        return Some("contact has no static reference".into());
    }
    None
}

/// The folder computed references are cached in (module docs); None without a home.
pub fn cache_dir() -> Option<PathBuf> {
    let base = std::env::var_os("HOX_CACHE_DIR").map(PathBuf::from).or_else(|| {
        std::env::var_os("XDG_CACHE_HOME")
            .map(|d| PathBuf::from(d).join("hox"))
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("hox")))
    })?;
    Some(base.join("references"))
}

/// FNV-1a, 64 bits: the cache file's name from the physics key (the key itself is stored in
/// the file and compared on reading).
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// The name of the cache file of `key` (in the cache folder, or the page's site).
pub fn cache_file_name(key: &str) -> String {
    format!("{:016x}.json", fnv1a(key))
}

/// A read-only cache besides the cache folder: a cache file's text by its name. The page (issue
/// #59) reads the references its site was built with (`references/NAME` on the site, written
/// by `scripts/build-web.sh`), set by [`read_only_cache`]; unset elsewhere.
static READ_ONLY_CACHE: std::sync::OnceLock<fn(&str) -> Option<String>> = std::sync::OnceLock::new();

/// Adds a read-only cache of references ([`READ_ONLY_CACHE`]); a second call changes nothing.
pub fn read_only_cache(read: fn(&str) -> Option<String>) {
    let _ = READ_ONLY_CACHE.set(read);
}

#[derive(serde::Serialize, serde::Deserialize)]
struct Cached {
    key: String,
    reference: Reference,
}

fn memory() -> &'static std::sync::Mutex<BTreeMap<String, Reference>> {
    static MEMORY: std::sync::OnceLock<std::sync::Mutex<BTreeMap<String, Reference>>> = std::sync::OnceLock::new();
    MEMORY.get_or_init(Default::default)
}

/// How references are looked up and computed: the finest level's size and the cache folder
/// (None: no disk cache).
#[derive(Clone, Debug, PartialEq)]
pub struct Lookup {
    pub finest_cells: usize,
    pub cache_dir: Option<PathBuf>,
}

impl Default for Lookup {
    /// [`FINEST_CELLS`] and [`cache_dir`].
    fn default() -> Lookup {
        Lookup { finest_cells: FINEST_CELLS, cache_dir: cache_dir() }
    }
}

impl Lookup {
    /// What determines the reference, as its cache key: the physics and, for a box, the levels
    /// solved; for a mesh file (whose reference is the static solution of that mesh) also the
    /// quadrature it is integrated with.
    pub fn key(&self, scene: &Scene) -> String {
        if scene.is_box() {
            // P2 mixed solves the even grids only (Levels::grids): a key of its own
            let kind = match compute::Levels::of(scene) {
                compute::Levels::Q2 => "Q2 levels",
                compute::Levels::P2Mixed => "P2 mixed even levels",
            };
            format!("{}; {kind} up to {} cells", physics_key(scene), self.finest_cells)
        } else if scene.mesh_kind() == MeshKind::Files {
            format!(
                "{}; the part's highest order, quadrature {:?}",
                physics_key(scene),
                scene.params().quadrature_degree
            )
        } else {
            format!("{}; own mesh, quadrature {:?}", physics_key(scene), scene.params().quadrature_degree)
        }
    }

    fn cache_file(&self, key: &str) -> Option<PathBuf> {
        self.cache_dir.as_ref().map(|d| d.join(cache_file_name(key)))
    }

    /// The reference of `scene` if it is known without solving: committed, or computed before
    /// (in memory, or for a box in the disk cache). Ok(None): it must be computed
    /// ([`Lookup::for_scene`]).
    pub fn known(&self, scene: &Scene) -> Result<Option<Reference>, SceneError> {
        if let Some(r) = committed(scene)? {
            return Ok(Some(r));
        }
        Ok(self.load(&self.key(scene), on_disk(scene)))
    }

    /// A reference stored under `key`: in memory, or (`disk`) in the cache folder.
    fn load(&self, key: &str, disk: bool) -> Option<Reference> {
        if let Some(r) = memory().lock().ok().and_then(|m| m.get(key).cloned()) {
            return Some(r);
        }
        if !disk {
            return None;
        }
        let text = self.cache_file(key).and_then(|path| std::fs::read_to_string(path).ok());
        let text = text.or_else(|| READ_ONLY_CACHE.get().and_then(|read| read(&cache_file_name(key))))?;
        // an unreadable or foreign cache file is recomputed, never trusted
        let cached = serde_json::from_str::<Cached>(&text).ok()?;
        (cached.key == key).then(|| {
            if let Ok(mut m) = memory().lock() {
                m.insert(key.to_string(), cached.reference.clone());
            }
            cached.reference
        })
    }

    /// Keeps `reference` under `key` in memory and (`disk`) in the cache folder.
    fn store(&self, key: &str, reference: &Reference, disk: bool) {
        if let Ok(mut m) = memory().lock() {
            m.insert(key.to_string(), reference.clone());
        }
        if let Some(path) = self.cache_file(key).filter(|_| disk) {
            // the cache is an optimisation: failing to write it loses nothing
            let cached = Cached { key: key.to_string(), reference: reference.clone() };
            let text = serde_json::to_string(&cached).unwrap_or_default();
            let tmp = path.with_extension("json.tmp");
            let _ = std::fs::create_dir_all(path.parent().unwrap_or(&path))
                .and_then(|_| std::fs::write(&tmp, text))
                .and_then(|_| std::fs::rename(&tmp, &path));
        }
    }

    /// Writes the cache files of `scene`'s computed reference (and of its field, when solved)
    /// into `dir`, as the cache folder holds them, when they are known without solving: the
    /// references a site carries for the page (issue #59, `hox lesson --references-to`). A
    /// committed reference (in the page's module already) or a mesh file's is not written.
    /// Ok(files written).
    pub fn export(&self, scene: &Scene, dir: &std::path::Path) -> std::io::Result<usize> {
        if !on_disk(scene) || unavailable(scene).is_some() || committed(scene).ok().flatten().is_some() {
            return Ok(0);
        }
        let mut written = 0;
        for key in [self.key(scene), self.field_key(scene)] {
            if let Some(reference) = self.load(&key, true) {
                let text =
                    serde_json::to_string(&Cached { key: key.clone(), reference }).map_err(std::io::Error::other)?;
                std::fs::create_dir_all(dir)?;
                std::fs::write(dir.join(cache_file_name(&key)), text)?;
                written += 1;
            }
        }
        Ok(written)
    }

    /// The reference of `scene`: committed, cached, or computed now (and cached). Err when the
    /// scene has none ([`unavailable`]) or the static solve fails.
    pub fn for_scene(&self, scene: &Scene, progress: Progress<'_>) -> Result<Reference, SceneError> {
        self.get(scene, false, progress, &mut |_| {})
    }

    /// The reference of `scene` (`with_field`: [`Lookup::with_field`], else
    /// [`Lookup::for_scene`]), passing each provisional estimate of a computation to
    /// `on_estimate` ([`compute_with`]) before the final reference is returned.
    pub fn get(
        &self,
        scene: &Scene,
        with_field: bool,
        progress: Progress<'_>,
        on_estimate: OnEstimate<'_>,
    ) -> Result<Reference, SceneError> {
        if with_field {
            let reference = self.probes_only(scene, progress, on_estimate)?;
            self.add_field(scene, reference, progress)
        } else {
            self.probes_only(scene, progress, on_estimate)
        }
    }

    fn probes_only(
        &self,
        scene: &Scene,
        progress: Progress<'_>,
        on_estimate: OnEstimate<'_>,
    ) -> Result<Reference, SceneError> {
        if let Some(why) = unavailable(scene) {
            return Err(SceneError::Simulation {
                source_name: scene.source.clone(),
                message: format!("no reference: {why}"),
            });
        }
        if let Some(r) = self.known(scene)? {
            return Ok(r);
        }
        let key = self.key(scene);
        let reference = if scene.is_box() {
            compute_with(scene, self.finest_cells, progress, on_estimate)?
        } else {
            own_mesh(scene, progress)?
        };
        self.store(&key, &reference, on_disk(scene));
        Ok(reference)
    }

    /// The key of [`Lookup::with_field`]'s result.
    pub fn field_key(&self, scene: &Scene) -> String {
        format!("{}; with its displacement field", self.key(scene))
    }

    /// [`Lookup::for_scene`] with its displacement field: a committed reference (probes only)
    /// gets the field of one static Q2 solve on the finest level ([`levels`]), cached.
    pub fn with_field(&self, scene: &Scene, progress: Progress<'_>) -> Result<Reference, SceneError> {
        self.get(scene, true, progress, &mut |_| {})
    }

    /// `reference` with its displacement field (solved once on the finest level if it has none).
    fn add_field(&self, scene: &Scene, reference: Reference, progress: Progress<'_>) -> Result<Reference, SceneError> {
        if reference.field.is_some() || !scene.is_box() {
            return Ok(reference);
        }
        let key = self.field_key(scene);
        if let Some(r) = self.load(&key, true) {
            return Ok(r);
        }
        let p = scene.params();
        let grid = levels(p.box_min_m, p.box_max_m, self.finest_cells)[2];
        let level = level_scene(scene, grid)?;
        let mesh = level.build_mesh()?;
        let what = format!("computing reference field: static {}", compute::Levels::of(scene).name(grid));
        let solution = crate::instance::solve_static(
            &level,
            &mesh,
            compute::TOLERANCE,
            compute::LOAD_STEPS,
            &mut |fraction, _, _| progress(&what, fraction),
        )?;
        let field = ReferenceField::lattice(&mesh, &solution.positions, p.box_min_m, p.box_max_m, grid);
        let with = Reference { field, ..reference };
        self.store(&key, &with, true);
        Ok(with)
    }
}

/// [`Lookup::known`] with the default lookup.
pub fn known(scene: &Scene) -> Result<Option<Reference>, SceneError> {
    Lookup::default().known(scene)
}

/// [`Lookup::for_scene`] with the default lookup.
pub fn for_scene(scene: &Scene, progress: Progress<'_>) -> Result<Reference, SceneError> {
    Lookup::default().for_scene(scene, progress)
}

#[cfg(test)]
mod tests;
