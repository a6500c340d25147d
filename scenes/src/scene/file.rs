//! Scene files: a scene is data, a TOML file (`assets/scenes/*.toml`) naming its mesh,
//! material, solver settings, the effects it needs and its probes.
//!
//! ```toml
//! name = "bending"
//! description = "…"
//! [mesh]        # a structured box (see hox_sim::mesh::structured), or a Gmsh file:
//!               # [mesh] file = "beam.msh" (relative to the scene file; see docs/MESHES.md),
//!               # or one file per element type, `element` picking one:
//!               # [mesh] files = { p1 = "tube-p1.msh", p2 = "tube-p2.msh" }
//! box_min_m = [0, 0, 0]
//! box_max_m = [2, 0.5, 0.5]
//! element = "p2"          # a registered element type (`hox elements`)
//! grid = [8, 2, 2]        # hexahedral cells per direction
//! split = "five"          # five (unbiased) | six (biased): tetrahedra per cell
//! refine = 0              # 1-to-8 refinements of the tetrahedra
//! [material]
//! model = "stvk"          # a registered model (hox_sim::material::MaterialModel::ALL)
//! youngs_modulus_pa = 3e6
//! poisson_ratio = 0.35
//! density_kg_m3 = 1000
//! [solver]                # all optional; defaults are the paper's
//! substeps = 50
//! iterations = 1
//! frames_per_second = 60
//! formulation = "energy"  # energy | split
//! quadrature_degree = 2   # omit for each element type's default
//! duration_secs = 3       # default run length
//! settle_damping_per_sec = 10  # velocity damping used by --settle
//! vbd_settle_damping_per_sec = 10 # the same with --solver vbd (2 settles fastest with vbd_coarse_cells = 0)
//! sweep = "colour"         # XPBD's sweep: colour (default) or element order
//! stability_guard = true   # above h·ω_max = 3, substeps with h·ω_max ≤ 1 (hox_sim::solver::stability)
//! [effect]                # optional: effects any scene can switch on
//! damping_per_sec = 0     # velocity damping of every node, always on (0: none)
//! [display]               # optional: how the app and recordings draw it
//! tessellation = 4        # pieces per edge of curved and quadrilateral faces
//! colour_max_m = 0        # top of the |u| colour range (0: a fifth of the largest extent)
//! quadrature_points = false
//! [[effects]]             # only the effects listed are simulated
//! type = "gravity"        # gravity | clamp | prescribed | damping | contact
//! acceleration_m_s2 = [0, 0, -9.81]
//! [[effects]]
//! type = "clamp"
//! nodes = { plane = "x", at_m = 0 }   # or { box_min_m = [...], box_max_m = [...] },
//!                                     # or { group = "clamp" } (a mesh file's physical group)
//! [[effects]]
//! type = "prescribed"     # translation and/or rotation, ramped smoothly then held
//! nodes = { plane = "x", at_m = 1 }
//! translation_m = [0.5, 0, 0]
//! rotation_axis = [1, 0, 0]
//! rotation_origin_m = [1, 0.25, 0.25]
//! rotation_deg = 90
//! ramp_secs = 1
//! [[effects]]
//! type = "damping"
//! rate_per_sec = 1
//! [[effects]]
//! type = "contact"        # half-space contact with a (moving) plane
//! point_m = [0, 0, 0]
//! normal = [0, 0, 1]      # points into the allowed side
//! velocity_m_s = [0, 0, 0]
//! move_secs = 2           # the plane stops after this long (default: never)
//! friction = 0.5
//! [[probes]]
//! name = "tip"
//! point_m = [2, 0.25, 0.25]
//! ```
//!
//! Unknown keys, missing fields, wrong types, negative or non-finite values, probes outside
//! the body and unknown physical groups are errors naming the file, the key and the value.

use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::Path;

use crate::error::SceneError;
use crate::params::{Group, MeshKind, PARAMS, Params};
use hox_sim::Vec3;
use hox_sim::effect::{AxisRotation, Prescribed};

/// A scene file as written (see the module docs): its `[mesh]`, `[material]` and `[solver]`
/// values are the parameter table's ([`crate::params`]), its effects and probes are lists.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    pub name: String,
    pub description: String,
    /// `[mesh] file`: a Gmsh mesh file, relative to the scene file (or absolute).
    pub mesh_file: Option<String>,
    /// `[mesh] files = { p1 = "…", p2 = "…", p3 = "…" }`: the same part meshed once per element
    /// type (the curved parts of `assets/parts/`, made by `scripts/gmsh_parts.py`); `element`
    /// picks the file. Relative like `file`; a built-in scene's are embedded
    /// ([`super::BUILTIN_MESHES`]).
    pub mesh_files: std::collections::BTreeMap<String, String>,
    /// Every parameter: the file's value, or the table's default.
    pub params: Params,
    /// The keys of the parameters the file gave (or an override set).
    pub given: BTreeSet<&'static str>,
    pub effects: Vec<EffectSpec>,
    pub probes: Vec<ProbeSpec>,
}

/// The file's layout; the parameter tables (one per [`Group`]) are read through the parameter table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSceneFile {
    name: String,
    #[serde(default)]
    description: String,
    mesh: toml::Table,
    material: toml::Table,
    #[serde(default)]
    solver: toml::Table,
    #[serde(default)]
    effect: toml::Table,
    #[serde(default)]
    display: toml::Table,
    #[serde(default)]
    effects: Vec<EffectSpec>,
    #[serde(default)]
    probes: Vec<ProbeSpec>,
}

impl SceneFile {
    /// Parses a scene file's text: the layout, then each `[mesh]`, `[material]`, `[solver]`,
    /// `[effect]` and `[display]` key through its entry in the parameter table (type and choice
    /// checked here, range when validated).
    pub fn parse(text: &str, source: &str) -> Result<SceneFile, SceneError> {
        let raw: RawSceneFile = toml::from_str(text)
            .map_err(|e| SceneError::Parse { source_name: source.to_string(), message: e.to_string() })?;
        let invalid = super::invalid_in(source);
        let mut file = SceneFile {
            name: raw.name,
            description: raw.description,
            mesh_file: None,
            mesh_files: Default::default(),
            params: Params::default(),
            given: BTreeSet::new(),
            effects: raw.effects,
            probes: raw.probes,
        };
        for group in Group::ALL {
            let table = match group {
                Group::Mesh => &raw.mesh,
                Group::Material => &raw.material,
                Group::Solver => &raw.solver,
                Group::Effect => &raw.effect,
                Group::Display => &raw.display,
            };
            for (key, value) in table {
                let path = format!("{}.{key}", group.section());
                if group == Group::Mesh && key == "file" {
                    let f = value.as_str().ok_or_else(|| invalid(&path, value.to_string(), "expected a file name"))?;
                    file.mesh_file = Some(f.to_string());
                    continue;
                }
                if group == Group::Mesh && key == "files" {
                    file.mesh_files = files_table(value, &path, &invalid)?;
                    continue;
                }
                let param = PARAMS.iter().find(|p| p.group == group && p.file_key == key).ok_or_else(|| {
                    let known: Vec<&str> = PARAMS.iter().filter(|p| p.group == group).map(|p| p.file_key).collect();
                    invalid(&path, value.to_string(), &format!("unknown key (expected one of {})", known.join(", ")))
                })?;
                let v = param.kind.from_toml(value).map_err(|reason| invalid(&path, value.to_string(), &reason))?;
                // a choice's name (or a number out of its field's range) is parsed into the typed
                // field here, the one place the file's text becomes a value
                if !(param.set)(&mut file.params, v.clone()) {
                    let reason =
                        param.check_value(&v).err().unwrap_or_else(|| format!("must be {}", param.kind.expected()));
                    return Err(invalid(&path, v.to_string(), &reason));
                }
                file.given.insert(param.key);
            }
        }
        if file.mesh_file.is_some() && !file.mesh_files.is_empty() {
            return Err(invalid(
                "mesh.files",
                "given".into(),
                "give either file (one mesh) or files (one per element type)",
            ));
        }
        let kind = file.mesh_kind();
        for p in PARAMS.iter().filter(|p| p.required && !file.given.contains(p.key)) {
            if kind != MeshKind::Box && p.box_only {
                continue;
            }
            let reason = if p.box_only {
                "a box mesh needs box_min_m, box_max_m, element and grid (or give file = \"….msh\")"
            } else {
                "is required"
            };
            return Err(invalid(&p.file_path(), "missing".into(), reason));
        }
        Ok(file)
    }

    /// What the mesh is: a box, one file, or one file per element type.
    pub fn mesh_kind(&self) -> MeshKind {
        match (&self.mesh_file, self.mesh_files.is_empty()) {
            (Some(_), _) => MeshKind::File,
            (None, false) => MeshKind::Files,
            (None, true) => MeshKind::Box,
        }
    }

    /// The scene file's text (TOML): the parameters given (and those a box or a material needs),
    /// the effects and the probes. Parsing it gives `self` back.
    pub fn to_toml(&self) -> String {
        let mut root = toml::Table::new();
        root.insert("name".into(), self.name.clone().into());
        root.insert("description".into(), self.description.clone().into());
        for group in Group::ALL {
            let mut t = toml::Table::new();
            if group == Group::Mesh
                && let Some(f) = &self.mesh_file
            {
                t.insert("file".into(), f.clone().into());
            }
            if group == Group::Mesh && !self.mesh_files.is_empty() {
                let files: toml::Table = self.mesh_files.iter().map(|(k, v)| (k.clone(), v.clone().into())).collect();
                t.insert("files".into(), toml::Value::Table(files));
            }
            for p in PARAMS.iter().filter(|p| p.group == group) {
                if p.used_with(self.mesh_kind())
                    && (self.given.contains(p.key) || p.required)
                    && let Some(v) = (p.get)(&self.params).to_toml()
                {
                    t.insert(p.file_key.into(), v);
                }
            }
            root.insert(group.section().into(), toml::Value::Table(t));
        }
        // the lists go into the same document, so the serializer places them after the tables
        if let Ok(v) = toml::Value::try_from(&self.effects) {
            root.insert("effects".into(), v);
        }
        if !self.probes.is_empty()
            && let Ok(v) = toml::Value::try_from(&self.probes)
        {
            root.insert("probes".into(), v);
        }
        toml::to_string(&root).unwrap_or_default()
    }

    /// A scene around a mesh file: the bending scene's material (the paper's beam: StVK,
    /// E = 3 MPa, ν = 0.35, ρ = 1000 kg/m³, read from assets/scenes/bending.toml), Newton with
    /// the default solver settings (its factor policy `auto`), and gravity unless `gravity` is
    /// false. Callers add clamps and drives
    /// (`NodeSelector::group`).
    pub fn for_mesh_file(path: &Path, gravity: bool) -> SceneFile {
        let bending =
            super::builtin::BUILTIN.iter().find(|(n, _)| *n == "bending").map(|(_, t)| *t).unwrap_or_default();
        let mut params = Params::default();
        let mut given = BTreeSet::new();
        if let Ok(b) = SceneFile::parse(bending, "builtin:bending") {
            for p in PARAMS.iter().filter(|p| p.group == Group::Material) {
                (p.set)(&mut params, (p.get)(&b.params));
                given.insert(p.key);
            }
        }
        // a user's part runs on the fastest safe path without a flag (issue #61): Newton, its
        // factor policy chosen by the part's size; the paper's scenes keep XPBD
        params.method = hox_sim::solver::Method::Newton;
        given.insert("solver");
        SceneFile {
            name: path.file_stem().map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned()),
            description: format!("the mesh {}", path.display()),
            mesh_file: Some(path.display().to_string()),
            mesh_files: Default::default(),
            params,
            given,
            effects: if gravity {
                vec![EffectSpec::Gravity { acceleration_m_s2: [0.0, 0.0, -9.81] }]
            } else {
                Vec::new()
            },
            probes: Vec::new(),
        }
    }
}

/// `[mesh] files`: a table from registered element type names to file names.
fn files_table(
    value: &toml::Value,
    path: &str,
    invalid: &dyn Fn(&str, String, &str) -> SceneError,
) -> Result<std::collections::BTreeMap<String, String>, SceneError> {
    let table = value.as_table().filter(|t| !t.is_empty()).ok_or_else(|| {
        invalid(
            path,
            value.to_string(),
            "expected a table of files by element type, e.g. { p1 = \"part-p1.msh\", p2 = \"part-p2.msh\" }",
        )
    })?;
    let mut files = std::collections::BTreeMap::new();
    for (element, f) in table {
        let key = format!("{path}.{element}");
        let Some(element_type) = hox_sim::element::ElementType::from_name(element) else {
            let known = hox_sim::element::ElementType::names();
            return Err(invalid(&key, element.clone(), &format!("not an element type (expected one of {known})")));
        };
        let name = f.as_str().ok_or_else(|| invalid(&key, f.to_string(), "expected a file name"))?;
        files.insert(element_type.name().to_string(), name.to_string());
    }
    Ok(files)
}

/// Which nodes an effect acts on: those on an axis-aligned plane, inside a box, or in a
/// physical group of the mesh file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSelector {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_min_m: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub box_max_m: Option<[f64; 3]>,
    /// A physical group of the mesh file (`[mesh] file = …`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
}

impl NodeSelector {
    /// The nodes of a mesh file's physical group.
    pub fn group(name: &str) -> Self {
        Self { group: Some(name.to_string()), ..Default::default() }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum EffectSpec {
    Gravity {
        acceleration_m_s2: [f64; 3],
    },
    Clamp {
        nodes: NodeSelector,
    },
    Prescribed {
        nodes: NodeSelector,
        #[serde(default)]
        translation_m: [f64; 3],
        #[serde(default)]
        rotation_axis: Option<[f64; 3]>,
        #[serde(default)]
        rotation_origin_m: Option<[f64; 3]>,
        #[serde(default)]
        rotation_deg: f64,
        #[serde(default)]
        ramp_secs: f64,
    },
    Damping {
        rate_per_sec: f64,
    },
    Contact {
        point_m: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        velocity_m_s: [f64; 3],
        #[serde(default)]
        move_secs: Option<f64>,
        #[serde(default)]
        friction: f64,
    },
}

impl EffectSpec {
    /// The prescribed motion this spec describes, acting on `nodes` (None for other effects).
    pub fn prescribed(&self, nodes: Vec<u32>) -> Option<Prescribed> {
        let EffectSpec::Prescribed { translation_m, rotation_axis, rotation_origin_m, rotation_deg, ramp_secs, .. } =
            self
        else {
            return None;
        };
        let rotation = rotation_axis.map(|axis| AxisRotation {
            axis: Vec3::from(axis).normalize(),
            origin_m: Vec3::from(rotation_origin_m.unwrap_or([0.0; 3])),
            angle_rad: rotation_deg.to_radians(),
        });
        Some(Prescribed { nodes, translation_m: Vec3::from(*translation_m), rotation, ramp_secs: *ramp_secs })
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Self::Gravity { .. } => "gravity",
            Self::Clamp { .. } => "clamp",
            Self::Prescribed { .. } => "prescribed",
            Self::Damping { .. } => "damping",
            Self::Contact { .. } => "contact",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub point_m: [f64; 3],
}
