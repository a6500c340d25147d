//! The parameter table: every mesh, material, solver, effect and display parameter of a scene,
//! defined once.
//!
//! Each entry of [`PARAMS`] states a parameter's key (`youngs`: the CLI flag `--youngs`, the
//! `--compare youngs=…` key, the app's link), its scene-file key (`material.youngs_modulus_pa`),
//! type ([`Kind`]), unit, help text, valid range, default, where it appears ([`Surfaces`]) and
//! what a change of it invalidates in a running simulation ([`Invalidates`]). From the table come:
//!
//! - the typed values [`Params`] (one field per entry, persisted by the app) and the typed
//!   [`SceneOverrides`] (the same fields, each optional);
//! - the scene file's `[mesh]`, `[material]`, `[solver]`, `[effect]` and `[display]` keys, their
//!   parsing and their range checks ([`crate::scene`]);
//! - the command line's flags and the `--compare key=value` keys (the app's `cli` room);
//! - the app's controls, their links in compare mode and their rebuild levels (the app's `gui`
//!   room), and the configuration a recording states.
//!
//! **Adding a parameter** is one entry in the `params!` invocation below plus the code that uses
//! the value (e.g. `SolverSettings`); nothing else lists parameters.

use hox_sim::element::ElementType;
use hox_sim::material::MaterialModel;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::{Method, Sweep, VbdInit};
use hox_sim::xpbd::constraint::Formulation;
use serde::{Deserialize, Serialize};

/// How much of a running simulation a change of a parameter invalidates (the app's rebuild
/// levels), in increasing order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Invalidates {
    Nothing,
    /// Solver settings: kept state, new time stepping (a quadrature change re-precomputes the
    /// element geometry).
    Settings,
    /// Material: kept positions and velocities, new constitutive law (and masses if ρ changed).
    Material,
    /// Mesh: element type, split, grid or refinement — the simulation is rebuilt from rest.
    Mesh,
}

/// The table a parameter lives in, in the scene file and in the app.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Group {
    Mesh,
    Material,
    Solver,
    /// Effects every scene can switch on, besides the effects it lists (`[[effects]]`).
    Effect,
    /// How the configuration is drawn (the app's viewport and recordings); never the physics.
    Display,
}

impl Group {
    pub const ALL: [Group; 5] = [Group::Mesh, Group::Material, Group::Solver, Group::Effect, Group::Display];
    /// The scene file's table (`[mesh]`, `[material]`, `[solver]`, `[effect]`, `[display]`).
    pub fn section(self) -> &'static str {
        match self {
            Group::Mesh => "mesh",
            Group::Material => "material",
            Group::Solver => "solver",
            Group::Effect => "effect",
            Group::Display => "display",
        }
    }
    pub fn heading(self) -> &'static str {
        match self {
            Group::Mesh => "Mesh",
            Group::Material => "Material",
            Group::Solver => "Solver",
            Group::Effect => "Effects",
            Group::Display => "Display",
        }
    }
}

/// Where a parameter appears.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Surfaces {
    /// A command-line flag (`--KEY`, or the switch of [`Param::switch`]) and a `--compare` key.
    pub cli: bool,
    /// A control in the app, linkable in compare mode.
    pub app: bool,
}

/// Every surface.
pub const EVERYWHERE: Surfaces = Surfaces { cli: true, app: true };
/// The scene file only.
pub const FILE_ONLY: Surfaces = Surfaces { cli: false, app: false };

/// A parameter's type and valid range.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// One of named options: `(name, description)`.
    Choice(fn() -> Vec<(&'static str, String)>),
    /// One or more of named options, comma-separated in order (`von-mises,strain`).
    Choices(fn() -> Vec<(&'static str, String)>),
    /// A whole number in `min..=max`; `soft_max` bounds the app's slider only.
    Whole { min: u64, max: u64, soft_max: u64 },
    /// A finite number in `min..max` (ends inclusive or not); `soft` bounds the app's slider (if
    /// any; `None`: a text field).
    Number { min: f64, min_inclusive: bool, max: f64, max_inclusive: bool, soft: Option<(f64, f64)> },
    /// On or off.
    Flag,
    /// Cells per direction, `NXxNYxNZ`, each in `min..=max`.
    Grid { min: usize, max: usize },
    /// A point or vector in metres, finite.
    Point,
    /// A quadrature degree in `1..=max`, or the element's default (`None`).
    Degree { max: usize },
}

/// A parameter value, untyped (the typed values are the fields of [`Params`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Text(String),
    Whole(u64),
    Number(f64),
    Flag(bool),
    Grid([usize; 3]),
    Point([f64; 3]),
    Degree(Option<usize>),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Text(s) => write!(f, "{s}"),
            Value::Whole(n) => write!(f, "{n}"),
            Value::Number(x) => write!(f, "{x}"),
            Value::Flag(b) => write!(f, "{}", if *b { "on" } else { "off" }),
            Value::Grid([x, y, z]) => write!(f, "{x}x{y}x{z}"),
            Value::Point(p) => write!(f, "{p:?}"),
            Value::Degree(None) => write!(f, "default"),
            Value::Degree(Some(d)) => write!(f, "{d}"),
        }
    }
}

impl Value {
    /// The value as TOML (None for "the element's default", which is written by omission).
    pub fn to_toml(&self) -> Option<toml::Value> {
        Some(match self {
            Value::Text(s) => toml::Value::String(s.clone()),
            Value::Whole(n) => toml::Value::Integer(*n as i64),
            Value::Number(x) => toml::Value::Float(*x),
            Value::Flag(b) => toml::Value::Boolean(*b),
            Value::Grid(g) => toml::Value::Array(g.iter().map(|&c| toml::Value::Integer(c as i64)).collect()),
            Value::Point(p) => toml::Value::Array(p.iter().map(|&c| toml::Value::Float(c)).collect()),
            Value::Degree(d) => toml::Value::Integer((*d)? as i64),
        })
    }

    /// The value as JSON (for what a recording or `--json` states).
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            Value::Text(s) => s.clone().into(),
            Value::Whole(n) => (*n).into(),
            Value::Number(x) => (*x).into(),
            Value::Flag(b) => (*b).into(),
            Value::Grid(g) => serde_json::json!(g),
            Value::Point(p) => serde_json::json!(p),
            Value::Degree(d) => serde_json::json!(d),
        }
    }
}

fn toml_number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(n) => Some(*n as f64),
        _ => None,
    }
}

fn toml_whole(v: &toml::Value) -> Option<i64> {
    match v {
        toml::Value::Integer(n) => Some(*n),
        _ => None,
    }
}

impl Kind {
    /// What a value of this kind looks like, for messages.
    pub fn expected(&self) -> String {
        match self {
            Kind::Choice(options) => {
                let names: Vec<&str> = options().into_iter().map(|(n, _)| n).collect();
                format!("one of {}", names.join(", "))
            }
            Kind::Choices(options) => {
                let names: Vec<&str> = options().into_iter().map(|(n, _)| n).collect();
                format!("one or more of {}, comma-separated", names.join(", "))
            }
            Kind::Whole { min, max, .. } => format!("a whole number from {min} to {max}"),
            Kind::Number { min, min_inclusive, max, max_inclusive, .. } => {
                let lo = if *min == f64::NEG_INFINITY {
                    String::new()
                } else {
                    format!("{} {min}", if *min_inclusive { "≥" } else { ">" })
                };
                let hi = if *max == f64::INFINITY {
                    String::new()
                } else {
                    format!("{} {max}", if *max_inclusive { "≤" } else { "<" })
                };
                let range = [lo, hi].into_iter().filter(|s| !s.is_empty()).collect::<Vec<_>>().join(" and ");
                if range.is_empty() { "a finite number".into() } else { format!("a finite number {range}") }
            }
            Kind::Flag => "on or off (true or false)".into(),
            Kind::Grid { min, max } => format!("NXxNYxNZ cells, each a whole number from {min} to {max} (e.g. 16x4x4)"),
            Kind::Point => "three finite numbers".into(),
            Kind::Degree { max } => format!("a quadrature degree from 1 to {max}, or \"default\""),
        }
    }

    /// Parses command-line text (a flag's value or a `--compare` value). The range is checked
    /// separately ([`Kind::check`]), with the whole configuration known.
    pub fn parse(&self, text: &str) -> Result<Value, String> {
        let t = text.trim();
        let bad = || format!("'{t}' is not {}", self.expected());
        match self {
            Kind::Choice(_) => Ok(Value::Text(t.to_ascii_lowercase())),
            Kind::Choices(_) => {
                Ok(Value::Text(t.split(',').map(|n| n.trim().to_ascii_lowercase()).collect::<Vec<_>>().join(",")))
            }
            Kind::Whole { .. } => t.parse::<u64>().map(Value::Whole).map_err(|_| bad()),
            Kind::Number { .. } => t.parse::<f64>().map(Value::Number).map_err(|_| bad()),
            Kind::Flag => match t.to_ascii_lowercase().as_str() {
                "on" | "true" | "yes" | "1" => Ok(Value::Flag(true)),
                "off" | "false" | "no" | "0" => Ok(Value::Flag(false)),
                _ => Err(bad()),
            },
            Kind::Grid { .. } => {
                let parts: Vec<&str> = t.split(['x', 'X']).collect();
                if parts.len() != 3 {
                    return Err(bad());
                }
                let mut g = [0; 3];
                for (gi, p) in g.iter_mut().zip(parts) {
                    *gi = p.trim().parse().map_err(|_| bad())?;
                }
                Ok(Value::Grid(g))
            }
            Kind::Point => {
                let parts: Vec<&str> = t.split(',').collect();
                if parts.len() != 3 {
                    return Err(bad());
                }
                let mut p = [0.0; 3];
                for (pi, s) in p.iter_mut().zip(parts) {
                    *pi = s.trim().parse().map_err(|_| bad())?;
                }
                Ok(Value::Point(p))
            }
            Kind::Degree { .. } => match t {
                "default" | "auto" => Ok(Value::Degree(None)),
                _ => t.parse::<usize>().map(|d| Value::Degree(Some(d))).map_err(|_| bad()),
            },
        }
    }

    /// Reads a scene file's TOML value (the type only; the range is checked by [`Kind::check`]).
    pub fn from_toml(&self, v: &toml::Value) -> Result<Value, String> {
        let bad = || format!("expected {}", self.expected());
        match self {
            Kind::Choice(_) => v.as_str().map(|s| Value::Text(s.to_string())).ok_or_else(bad),
            // a string ("von-mises,strain") or an array of strings
            Kind::Choices(_) => match v {
                toml::Value::Array(a) => a
                    .iter()
                    .map(|x| x.as_str().map(str::to_string))
                    .collect::<Option<Vec<_>>>()
                    .map(|names| Value::Text(names.join(",")))
                    .ok_or_else(bad),
                _ => v.as_str().map(|s| Value::Text(s.to_string())).ok_or_else(bad),
            },
            Kind::Whole { .. } => toml_whole(v).and_then(|n| u64::try_from(n).ok()).map(Value::Whole).ok_or_else(bad),
            Kind::Number { .. } => toml_number(v).map(Value::Number).ok_or_else(bad),
            Kind::Flag => v.as_bool().map(Value::Flag).ok_or_else(bad),
            Kind::Grid { .. } => {
                let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
                let mut g = [0; 3];
                for (gi, c) in g.iter_mut().zip(a) {
                    *gi = toml_whole(c).and_then(|n| usize::try_from(n).ok()).ok_or_else(bad)?;
                }
                Ok(Value::Grid(g))
            }
            Kind::Point => {
                let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
                let mut p = [0.0; 3];
                for (pi, c) in p.iter_mut().zip(a) {
                    *pi = toml_number(c).ok_or_else(bad)?;
                }
                Ok(Value::Point(p))
            }
            Kind::Degree { .. } => {
                toml_whole(v).and_then(|n| usize::try_from(n).ok()).map(|d| Value::Degree(Some(d))).ok_or_else(bad)
            }
        }
    }

    /// Whether `v` lies in this kind's valid range (the reason if not).
    pub fn check(&self, v: &Value) -> Result<(), String> {
        let ok = match (self, v) {
            (Kind::Choice(options), Value::Text(s)) => options().iter().any(|(n, _)| n == s),
            (Kind::Choices(options), Value::Text(s)) => {
                let known = options();
                !s.is_empty() && s.split(',').all(|part| known.iter().any(|(n, _)| *n == part))
            }
            (Kind::Whole { min, max, .. }, Value::Whole(n)) => (min..=max).contains(&n),
            (Kind::Number { min, min_inclusive, max, max_inclusive, .. }, Value::Number(x)) => {
                x.is_finite()
                    && (if *min_inclusive { x >= min } else { x > min })
                    && (if *max_inclusive { x <= max } else { x < max })
            }
            (Kind::Flag, Value::Flag(_)) => true,
            (Kind::Grid { min, max }, Value::Grid(g)) => g.iter().all(|c| (min..=max).contains(&c)),
            (Kind::Point, Value::Point(p)) => p.iter().all(|c| c.is_finite()),
            (Kind::Degree { max }, Value::Degree(d)) => d.is_none_or(|d| (1..=*max).contains(&d)),
            _ => false,
        };
        if ok { Ok(()) } else { Err(format!("must be {}", self.expected())) }
    }
}

/// One parameter (see the module docs). Built by the `params!` table below.
pub struct Param {
    /// The short key: CLI flag `--KEY`, `--compare KEY=…`, the app's link name.
    pub key: &'static str,
    /// The field of [`Params`] (and of [`SceneOverrides`]).
    pub field: &'static str,
    pub group: Group,
    /// The key within the scene file's `[group]` table.
    pub file_key: &'static str,
    /// The app's label (the unit is appended in parentheses).
    pub label: &'static str,
    /// SI unit ("" for none).
    pub unit: &'static str,
    pub help: &'static str,
    pub kind: Kind,
    pub invalidates: Invalidates,
    pub surfaces: Surfaces,
    /// A scene file must give it (else the default applies).
    pub required: bool,
    /// A box mesh's parameter, meaningless for a mesh file.
    pub box_only: bool,
    /// For a flag: the command line's switch and the value it sets (`--no-stability-guard`
    /// sets false) instead of `--KEY VALUE`.
    pub switch: Option<(&'static str, bool)>,
    /// Whether it applies to a configuration (the app greys it out where not; e.g. the tet
    /// split for hexahedra). None: always.
    pub applies: Option<fn(&Params) -> bool>,
    /// A check that needs the whole configuration (e.g. the size of a refined mesh).
    pub check_with: Option<fn(&Params) -> Result<(), String>>,
    pub get: fn(&Params) -> Value,
    /// Sets the field; false if `Value` has the wrong variant.
    pub set: fn(&mut Params, Value) -> bool,
    pub get_override: fn(&SceneOverrides) -> Option<Value>,
    pub set_override: fn(&mut SceneOverrides, Value) -> bool,
}

impl std::fmt::Debug for Param {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Param").field("key", &self.key).finish()
    }
}

impl Param {
    /// `material.youngs_modulus_pa`.
    pub fn file_path(&self) -> String {
        format!("{}.{}", self.group.section(), self.file_key)
    }
    /// The label with its unit, e.g. `Young's modulus E (Pa)`.
    pub fn label_with_unit(&self) -> String {
        if self.unit.is_empty() { self.label.to_string() } else { format!("{} ({})", self.label, self.unit) }
    }
    /// The command-line flag, e.g. `--youngs` or `--no-stability-guard`.
    pub fn flag(&self) -> String {
        format!("--{}", self.switch.map_or(self.key, |(name, _)| name))
    }
    /// The range check of one value; the reason names the parameter (`Poisson ratio ν must be …`).
    pub fn check_value(&self, v: &Value) -> Result<(), String> {
        self.kind.check(v).map_err(|e| format!("{} {e}", self.label))
    }
    /// Range and whole-configuration checks of this parameter's value in `params`.
    pub fn check(&self, params: &Params) -> Result<(), String> {
        let range = self.check_value(&(self.get)(params));
        let whole = self.check_with.map_or(Ok(()), |f| f(params));
        match (range, whole) {
            (Err(a), Err(b)) => Err(format!("{a}: {b}")),
            (Err(e), Ok(())) | (Ok(()), Err(e)) => Err(e),
            (Ok(()), Ok(())) => Ok(()),
        }
    }
}

/// Conversion between a typed field and a [`Value`].
pub trait ParamType: Sized {
    fn to_value(&self) -> Value;
    fn from_value(v: Value) -> Option<Self>;
}

/// `ParamType` for a field type stored as one `Value` variant: `$to` makes the variant's payload
/// from `&self`, `$from` the field from the payload (None when out of the type's range).
macro_rules! param_type {
    ($($ty:ty => $variant:ident, |$s:ident| $to:expr, |$v:ident| $from:expr;)*) => {
        $(impl ParamType for $ty {
            fn to_value(&self) -> Value {
                let $s = self;
                Value::$variant($to)
            }
            fn from_value(v: Value) -> Option<Self> {
                if let Value::$variant($v) = v { $from } else { None }
            }
        })*
    };
}

param_type! {
    String => Text, |s| s.clone(), |x| Some(x);
    usize => Whole, |s| *s as u64, |n| usize::try_from(n).ok();
    u32 => Whole, |s| u64::from(*s), |n| u32::try_from(n).ok();
    f64 => Number, |s| *s, |x| Some(x);
    bool => Flag, |s| *s, |b| Some(b);
    [usize; 3] => Grid, |s| *s, |g| Some(g);
    [f64; 3] => Point, |s| *s, |p| Some(p);
    Option<usize> => Degree, |s| *s, |d| Some(d);
}

/// Fields every entry shares unless it says otherwise.
const BASE: Param = Param {
    key: "",
    field: "",
    group: Group::Solver,
    file_key: "",
    label: "",
    unit: "",
    help: "",
    kind: Kind::Flag,
    invalidates: Invalidates::Settings,
    surfaces: EVERYWHERE,
    required: false,
    box_only: false,
    switch: None,
    applies: None,
    check_with: None,
    get: |_| Value::Flag(false),
    set: |_, _| false,
    get_override: |_| None,
    set_override: |_, _| false,
};

/// Defines [`Params`], [`SceneOverrides`] and [`PARAMS`] from one list.
macro_rules! params {
    ($( $(#[doc = $doc:literal])* $field:ident : $ty:ty = $default:expr => { $($def:tt)* } )*) => {
        /// Every parameter's value (see the module docs); a scene's resolved configuration and
        /// the app's live controls. Persisted by the app (missing fields take their defaults).
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(default)]
        pub struct Params {
            $( $(#[doc = $doc])* pub $field: $ty, )*
        }

        impl Default for Params {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        /// Changes to a scene's parameters (command line, `--compare`, the app, studies),
        /// applied by [`crate::Scene::with_overrides`]: a field per parameter, `None` = keep.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct SceneOverrides {
            $( pub $field: Option<$ty>, )*
        }

        /// The table, in display order.
        pub static PARAMS: &[Param] = &[
            $( Param {
                field: stringify!($field),
                get: |p| p.$field.to_value(),
                set: |p, v| match <$ty as ParamType>::from_value(v) {
                    Some(x) => { p.$field = x; true }
                    None => false,
                },
                get_override: |o| o.$field.as_ref().map(ParamType::to_value),
                set_override: |o, v| match <$ty as ParamType>::from_value(v) {
                    Some(x) => { o.$field = Some(x); true }
                    None => false,
                },
                $($def)*
            }, )*
        ];
    };
}

fn element_options() -> Vec<(&'static str, String)> {
    ElementType::all().map(|e| (e.name(), format!("{} — {}", e.name().to_uppercase(), e.description()))).collect()
}
fn split_options() -> Vec<(&'static str, String)> {
    [TetSplit::Five, TetSplit::Six]
        .iter()
        .map(|s| (s.name(), format!("{} ({})", s.name(), if *s == TetSplit::Five { "unbiased" } else { "biased" })))
        .collect()
}
fn material_options() -> Vec<(&'static str, String)> {
    MaterialModel::ALL.iter().map(|m| (m.name(), m.long_name().to_string())).collect()
}
fn sweep_options() -> Vec<(&'static str, String)> {
    Sweep::ALL
        .iter()
        .map(|s| {
            let long = match s {
                Sweep::Colour => "colour by colour (fast, any thread count)",
                Sweep::Element => "element order (the paper's, one thread)",
            };
            (s.name(), long.to_string())
        })
        .collect()
}
fn formulation_options() -> Vec<(&'static str, String)> {
    Formulation::ALL.iter().map(|f| (f.name(), f.name().to_string())).collect()
}

fn field_options() -> Vec<(&'static str, String)> {
    hox_sim::measure::field::Field::ALL.iter().map(|f| (f.name(), f.description().to_string())).collect()
}

fn method_options() -> Vec<(&'static str, String)> {
    Method::ALL
        .iter()
        .map(|m| {
            let long = match m {
                Method::Xpbd => "XPBD (the paper's)",
                Method::Vbd => "VBD (vertex block descent)",
                Method::Newton => "Newton (implicit Euler)",
            };
            (m.name(), long.to_string())
        })
        .collect()
}
fn vbd_init_options() -> Vec<(&'static str, String)> {
    VbdInit::ALL.iter().map(|i| (i.name(), i.name().to_string())).collect()
}

/// Whether the solver is the paper's XPBD (substeps, iterations, formulation and guard apply).
pub fn is_xpbd(p: &Params) -> bool {
    Method::from_name(&p.method).is_none_or(|m| m == Method::Xpbd)
}
/// Whether the solver is implicit (VBD or Newton: steps per frame apply).
pub fn is_implicit(p: &Params) -> bool {
    !is_xpbd(p)
}
pub fn is_vbd(p: &Params) -> bool {
    Method::from_name(&p.method) == Some(Method::Vbd)
}
fn is_newton(p: &Params) -> bool {
    Method::from_name(&p.method) == Some(Method::Newton)
}

/// Whether the element type is a tetrahedron (P1, P2, P3): the tet split and refinement apply.
pub fn is_tetrahedral(p: &Params) -> bool {
    ElementType::from_name(&p.element).is_some_and(|e| e.shape() == hox_sim::element::ReferenceShape::Tetrahedron)
}

/// The largest mesh a box scene may ask for, elements: 24 times the paper's largest beam (P1
/// 81,920), whose run measured 63 MB of resident memory in all (about 25 MB above the binary's
/// own; [`box_bytes`] estimates 58 MB, an upper bound).
pub const MAX_BOX_ELEMENTS: u64 = 2_000_000;

/// The most memory a box scene may ask for by [`box_bytes`], bytes (a third of this machine's
/// 24 GiB): high-order elements reach it before the element limit.
pub const MAX_BOX_BYTES: u64 = 8_000_000_000;

/// Elements a box mesh of `p` would have (without building it).
pub fn box_elements(p: &Params) -> Option<u64> {
    let e = ElementType::from_name(&p.element)?;
    let cells: u64 = p.grid.iter().map(|&c| c as u64).product();
    let split = if is_tetrahedral(p) { TetSplit::from_name(&p.split)? } else { TetSplit::default() };
    let per_cell = hox_sim::mesh::structured::elements_per_cell(e.shape(), split) as u64;
    let refine = u32::try_from(p.refine).ok().filter(|r| *r <= 20)?;
    Some(cells.saturating_mul(per_cell).saturating_mul(8u64.saturating_pow(refine)))
}

/// Rough memory a box mesh of `p` takes when simulated, bytes: per element its node indices and,
/// per quadrature point, the material gradients of its shape functions and the rest volume; per
/// node (about one per element for these meshes, more for high order) positions, velocities,
/// previous positions, rest positions, masses and the solver's scratch.
pub fn box_bytes(p: &Params) -> Option<u64> {
    let e = ElementType::from_name(&p.element)?;
    let nodes = e.num_nodes() as u64;
    let qp = hox_sim::fem::quadrature::rule(e.shape(), p.quadrature_degree.unwrap_or(e.default_quadrature_degree()))
        .map(|r| r.len() as u64)
        .unwrap_or(1);
    let per_element = nodes * 4 + qp * (nodes * 24 + 16) + nodes * 6 * 24;
    Some(box_elements(p)?.saturating_mul(per_element))
}

/// A box may ask for more elements or memory than a simulation can hold: refuse with the count
/// and the memory it would take.
fn check_box_size(p: &Params) -> Result<(), String> {
    let (Some(elements), Some(bytes)) = (box_elements(p), box_bytes(p)) else { return Ok(()) };
    if elements <= MAX_BOX_ELEMENTS && bytes <= MAX_BOX_BYTES {
        return Ok(());
    }
    let [x, y, z] = p.grid;
    Err(format!(
        "{} {x}×{y}×{z}{} would be {} elements and take about {:.1} GB; at most {} elements and {:.0} GB",
        p.element.to_uppercase(),
        if p.refine > 0 { format!(" refined {} time(s)", p.refine) } else { String::new() },
        thousands(elements),
        bytes as f64 / 1e9,
        thousands(MAX_BOX_ELEMENTS),
        MAX_BOX_BYTES as f64 / 1e9
    ))
}

/// The size check, reported on the grid when nothing is refined ...
fn check_grid_size(p: &Params) -> Result<(), String> {
    if p.refine == 0 { check_box_size(p) } else { Ok(()) }
}

/// ... and on the refinement otherwise (each multiplies the elements by 8).
fn check_refine_size(p: &Params) -> Result<(), String> {
    if p.refine > 0 { check_box_size(p) } else { Ok(()) }
}

/// 5242880 → "5,242,880".
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (k, c) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

params! {
    /// Element type of a box mesh: a registered element type's name ([`ElementType::all`]).
    element: String = "p2".into() => {
        key: "element", group: Group::Mesh, file_key: "element", label: "Element",
        help: "The element type: its shape (tetrahedron, hexahedron, prism, pyramid) and polynomial order; `hox elements` describes each.",
        kind: Kind::Choice(element_options), invalidates: Invalidates::Mesh, required: true, box_only: true, ..BASE
    }
    /// `five` (unbiased) or `six` (biased) tetrahedra per cell.
    split: String = "five".into() => {
        key: "split", group: Group::Mesh, file_key: "split", label: "Tet split",
        help: "How each hexahedral cell is cut into tetrahedra: five (unbiased, alternating) or six (biased along one diagonal).",
        kind: Kind::Choice(split_options), invalidates: Invalidates::Mesh, box_only: true, applies: Some(is_tetrahedral), ..BASE
    }
    /// Hexahedral cells per direction of a box mesh.
    grid: [usize; 3] = [8, 2, 2] => {
        key: "grid", group: Group::Mesh, file_key: "grid", label: "Grid",
        help: "Hexahedral cells along x, y and z before any splitting (each 1–64), NXxNYxNZ.",
        kind: Kind::Grid { min: 1, max: 64 }, invalidates: Invalidates::Mesh, required: true, box_only: true,
        check_with: Some(check_grid_size), ..BASE
    }
    /// 1-to-8 refinements of the tetrahedra.
    refine: usize = 0 => {
        key: "refine", group: Group::Mesh, file_key: "refine", label: "Refine",
        help: "1-to-8 refinements of the tetrahedra (each multiplies the element count by 8; tetrahedra only).",
        kind: Kind::Whole { min: 0, max: 3, soft_max: 3 }, invalidates: Invalidates::Mesh, box_only: true,
        applies: Some(is_tetrahedral), check_with: Some(check_refine_size), ..BASE
    }
    /// The box's lower corner, metres.
    box_min_m: [f64; 3] = [0.0; 3] => {
        key: "box-min-m", group: Group::Mesh, file_key: "box_min_m", label: "Box lower corner", unit: "m",
        help: "The box mesh's lower corner, metres.",
        kind: Kind::Point, invalidates: Invalidates::Mesh, surfaces: FILE_ONLY, required: true, box_only: true, ..BASE
    }
    /// The box's upper corner, metres.
    box_max_m: [f64; 3] = [2.0, 0.5, 0.5] => {
        key: "box-max-m", group: Group::Mesh, file_key: "box_max_m", label: "Box upper corner", unit: "m",
        help: "The box mesh's upper corner, metres; beyond the lower corner in every direction.",
        kind: Kind::Point, invalidates: Invalidates::Mesh, surfaces: FILE_ONLY, required: true, box_only: true, ..BASE
    }
    /// A registered material model's name ([`MaterialModel::ALL`]).
    material: String = "stvk".into() => {
        key: "material", group: Group::Material, file_key: "model", label: "Model",
        help: "The hyperelastic energy model; stvk (Saint-Venant–Kirchhoff) is the paper's.",
        kind: Kind::Choice(material_options), invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Young's modulus, Pa.
    youngs_modulus_pa: f64 = 3e6 => {
        key: "youngs", group: Group::Material, file_key: "youngs_modulus_pa", label: "Young's modulus E", unit: "Pa",
        help: "Stiffness in pascals, > 0 (rubber ~1e6, the paper's beam 3e6).",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Poisson ratio.
    poisson_ratio: f64 = 0.35 => {
        key: "poisson", group: Group::Material, file_key: "poisson_ratio", label: "Poisson ratio ν",
        help: "Lateral contraction, between −1 and 0.5 (exclusive); near 0.5 is nearly incompressible.",
        kind: Kind::Number { min: -1.0, min_inclusive: false, max: 0.5, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// Density, kg/m³.
    density_kg_m3: f64 = 1000.0 => {
        key: "density", group: Group::Material, file_key: "density_kg_m3", label: "Density ρ", unit: "kg/m³",
        help: "Mass per volume in kg/m³, > 0 (water 1000).",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Material, required: true, ..BASE
    }
    /// xpbd | vbd | newton ([`hox_sim::solver::Method`]).
    method: String = "xpbd".into() => {
        key: "solver", group: Group::Solver, file_key: "method", label: "Solver",
        help: "xpbd: the paper's extended position-based dynamics (substeps × iterations); vbd: vertex block descent on implicit Euler (Chen et al. 2024); newton: implicit Euler solved by Newton's method to --newton-tolerance (sparse Cholesky). Contact needs xpbd or vbd.",
        kind: Kind::Choice(method_options), ..BASE
    }
    /// Implicit steps per frame (VBD, Newton).
    steps_per_frame: u32 = 1 => {
        key: "steps", group: Group::Solver, file_key: "steps_per_frame", label: "Steps per frame",
        help: "Implicit Euler steps per frame for vbd and newton (XPBD takes --substeps); more steps, less numerical damping.",
        kind: Kind::Whole { min: 1, max: 10_000, soft_max: 20 }, applies: Some(is_implicit), ..BASE
    }
    /// VBD sweeps per step.
    vbd_iterations: u32 = 10 => {
        key: "vbd-iterations", group: Group::Solver, file_key: "vbd_iterations", label: "VBD iterations",
        help: "Vertex block descent sweeps over the node colours per step.",
        kind: Kind::Whole { min: 1, max: 100_000, soft_max: 200 }, applies: Some(is_vbd), ..BASE
    }
    /// Chebyshev acceleration's ρ for VBD (0: off).
    chebyshev_rho: f64 = 0.9 => {
        key: "chebyshev-rho", group: Group::Solver, file_key: "chebyshev_rho", label: "Chebyshev ρ",
        help: "Chebyshev acceleration of the VBD sweeps, its spectral radius estimate in [0, 1) (0: off; 0.9 halves the sweeps to settle the bending beam; 0.95 can diverge at few sweeps).",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: 1.0, max_inclusive: false, soft: None }, applies: Some(is_vbd), ..BASE
    }
    /// VBD's two-level correction: about how many coarse cells (0: off).
    vbd_coarse_cells: u32 = 32 => {
        key: "vbd-coarse-cells", group: Group::Solver, file_key: "vbd_coarse_cells", label: "VBD coarse cells",
        help: "VBD's two-level correction: before its sweeps each step solves for the smooth part of the motion on a coarse grid of about this many trilinear cells over the body (0: off, the paper's VBD alone). The sweeps barely move smooth error such as a beam's slow bending; with the correction Gmsh's P2 beam settles in 122 frames (as Newton) instead of 707.",
        kind: Kind::Whole { min: 0, max: 256, soft_max: 128 }, applies: Some(is_vbd), ..BASE
    }
    /// Where a VBD step starts: adaptive | inertia | previous.
    vbd_init: String = "adaptive".into() => {
        key: "vbd-init", group: Group::Solver, file_key: "vbd_init", label: "VBD start",
        help: "Where a VBD step starts: adaptive (the paper's: the last step's acceleration along gravity, so a body at rest stays at rest), inertia (the inertial prediction) or previous (the last position).",
        kind: Kind::Choice(vbd_init_options), applies: Some(is_vbd), ..BASE
    }
    /// Newton's tolerance per step, relative to the load.
    newton_tolerance: f64 = 1e-6 => {
        key: "newton-tolerance", group: Group::Solver, file_key: "newton_tolerance", label: "Newton tolerance",
        help: "A Newton step has converged when its unbalanced force is at most this fraction of the load (the body force, or the reactions if larger), as `hox static` measures it; in (0, 1).",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: 1.0, max_inclusive: false, soft: None }, applies: Some(is_newton), ..BASE
    }
    /// energy | split.
    formulation: String = "energy".into() => {
        key: "formulation", group: Group::Solver, file_key: "formulation", label: "Formulation",
        help: "Energy: one constraint C = √(2U) per element (the paper's); split: deviatoric and hydrostatic constraints per quadrature point.",
        kind: Kind::Choice(formulation_options), applies: Some(is_xpbd), ..BASE
    }
    /// None: each element type's default degree.
    quadrature_degree: Option<usize> = None => {
        key: "quadrature", group: Group::Solver, file_key: "quadrature_degree", label: "Quadrature",
        help: "Degree of polynomials the element quadrature integrates exactly (default: the element's own).",
        kind: Kind::Degree { max: 21 }, ..BASE
    }
    /// XPBD substeps per frame.
    substeps: u32 = 50 => {
        key: "substeps", group: Group::Solver, file_key: "substeps", label: "Substeps",
        help: "XPBD substeps per frame (the paper: 50); more substeps, less solver bias, more time.",
        kind: Kind::Whole { min: 1, max: 1_000_000, soft_max: 500 }, applies: Some(is_xpbd), ..BASE
    }
    /// Constraint sweeps per substep.
    iterations: u32 = 1 => {
        key: "iterations", group: Group::Solver, file_key: "iterations", label: "Iterations",
        help: "Constraint sweeps per substep (the paper: 1).",
        kind: Kind::Whole { min: 1, max: 1_000_000, soft_max: 20 }, applies: Some(is_xpbd), ..BASE
    }
    /// More substeps where the stiffest element needs them (`hox_sim::solver::stability`).
    stability_guard: bool = true => {
        key: "guard", group: Group::Solver, file_key: "stability_guard", label: "Stability guard",
        help: "More substeps when the stiffest element needs them (when h·ω_max would exceed 3, enough for h·ω_max ≤ 1; just below 3 your substeps are kept); off: exactly the substeps asked for, which may blow up (docs/STABILITY.md).",
        kind: Kind::Flag, switch: Some(("no-stability-guard", false)), applies: Some(is_xpbd), ..BASE
    }
    /// Simulated frames per second; each frame is one time step.
    frames_per_second: f64 = 60.0 => {
        key: "fps", group: Group::Solver, file_key: "frames_per_second", label: "Frames per second",
        help: "Simulated frames per second of simulated time (the paper: 60); each frame is one time step h = 1/fps.",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: f64::INFINITY, max_inclusive: false, soft: Some((10.0, 240.0)) },
        ..BASE
    }
    /// colour | element: the order of XPBD's Gauss–Seidel sweep.
    sweep: String = "colour".into() => {
        key: "sweep", group: Group::Solver, file_key: "sweep", label: "Sweep",
        help: "Order of XPBD's constraint sweep. colour (default): colour by colour, four elements per AVX2 register, on every thread (RAYON_NUM_THREADS sets how many), the same result on any thread count; element: element after element in mesh order on one thread (the order of the paper's figures and of hox's results before the colour sweep became the default).",
        kind: Kind::Choice(sweep_options), applies: Some(is_xpbd), ..BASE
    }
    /// Default run length, seconds.
    duration_secs: f64 = 3.0 => {
        key: "duration", group: Group::Solver, file_key: "duration_secs", label: "Duration", unit: "s",
        help: "Simulated time a run lasts by default (`--seconds` overrides it).",
        kind: Kind::Number { min: 0.0, min_inclusive: false, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping used by `--settle`, 1/s.
    settle_damping_per_sec: f64 = 10.0 => {
        key: "settle-damping", group: Group::Solver, file_key: "settle_damping_per_sec", label: "Settle damping", unit: "1/s",
        help: "Velocity damping rate a run to rest (--settle) adds, per second.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping used by `--settle` when the solver is VBD, 1/s.
    vbd_settle_damping_per_sec: f64 = 10.0 => {
        key: "vbd-settle-damping", group: Group::Solver, file_key: "vbd_settle_damping_per_sec", label: "VBD settle damping", unit: "1/s",
        help: "Velocity damping rate a run to rest (--settle) adds when the solver is vbd, per second, in place of the settle damping. With the coarse correction (vbd_coarse_cells > 0) VBD's steps are near converged and the 10/s that settles XPBD and Newton fastest does so too (Gmsh's P2 1,471 beam: 122 frames, as Newton); without it the few sweeps per step leave the slow bending modes only part of their stiffness and 2/s settles fastest (707 frames against 2,200 at 10/s).",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        applies: Some(is_vbd), invalidates: Invalidates::Nothing, surfaces: FILE_ONLY, ..BASE
    }
    /// Velocity damping of every node, 1/s (0: none).
    damping_per_sec: f64 = 0.0 => {
        key: "damping", group: Group::Effect, file_key: "damping_per_sec", label: "Damping", unit: "1/s",
        help: "Velocity damping rate of every node per second, on top of any damping effect the scene lists (0: none); a swinging beam comes to rest at a rate of about this many e-foldings per second. A change restarts the run.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Mesh, ..BASE
    }
    /// Pieces per edge of drawn curved and quadrilateral faces.
    tessellation: usize = 4 => {
        key: "tessellation", group: Group::Display, file_key: "tessellation", label: "Face segments",
        help: "Pieces per edge when drawing curved (high-order) and quadrilateral faces: more shows the curvature of P2, P3 and Q2 elements more smoothly, at more drawing cost.",
        kind: Kind::Whole { min: 1, max: 16, soft_max: 12 }, invalidates: Invalidates::Nothing, ..BASE
    }
    /// The fields the surface is coloured by, comma-separated; the first is drawn
    /// ([`hox_sim::measure::field::Field`]).
    field: String = "displacement".into() => {
        key: "field", group: Group::Display, file_key: "field", label: "Colour by",
        help: "What the surface is coloured by: displacement (|u|, m), von-mises (stress, Pa), strain (equivalent Green–Lagrange strain), det-f (volume ratio), energy-density (J/m³) or error (|u − u_ref| against the reference field, m), evaluated at each element's own points. `hox record` records every field listed (comma-separated or --field repeated), each in its own 3D view; the app draws the first.",
        kind: Kind::Choices(field_options), invalidates: Invalidates::Nothing, ..BASE
    }
    /// Top of the colour range of the metre fields (|u|, error), metres (0: automatic).
    colour_max_m: f64 = 0.0 => {
        key: "colour-max-m", group: Group::Display, file_key: "colour_max_m", label: "Colour top (m)", unit: "m",
        help: "Top of a fixed colour range for displacement and error, metres (larger values are drawn pink, marked saturated); 0: automatic, growing to the largest value seen so nothing saturates. Compared configurations share the first one's range.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, ..BASE
    }
    /// Top of the colour range of the first other field listed, in its unit (0: automatic).
    colour_max: f64 = 0.0 => {
        key: "colour-max", group: Group::Display, file_key: "colour_max", label: "Colour top (field unit)",
        help: "Top of a fixed colour range for the first field listed other than displacement and error, in its unit (Pa for von-mises, J/m³ for energy-density, none for strain and det-f, whose range is then symmetric about 1); larger values are drawn pink, smaller than the bottom light blue. 0: automatic.",
        kind: Kind::Number { min: 0.0, min_inclusive: true, max: f64::INFINITY, max_inclusive: false, soft: None },
        invalidates: Invalidates::Nothing, ..BASE
    }
    /// Draw (or record) every quadrature point.
    quadrature_points: bool = false => {
        key: "quadrature-points", group: Group::Display, file_key: "quadrature_points", label: "Quadrature points",
        help: "Also draw (and record) every quadrature point, where the solver samples F.",
        kind: Kind::Flag, switch: Some(("quadrature-points", true)), invalidates: Invalidates::Nothing, ..BASE
    }
}

/// The parameter with command-line / `--compare` / link key `key`.
pub fn by_key(key: &str) -> Option<&'static Param> {
    PARAMS.iter().find(|p| p.key == key)
}

/// The parameters of `group`, in display order.
pub fn in_group(group: Group) -> impl Iterator<Item = &'static Param> {
    PARAMS.iter().filter(move |p| p.group == group)
}

/// The keys `--compare` accepts, comma-separated.
pub fn compare_keys() -> String {
    PARAMS.iter().filter(|p| p.surfaces.cli).map(|p| p.key).collect::<Vec<_>>().join(", ")
}

impl SceneOverrides {
    /// The parameters this sets, with their values.
    pub fn iter(&self) -> impl Iterator<Item = (&'static Param, Value)> + '_ {
        PARAMS.iter().filter_map(move |p| (p.get_override)(self).map(|v| (p, v)))
    }

    /// Sets the parameter `key` from text (`--compare key=value`); errors name the key.
    pub fn set_text(&mut self, key: &str, text: &str) -> Result<(), String> {
        let p = by_key(key).filter(|p| p.surfaces.cli).ok_or_else(|| {
            let near = PARAMS.iter().filter(|p| p.surfaces.cli).find(|p| {
                let prefix: String = key.chars().take(3).collect();
                p.key.starts_with(&prefix)
            });
            format!(
                "unknown option '{key}'{} (options: {})",
                near.map_or(String::new(), |p| format!(", did you mean '{}'?", p.key)),
                compare_keys()
            )
        })?;
        let v = p.kind.parse(text).map_err(|e| format!("{key}: {e}"))?;
        p.check_value(&v).map_err(|e| format!("{key} = {v}: {e}"))?;
        (p.set_override)(self, v);
        Ok(())
    }

    /// `self` with every value `other` sets put on top.
    pub fn merged(&self, other: &SceneOverrides) -> SceneOverrides {
        let mut out = self.clone();
        for (p, v) in other.iter() {
            (p.set_override)(&mut out, v);
        }
        out
    }
}

impl Params {
    /// The value of the parameter `key`.
    pub fn value(&self, key: &str) -> Option<Value> {
        by_key(key).map(|p| (p.get)(self))
    }

    /// `self` with `overrides` applied (unchecked; [`crate::Scene::with_overrides`] checks).
    pub fn overridden(&self, overrides: &SceneOverrides) -> Params {
        let mut p = self.clone();
        for (param, v) in overrides.iter() {
            (param.set)(&mut p, v);
        }
        p
    }

    /// Every value as overrides (what the app applies to its scene); a mesh file's scene takes
    /// no box parameters.
    pub fn as_overrides(&self, is_box: bool) -> SceneOverrides {
        let mut o = SceneOverrides::default();
        for p in PARAMS.iter().filter(|p| is_box || !p.box_only) {
            (p.set_override)(&mut o, (p.get)(self));
        }
        o
    }

    /// The keys of the parameters (shown in the app) that differ between `self` and `other`.
    pub fn changed_keys(&self, other: &Params) -> Vec<&'static str> {
        PARAMS.iter().filter(|p| (p.get)(self) != (p.get)(other)).map(|p| p.key).collect()
    }

    /// Copies parameter `key` from `from`.
    pub fn copy_from(&mut self, from: &Params, key: &str) {
        if let Some(p) = by_key(key) {
            (p.set)(self, (p.get)(from));
        }
    }

    /// What changing from `self` to `new` invalidates (Nothing: a display or run-length change,
    /// which a running simulation does not see).
    pub fn invalidated_by(&self, new: &Params) -> Invalidates {
        PARAMS
            .iter()
            .filter(|p| (p.get)(self) != (p.get)(new))
            .map(|p| p.invalidates)
            .max()
            .unwrap_or(Invalidates::Nothing)
    }

    /// A short label of a box configuration, e.g. `P2 8×2×2 five` or `P1 8×2×2 five r1`.
    pub fn box_label(&self) -> String {
        let [x, y, z] = self.grid;
        let tets = is_tetrahedral(self);
        let mut s = format!("{} {x}×{y}×{z}", self.element.to_uppercase());
        if tets {
            s += &format!(" {}", self.split);
            if self.refine > 0 {
                s += &format!(" r{}", self.refine);
            }
        }
        s
    }

    /// Every parameter as JSON, by scene-file path (`material.youngs_modulus_pa`): what a
    /// recording or a report states about its configuration.
    pub fn to_json(&self, is_box: bool) -> serde_json::Value {
        let mut out = serde_json::Map::new();
        for p in PARAMS.iter().filter(|p| is_box || !p.box_only) {
            out.insert(p.file_path(), (p.get)(self).to_json());
        }
        serde_json::Value::Object(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_is_complete_and_its_keys_unique() {
        let mut keys = std::collections::HashSet::new();
        let mut paths = std::collections::HashSet::new();
        for p in PARAMS {
            assert!(!p.key.is_empty() && !p.file_key.is_empty() && !p.label.is_empty() && !p.help.is_empty(), "{p:?}");
            assert!(keys.insert(p.key), "key {} twice", p.key);
            assert!(paths.insert(p.file_path()), "file key {} twice", p.file_path());
            // the default is valid and round-trips through Value, TOML and text
            let d = Params::default();
            let v = (p.get)(&d);
            p.kind.check(&v).unwrap_or_else(|e| panic!("{}: default {v}: {e}", p.key));
            let mut q = d.clone();
            assert!((p.set)(&mut q, v.clone()), "{}", p.key);
            assert_eq!(q, d);
            if let Some(t) = v.to_toml() {
                assert_eq!(p.kind.from_toml(&t).as_ref(), Ok(&v), "{}", p.key);
            }
            if !matches!(p.kind, Kind::Point) {
                assert_eq!(p.kind.parse(&v.to_string()).as_ref(), Ok(&v), "{}", p.key);
            }
        }
    }

    #[test]
    fn overrides_set_by_text_name_the_key_and_check_the_range() {
        let mut o = SceneOverrides::default();
        o.set_text("youngs", "6e6").unwrap();
        o.set_text("grid", "16x4x4").unwrap();
        o.set_text("quadrature", "default").unwrap();
        o.set_text("guard", "off").unwrap();
        assert_eq!(o.youngs_modulus_pa, Some(6e6));
        assert_eq!(o.grid, Some([16, 4, 4]));
        assert_eq!(o.quadrature_degree, Some(None));
        assert_eq!(o.stability_guard, Some(false));
        let e = o.set_text("youngz", "1").unwrap_err();
        assert!(e.contains("'youngz'") && e.contains("did you mean 'youngs'"), "{e}");
        let e = o.set_text("grid", "-4x2x2").unwrap_err();
        assert!(e.starts_with("grid:"), "{e}");
        let e = o.set_text("refine", "9").unwrap_err();
        assert!(e.starts_with("refine = 9"), "{e}");
        let e = o.set_text("poisson", "0.5").unwrap_err();
        assert!(e.contains("< 0.5"), "{e}");
    }

    #[test]
    fn a_change_invalidates_what_its_entry_says() {
        let a = Params::default();
        let mut b = a.clone();
        assert_eq!(a.invalidated_by(&b), Invalidates::Nothing);
        b.substeps = 10;
        assert_eq!(a.invalidated_by(&b), Invalidates::Settings);
        b.youngs_modulus_pa = 1e7;
        assert_eq!(a.invalidated_by(&b), Invalidates::Material);
        b.element = "q2".into();
        assert_eq!(a.invalidated_by(&b), Invalidates::Mesh);
        assert_eq!(a.changed_keys(&b), ["element", "youngs", "substeps"]);
    }

    #[test]
    fn the_size_of_a_refined_box_is_estimated_before_building_it() {
        let mut p = Params::default();
        assert_eq!(box_elements(&p), Some(160));
        p.refine = 3;
        assert_eq!(box_elements(&p), Some(81_920));
        assert!(check_box_size(&p).is_ok());
        p.refine = 5;
        let e = check_box_size(&p).unwrap_err();
        assert!(e.contains("5,242,880 elements") && e.contains("GB"), "{e}");
        p.refine = 0;
        p.grid = [64, 64, 64];
        p.element = "p1".into();
        assert_eq!(box_elements(&p), Some(1_310_720));
        assert!(check_box_size(&p).is_ok());
        p.split = "six".into();
        p.refine = 1;
        assert!(check_box_size(&p).unwrap_err().contains("12,582,912 elements"));
        assert!(check_grid_size(&p).is_ok(), "reported on the refinement, not the grid");
        // high order reaches the memory limit first, and unrefined it is the grid's
        p.element = "p3".into();
        p.split = "five".into();
        p.refine = 0;
        let e = check_grid_size(&p).unwrap_err();
        assert!(e.contains("1,310,720 elements") && e.contains("GB"), "{e}");
        assert!(check_refine_size(&p).is_ok());
    }
}
