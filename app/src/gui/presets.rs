//! What the class sees of the bodies, as the model holds it: the drawing options
//! ([`ViewOptions`]) and the camera preset ([`ViewPreset`]), which also lays compared
//! configurations apart.

/// What the viewport shows.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ViewOptions {
    pub edges: bool,
    pub nodes: bool,
    pub boundary_conditions: bool,
    pub ghost: bool,
    pub probes: bool,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self { edges: true, nodes: false, boundary_conditions: true, ghost: true, probes: true }
    }
}

/// A camera preset: where the view looks from, and the axis compared configurations are laid
/// apart along so neither hides the other from there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
pub enum ViewPreset {
    /// Three-quarter view from the front, above.
    #[default]
    Iso,
    /// Looking along +y at the x–z plane: a beam's bending.
    Front,
    /// Looking along −x at the y–z plane: a beam's cross-section, its twist and sideways bend.
    Side,
    /// Looking down −z at the x–y plane: a sideways bend (the tet split's bias).
    Top,
}

impl ViewPreset {
    pub const ALL: [ViewPreset; 4] = [ViewPreset::Iso, ViewPreset::Front, ViewPreset::Side, ViewPreset::Top];

    pub fn name(self) -> &'static str {
        match self {
            ViewPreset::Iso => "iso",
            ViewPreset::Front => "front",
            ViewPreset::Side => "side",
            ViewPreset::Top => "top",
        }
    }

    /// The preset named `name` ("iso", "front", "side", "top").
    pub fn from_name(name: &str) -> Option<ViewPreset> {
        ViewPreset::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The camera's (yaw, pitch), radians ([`Camera`]): the eye's direction from the target.
    pub fn yaw_pitch(self) -> (f32, f32) {
        use std::f32::consts::FRAC_PI_2;
        match self {
            ViewPreset::Iso => (-1.2, 0.45),
            ViewPreset::Front => (-FRAC_PI_2, 0.0),
            ViewPreset::Side => (0.0, 0.0),
            // straight down, x to the right
            ViewPreset::Top => (-FRAC_PI_2, FRAC_PI_2 - 1e-3),
        }
    }

    /// The axis across the line of sight that configurations are laid apart along.
    pub fn layout_axis(self) -> crate::display::LayoutAxis {
        match self {
            ViewPreset::Side => crate::display::LayoutAxis::Y,
            _ => crate::display::LayoutAxis::X,
        }
    }
}
