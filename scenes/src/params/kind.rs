//! The parameter table's meta-types: a parameter's type and valid range ([`Kind`]: parsing
//! command-line text and scene-file TOML into a [`Value`], the range check, the wording of
//! messages), the table it lives in ([`Group`]), where it appears ([`Surfaces`]) and what a change
//! of it invalidates ([`Invalidates`]).

use super::value::Value;
#[cfg(doc)]
use hox_sim::solver::SolverSettings;
use hox_sim::solver::{Range, RangeValue};

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
    /// A solver setting's kind from its declaration in sim ([`SolverSettings::RANGES`]).
    pub const fn of_range(r: Range) -> Kind {
        match r {
            Range::Whole { min, max, soft_max } => Kind::Whole { min, max, soft_max },
            Range::Number { min, min_inclusive, max, max_inclusive, soft } => {
                Kind::Number { min, min_inclusive, max, max_inclusive, soft }
            }
        }
    }

    /// A number kind's range, in sim's terms: its check and its wording are sim's
    /// ([`Range::contains`], [`Range::expected`]), written once for the table and
    /// [`SolverSettings::validate`].
    pub fn range(&self) -> Option<Range> {
        match *self {
            Kind::Whole { min, max, soft_max } => Some(Range::Whole { min, max, soft_max }),
            Kind::Number { min, min_inclusive, max, max_inclusive, soft } => {
                Some(Range::Number { min, min_inclusive, max, max_inclusive, soft })
            }
            _ => None,
        }
    }

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
            Kind::Whole { .. } | Kind::Number { .. } => self.range().map(|r| r.expected()).unwrap_or_default(),
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
            (Kind::Whole { .. }, Value::Whole(n)) => self.range().is_some_and(|r| r.contains(RangeValue::Whole(*n))),
            (Kind::Number { .. }, Value::Number(x)) => self.range().is_some_and(|r| r.contains(RangeValue::Number(*x))),
            (Kind::Flag, Value::Flag(_)) => true,
            (Kind::Grid { min, max }, Value::Grid(g)) => g.iter().all(|c| (min..=max).contains(&c)),
            (Kind::Point, Value::Point(p)) => p.iter().all(|c| c.is_finite()),
            (Kind::Degree { max }, Value::Degree(d)) => d.is_none_or(|d| (1..=*max).contains(&d)),
            _ => false,
        };
        if ok { Ok(()) } else { Err(format!("must be {}", self.expected())) }
    }
}
