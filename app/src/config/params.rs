//! The scene parameters on the command line (the headless commands' and `hox app`'s), made from
//! the parameter table ([`hox_scenes::params::PARAMS`]): one flag per entry shown on the command
//! line (`--KEY VALUE`, or a switch such as `--no-stability-guard`), parsed by the entry's kind
//! (a choice into its option); the range is checked when the scene is validated, and an error
//! names the option.

use clap::{Arg, ArgAction, ArgMatches, Command, FromArgMatches};
use hox_scenes::SceneOverrides;
use hox_scenes::params::{Group, Kind, PARAMS, Param, Value};

/// The mesh parameters (`--element --grid --split --refine`).
#[derive(Clone, Debug, Default)]
pub struct MeshArgs {
    pub overrides: SceneOverrides,
}

/// The material, solver and effect parameters (`--material --youngs … --sweep
/// --no-stability-guard --damping`).
#[derive(Clone, Debug, Default)]
pub struct PhysicsArgs {
    pub overrides: SceneOverrides,
}

/// The display parameters (`--tessellation --colour-max-m --quadrature-points`), for the
/// commands that draw (`hox record`, `hox app`).
#[derive(Clone, Debug, Default)]
pub struct DisplayArgs {
    pub overrides: SceneOverrides,
}

fn on_cli(groups: &'static [Group]) -> impl Iterator<Item = &'static Param> {
    PARAMS.iter().filter(move |p| p.surfaces.cli && groups.contains(&p.group))
}

fn value_name(p: &Param) -> &'static str {
    match p.kind {
        Kind::Choice(_) => "NAME",
        Kind::Choices(_) => "NAME[,NAME…]",
        Kind::Whole { .. } => "N",
        Kind::Number { .. } => "X",
        Kind::Flag => "on|off",
        Kind::Grid { .. } => "NXxNYxNZ",
        Kind::Point => "X,Y,Z",
        Kind::Degree { .. } => "DEGREE",
    }
}

/// The clap argument of one table entry.
pub fn arg(p: &'static Param) -> Arg {
    let unit = if p.unit.is_empty() { String::new() } else { format!(", {}", p.unit) };
    match p.switch {
        Some((name, _)) => Arg::new(p.key).long(name).action(ArgAction::SetTrue).help(p.help),
        // a list may be given as one comma-separated value or by repeating the flag
        None if matches!(p.kind, Kind::Choices(_)) => Arg::new(p.key)
            .long(p.key)
            .value_name(value_name(p))
            .help(format!("{} [{}]", p.help, p.kind.expected()))
            .action(ArgAction::Append)
            .value_parser(move |s: &str| parse(p, s)),
        None => Arg::new(p.key)
            .long(p.key)
            .value_name(value_name(p))
            .help(format!("{} [{}{unit}]", p.help, p.kind.expected()))
            // `--grid -4x2x2` and `--refine -1` reach the parser, which names the option
            .allow_hyphen_values(true)
            .value_parser(move |s: &str| parse(p, s)),
    }
}

/// A flag's value: a choice's name is parsed into its option here (the overrides hold the typed
/// value), so an unknown name is refused with the entry's reason (`Element must be one of …`);
/// the other ranges are checked when the scene is validated.
fn parse(p: &'static Param, text: &str) -> Result<Value, String> {
    let v = p.kind.parse(text)?;
    if matches!(p.kind, Kind::Choice(_) | Kind::Choices(_)) {
        p.check_value(&v)?;
    }
    Ok(v)
}

fn augment(mut cmd: Command, groups: &'static [Group]) -> Command {
    for p in on_cli(groups) {
        cmd = cmd.arg(arg(p));
    }
    cmd
}

fn read(m: &ArgMatches, groups: &'static [Group]) -> SceneOverrides {
    let mut o = SceneOverrides::default();
    for p in on_cli(groups) {
        match p.switch {
            Some((_, sets)) => {
                if m.get_flag(p.key) {
                    (p.set_override)(&mut o, Value::Flag(sets));
                }
            }
            None if matches!(p.kind, Kind::Choices(_)) => {
                if let Some(values) = m.get_many::<Value>(p.key) {
                    let names: Vec<String> = values.map(|v| v.to_string()).collect();
                    (p.set_override)(&mut o, Value::Text(names.join(",")));
                }
            }
            None => {
                if let Some(v) = m.get_one::<Value>(p.key) {
                    (p.set_override)(&mut o, v.clone());
                }
            }
        }
    }
    o
}

const MESH: &[Group] = &[Group::Mesh];
const PHYSICS: &[Group] = &[Group::Material, Group::Solver, Group::Effect];
const DISPLAY: &[Group] = &[Group::Display];

macro_rules! param_args {
    ($ty:ident, $groups:expr) => {
        impl FromArgMatches for $ty {
            fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
                Ok(Self { overrides: read(m, $groups) })
            }
            fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
                self.overrides = self.overrides.merged(&read(m, $groups));
                Ok(())
            }
        }
        impl clap::Args for $ty {
            fn augment_args(cmd: Command) -> Command {
                augment(cmd, $groups)
            }
            fn augment_args_for_update(cmd: Command) -> Command {
                augment(cmd, $groups)
            }
        }
    };
}

param_args!(MeshArgs, MESH);
param_args!(PhysicsArgs, PHYSICS);
param_args!(DisplayArgs, DISPLAY);

/// The overrides the command line gives.
pub fn overrides(mesh: &MeshArgs, physics: Option<&PhysicsArgs>) -> SceneOverrides {
    physics.map_or_else(|| mesh.overrides.clone(), |p| mesh.overrides.merged(&p.overrides))
}
