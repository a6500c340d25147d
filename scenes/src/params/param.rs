//! One entry of the parameter table ([`Param`]): its keys, label, help, kind, surfaces and
//! accessors, and the fields every entry shares unless it says otherwise ([`BASE`]).

use super::kind::{EVERYWHERE, Group, Invalidates, Kind, Surfaces};
use super::value::Value;
use super::{Params, SceneOverrides};

/// What a scene's mesh is, for which mesh parameters it reads ([`Param::used_with`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshKind {
    /// A structured box: element, split, grid, refinement and the corners.
    Box,
    /// One mesh file (`[mesh] file`): none of the box's parameters.
    File,
    /// One mesh file per element type (`[mesh] files`, the curved parts of `assets/parts/`):
    /// the element type picks the file.
    Files,
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
    /// A box mesh's parameter, meaningless for a mesh file ([`Param::used_with`]).
    pub box_only: bool,
    /// A box parameter that a scene with one mesh file per element type (`[mesh] files`) uses
    /// too: the element type, which picks the file.
    pub picks_file: bool,
    /// For a flag: the command line's switch and the value it sets (`--no-stability-guard`
    /// sets false) instead of `--KEY VALUE`.
    pub switch: Option<(&'static str, bool)>,
    /// Whether it applies to a configuration (the app greys it out where not; e.g. the tet
    /// split for hexahedra). None: always.
    /// (A solver's own parameter also needs the configuration's solver to read it:
    /// [`Param::applies_to`].)
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
    /// Whether it applies to the configuration `p`: its own predicate, and for a solver's own
    /// parameter, the configuration's solver reads it ([`super::applies::solver_reads`]).
    pub fn applies_to(&self, p: &Params) -> bool {
        self.applies.is_none_or(|f| f(p)) && super::applies::solver_reads(p.method, self.file_key)
    }

    /// Whether a scene whose mesh is of kind `kind` reads this parameter: every one for a box, the
    /// non-box ones for a mesh file, and the element type too for one file per element type.
    pub fn used_with(&self, kind: MeshKind) -> bool {
        match kind {
            MeshKind::Box => true,
            MeshKind::File => !self.box_only,
            MeshKind::Files => !self.box_only || self.picks_file,
        }
    }

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

/// Fields every entry shares unless it says otherwise.
pub(super) const BASE: Param = Param {
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
    picks_file: false,
    switch: None,
    applies: None,
    check_with: None,
    get: |_| Value::Flag(false),
    set: |_, _| false,
    get_override: |_| None,
    set_override: |_, _| false,
};
