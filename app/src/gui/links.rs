//! Compare-mode links: which controls of the second configuration follow the first.

/// Which controls of the second configuration follow the first (compare mode).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Links(pub std::collections::BTreeMap<String, bool>);

/// The parameters a link can tie: those the app shows, in control order (the parameter table).
pub fn linkable() -> impl Iterator<Item = &'static str> {
    hox_scenes::params::PARAMS.iter().filter(|p| p.surfaces.app).map(|p| p.key)
}

impl Default for Links {
    fn default() -> Self {
        // the classroom comparison: different element (and refinement), everything else shared
        Links(linkable().map(|f| (f.to_string(), !matches!(f, "element" | "refine"))).collect())
    }
}

impl Links {
    pub fn linked(&self, field: &str) -> bool {
        self.0.get(field).copied().unwrap_or(true)
    }
}
