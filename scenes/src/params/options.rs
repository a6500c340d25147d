//! The options of the choice parameters (`element`, `split`, `material`, `solver`, `sweep`,
//! `formulation`, `vbd-init`, `integrator`, `field`): each option's name and description, from sim's registries.

use hox_sim::element::ElementType;
use hox_sim::material::MaterialModel;
use hox_sim::mesh::structured::TetSplit;
use hox_sim::solver::{Integrator, Method, NewtonPolicy, Sweep, VbdInit};
use hox_sim::xpbd::constraint::Formulation;

pub(super) fn element_options() -> Vec<(&'static str, String)> {
    ElementType::all().map(|e| (e.name(), format!("{} — {}", e.name().to_uppercase(), e.description()))).collect()
}
pub(super) fn split_options() -> Vec<(&'static str, String)> {
    [TetSplit::Five, TetSplit::Six]
        .iter()
        .map(|s| (s.name(), format!("{} ({})", s.name(), if *s == TetSplit::Five { "unbiased" } else { "biased" })))
        .collect()
}
pub(super) fn material_options() -> Vec<(&'static str, String)> {
    MaterialModel::ALL.iter().map(|m| (m.name(), m.long_name().to_string())).collect()
}
pub(super) fn sweep_options() -> Vec<(&'static str, String)> {
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
pub(super) fn formulation_options() -> Vec<(&'static str, String)> {
    Formulation::ALL.iter().map(|f| (f.name(), f.name().to_string())).collect()
}

pub(super) fn field_options() -> Vec<(&'static str, String)> {
    hox_sim::measure::field::Field::ALL.iter().map(|f| (f.name(), f.description().to_string())).collect()
}

pub(super) fn method_options() -> Vec<(&'static str, String)> {
    Method::ALL.iter().map(|m| (m.name(), m.long_name().to_string())).collect()
}
pub(super) fn newton_policy_options() -> Vec<(&'static str, String)> {
    NewtonPolicy::ALL.iter().map(|p| (p.name(), p.name().to_string())).collect()
}

pub(super) fn vbd_init_options() -> Vec<(&'static str, String)> {
    VbdInit::ALL.iter().map(|i| (i.name(), i.name().to_string())).collect()
}
pub(super) fn integrator_options() -> Vec<(&'static str, String)> {
    Integrator::ALL.iter().map(|i| (i.name(), i.long_name().to_string())).collect()
}
