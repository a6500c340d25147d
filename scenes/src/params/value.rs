//! A parameter's value untyped ([`Value`]: shown, written as TOML or JSON) and its conversion
//! to and from the typed fields of [`super::Params`] ([`ParamType`]); the choice parameters'
//! types ([`Choice`]: element, split, material, solver, sweep, formulation, VBD start, fields).

use hox_sim::element::ElementType;
use hox_sim::material::MaterialModel;
use hox_sim::measure::field::Field;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::{Integrator, Method, NewtonPolicy, Sweep, VbdInit};
use hox_sim::xpbd::constraint::Formulation;

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
    usize => Whole, |s| *s as u64, |n| usize::try_from(n).ok();
    u32 => Whole, |s| u64::from(*s), |n| u32::try_from(n).ok();
    f64 => Number, |s| *s, |x| Some(x);
    bool => Flag, |s| *s, |b| Some(b);
    [usize; 3] => Grid, |s| *s, |g| Some(g);
    [f64; 3] => Point, |s| *s, |p| Some(p);
    Option<usize> => Degree, |s| *s, |d| Some(d);
}

/// A choice parameter's typed value: one of named options, written by its name ([`Kind::Choice`]
/// checks text against the same names, so text that passes the check always converts).
///
/// [`Kind::Choice`]: super::Kind::Choice
pub trait Choice: Copy + 'static {
    /// Every option, in menu order.
    fn options() -> Vec<Self>;
    /// The option's name on the command line and in scene files.
    fn name(self) -> &'static str;
    /// The option named exactly `name` (the names are lowercase; command-line text is lowercased
    /// when parsed, a scene file's is taken as written).
    fn from_option_name(name: &str) -> Option<Self> {
        Self::options().into_iter().find(|o| o.name() == name)
    }
}

macro_rules! choice {
    ($($ty:ty => $options:expr, |$o:ident| $name:expr;)*) => {
        $(impl Choice for $ty {
            fn options() -> Vec<Self> {
                $options
            }
            fn name(self) -> &'static str {
                let $o = self;
                $name
            }
        }
        impl ParamType for $ty {
            fn to_value(&self) -> Value {
                Value::Text(Choice::name(*self).to_string())
            }
            fn from_value(v: Value) -> Option<Self> {
                if let Value::Text(s) = v { <$ty as Choice>::from_option_name(&s) } else { None }
            }
        })*
    };
}

choice! {
    ElementType => ElementType::all().collect(), |o| o.reference().name();
    TetSplit => vec![TetSplit::Five, TetSplit::Six], |o| TetSplit::name(o);
    MaterialModel => MaterialModel::ALL.to_vec(), |o| MaterialModel::name(o);
    Method => Method::ALL.to_vec(), |o| Method::name(o);
    Sweep => Sweep::ALL.to_vec(), |o| Sweep::name(o);
    Formulation => Formulation::ALL.to_vec(), |o| Formulation::name(o);
    VbdInit => VbdInit::ALL.to_vec(), |o| VbdInit::name(o);
    NewtonPolicy => NewtonPolicy::ALL.to_vec(), |o| NewtonPolicy::name(o);
    Integrator => Integrator::ALL.to_vec(), |o| Integrator::name(o);
    Field => Field::ALL.to_vec(), |o| Field::name(o);
}

/// One or more options in order ([`Kind::Choices`]), written comma-separated.
///
/// [`Kind::Choices`]: super::Kind::Choices
impl<T: Choice> ParamType for Vec<T> {
    fn to_value(&self) -> Value {
        Value::Text(self.iter().map(|o| o.name()).collect::<Vec<_>>().join(","))
    }
    fn from_value(v: Value) -> Option<Self> {
        if let Value::Text(s) = v { s.split(',').map(T::from_option_name).collect() } else { None }
    }
}

/// Serde for a field stored as text ([`Value::Text`]): the typed choices, written by name as the
/// app persisted them when they were strings; an unknown name is an error.
pub(super) mod as_text {
    use super::{ParamType, Value};
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<T: ParamType, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&v.to_value().to_string())
    }

    pub fn deserialize<'de, T: ParamType, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        let text = String::deserialize(d)?;
        T::from_value(Value::Text(text.clone())).ok_or_else(|| D::Error::custom(format!("unknown option '{text}'")))
    }
}
