//! A parameter's value untyped ([`Value`]: shown, written as TOML or JSON) and its conversion
//! to and from the typed fields of [`super::Params`] ([`ParamType`]).

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
    String => Text, |s| s.clone(), |x| Some(x);
    usize => Whole, |s| *s as u64, |n| usize::try_from(n).ok();
    u32 => Whole, |s| u64::from(*s), |n| u32::try_from(n).ok();
    f64 => Number, |s| *s, |x| Some(x);
    bool => Flag, |s| *s, |b| Some(b);
    [usize; 3] => Grid, |s| *s, |g| Some(g);
    [f64; 3] => Point, |s| *s, |p| Some(p);
    Option<usize> => Degree, |s| *s, |d| Some(d);
}
