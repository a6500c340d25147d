//! Validating a scene file: every parameter against its entry's range ([`crate::params`]), the
//! material against its model, the mesh (a box, or a Gmsh file read now), the effects and the
//! probes. Errors name the source, the key and the value.

use hox_sim::Vec3;
use hox_sim::element::ElementType;
use hox_sim::material::Material;
use hox_sim::mesh::structured::{BoxGrid, BoxMeshSpec};
use hox_sim::xpbd::constraint::Formulation;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::build::axis_index;
use super::{EffectSpec, NodeSelector, Scene, SceneFile, SceneMesh};
use crate::error::SceneError;
use crate::params::{MeshKind, PARAMS};

pub(crate) type Invalid<'a> = dyn Fn(&str, String, &str) -> SceneError + 'a;

/// An error maker for `source`: `(key, value, reason)`.
pub(crate) fn invalid_in(source: &str) -> impl Fn(&str, String, &str) -> SceneError + '_ {
    move |key: &str, value: String, reason: &str| SceneError::Invalid {
        source_name: source.to_string(),
        key: key.to_string(),
        value,
        reason: reason.to_string(),
    }
}

impl Scene {
    /// Validates `file`; `cached` is a mesh file already read for the same path.
    pub(super) fn validate(
        file: SceneFile,
        source: &str,
        base_dir: Option<PathBuf>,
        cached: Option<&SceneMesh>,
    ) -> Result<Scene, SceneError> {
        let invalid = invalid_in(source);
        let params = &file.params;
        let kind = file.mesh_kind();
        for p in PARAMS.iter().filter(|p| p.used_with(kind)) {
            p.check(params).map_err(|reason| invalid(&p.file_path(), (p.get)(params).to_string(), &reason))?;
        }
        let mesh = mesh_of(&file, source, base_dir.as_deref(), cached, &invalid)?;
        // E, ν and ρ were checked against the table just now, whose ranges are sim's
        // (`hox_sim::material::YOUNGS_MODULUS_PA`, …): they are not checked again. What remains is
        // the pair (E, ν) overflowing μ or λ, reported on E
        let material = Material::from_checked_ranges(
            params.material,
            params.youngs_modulus_pa,
            params.poisson_ratio,
            params.density_kg_m3,
        )
        .map_err(|e| invalid("material.youngs_modulus_pa", params.youngs_modulus_pa.to_string(), &e.to_string()))?;
        if let Some(d) = params.quadrature_degree {
            let types: Vec<ElementType> = match &mesh {
                SceneMesh::Box(b) => vec![b.element_type],
                SceneMesh::File { imported, .. } => imported.mesh.blocks.iter().map(|b| b.element_type).collect(),
            };
            for element_type in types {
                let max = hox_sim::fem::quadrature::max_degree(element_type.shape());
                if d == 0 || d > max {
                    return Err(invalid(
                        "solver.quadrature_degree",
                        d.to_string(),
                        &format!("must lie in 1..={max} for {element_type}"),
                    ));
                }
            }
        }
        if params.formulation == Formulation::Split && material.split_stiffness_pa().iter().any(|k| !(*k > 0.0)) {
            return Err(invalid(
                "material.poisson_ratio",
                params.poisson_ratio.to_string(),
                "the split formulation needs positive Lamé parameters (ν ≥ 0); use the energy formulation",
            ));
        }
        for (k, e) in file.effects.iter().enumerate() {
            validate_effect(k, e, &invalid)?;
            if let EffectSpec::Clamp { nodes } | EffectSpec::Prescribed { nodes, .. } = e {
                validate_group(&format!("effects[{k}].nodes"), nodes, &mesh, &invalid)?;
            }
        }
        let mut names = std::collections::HashSet::new();
        for (k, p) in file.probes.iter().enumerate() {
            finite3(&format!("probes[{k}].point_m"), &p.point_m, &invalid)?;
            if !names.insert(p.name.as_str()) {
                return Err(invalid(&format!("probes[{k}].name"), format!("{:?}", p.name), "is used twice"));
            }
        }
        Ok(Scene { source: source.to_string(), base_dir, file, mesh, material })
    }
}

/// The scene's mesh: a box from its parameters, or the file (read now, or reused from `cached`).
fn mesh_of(
    file: &SceneFile,
    source: &str,
    base_dir: Option<&Path>,
    cached: Option<&SceneMesh>,
    invalid: &Invalid<'_>,
) -> Result<SceneMesh, SceneError> {
    let p = &file.params;
    let picked;
    let mesh_file = match file.mesh_kind() {
        MeshKind::Box => None,
        MeshKind::File => file.mesh_file.as_ref(),
        MeshKind::Files => {
            let element = p.element.name();
            picked = file.mesh_files.get(element).ok_or_else(|| {
                let types: Vec<&str> = file.mesh_files.keys().map(String::as_str).collect();
                invalid(
                    "mesh.element",
                    element.to_string(),
                    &format!("this part is meshed as {} only (mesh.files)", types.join(", ")),
                )
            })?;
            Some(picked)
        }
    };
    if let Some(mesh_file) = mesh_file {
        if let Some(given) = PARAMS.iter().find(|q| !q.used_with(file.mesh_kind()) && file.given.contains(q.key)) {
            let reason = if file.mesh_kind() == MeshKind::Files {
                format!(
                    "the part is read from {mesh_file} (the element type picks its file); box_min_m, box_max_m, grid, split and refine describe box meshes"
                )
            } else {
                format!(
                    "the mesh is read from {mesh_file}; box_min_m, box_max_m, element, grid, split and refine describe box meshes"
                )
            };
            return Err(invalid(&given.file_path(), "given".into(), &reason));
        }
        let path = match base_dir {
            Some(dir) if Path::new(mesh_file).is_relative() => dir.join(mesh_file),
            _ => PathBuf::from(mesh_file),
        };
        if let Some(SceneMesh::File { path: cached_path, imported }) = cached
            && *cached_path == path
        {
            return Ok(SceneMesh::File { path, imported: imported.clone() });
        }
        // a built-in scene's mesh files are in the binary (a scene read without a folder, such
        // as a built-in one or its text written back, names them relative to assets/scenes/)
        if base_dir.is_none()
            && let Some(imported) = super::builtin_mesh(mesh_file)
        {
            let imported = imported.map_err(|message| SceneError::Mesh { source_name: source.to_string(), message })?;
            return Ok(SceneMesh::File { path, imported });
        }
        let imported = hox_sim::io::gmsh::read_msh(&path).map_err(|e| {
            // a scene built from the mesh file alone (`--mesh`) is named by the file already
            if source == path.display().to_string() {
                SceneError::MeshFile(e.to_string())
            } else {
                SceneError::Mesh { source_name: source.to_string(), message: e.to_string() }
            }
        })?;
        return Ok(SceneMesh::File { path, imported: Arc::new(imported) });
    }
    // the ranges were checked against the parameter table, the choices parsed when read
    for d in 0..3 {
        if p.box_max_m[d] <= p.box_min_m[d] {
            return Err(invalid(
                "mesh.box_max_m",
                format!("{:?}", p.box_max_m),
                "must exceed box_min_m in every direction",
            ));
        }
    }
    Ok(SceneMesh::Box(BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::from(p.box_min_m), max_m: Vec3::from(p.box_max_m), cells: p.grid },
        element_type: p.element,
        split: p.split,
        refine: p.refine,
    }))
}

fn finite3(key: &str, v: &[f64; 3], invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if v.iter().all(|c| c.is_finite()) { Ok(()) } else { Err(invalid(key, format!("{v:?}"), "must be finite")) }
}

fn non_negative(key: &str, v: f64, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 { Ok(()) } else { Err(invalid(key, v.to_string(), "must be finite and not negative")) }
}

fn validate_selector(key: &str, sel: &NodeSelector, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    if sel.group.is_some() {
        return if sel.plane.is_none() && sel.at_m.is_none() && sel.box_min_m.is_none() && sel.box_max_m.is_none() {
            Ok(())
        } else {
            Err(invalid(key, format!("{sel:?}"), "give a group alone, not with a plane or box"))
        };
    }
    match (&sel.plane, sel.at_m, sel.box_min_m, sel.box_max_m) {
        (Some(p), Some(at), None, None) => {
            if axis_index(p).is_none() {
                return Err(invalid(&format!("{key}.plane"), format!("{p:?}"), "expected \"x\", \"y\" or \"z\""));
            }
            if !at.is_finite() {
                return Err(invalid(&format!("{key}.at_m"), at.to_string(), "must be finite"));
            }
            Ok(())
        }
        (None, None, Some(a), Some(b)) => {
            finite3(&format!("{key}.box_min_m"), &a, invalid)?;
            finite3(&format!("{key}.box_max_m"), &b, invalid)
        }
        _ => Err(invalid(key, format!("{sel:?}"), "give either plane and at_m, box_min_m and box_max_m, or group")),
    }
}

/// A group selector needs a mesh file that has the group.
fn validate_group(key: &str, sel: &NodeSelector, mesh: &SceneMesh, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    let Some(name) = &sel.group else { return Ok(()) };
    match mesh.imported() {
        None => Err(invalid(
            &format!("{key}.group"),
            format!("{name:?}"),
            "physical groups need a mesh file ([mesh] file = \"….msh\")",
        )),
        Some(imported) => imported
            .node_set(name)
            .map(|_| ())
            .map_err(|e| invalid(&format!("{key}.group"), format!("{name:?}"), &e.to_string())),
    }
}

fn validate_effect(k: usize, e: &EffectSpec, invalid: &Invalid<'_>) -> Result<(), SceneError> {
    let key = |f: &str| format!("effects[{k}].{f}");
    match e {
        EffectSpec::Gravity { acceleration_m_s2 } => finite3(&key("acceleration_m_s2"), acceleration_m_s2, invalid),
        EffectSpec::Clamp { nodes } => validate_selector(&key("nodes"), nodes, invalid),
        EffectSpec::Prescribed { nodes, translation_m, rotation_axis, rotation_origin_m, rotation_deg, ramp_secs } => {
            validate_selector(&key("nodes"), nodes, invalid)?;
            finite3(&key("translation_m"), translation_m, invalid)?;
            if let Some(a) = rotation_axis {
                finite3(&key("rotation_axis"), a, invalid)?;
                if Vec3::from(*a).norm() == 0.0 {
                    return Err(invalid(&key("rotation_axis"), format!("{a:?}"), "must not be zero"));
                }
            }
            if let Some(o) = rotation_origin_m {
                finite3(&key("rotation_origin_m"), o, invalid)?;
            }
            if !rotation_deg.is_finite() {
                return Err(invalid(&key("rotation_deg"), rotation_deg.to_string(), "must be finite"));
            }
            if *rotation_deg != 0.0 && rotation_axis.is_none() {
                return Err(invalid(&key("rotation_axis"), "missing".into(), "a rotation needs an axis"));
            }
            non_negative(&key("ramp_secs"), *ramp_secs, invalid)
        }
        EffectSpec::Damping { rate_per_sec } => non_negative(&key("rate_per_sec"), *rate_per_sec, invalid),
        EffectSpec::Contact { point_m, normal, velocity_m_s, move_secs, friction } => {
            finite3(&key("point_m"), point_m, invalid)?;
            finite3(&key("normal"), normal, invalid)?;
            if Vec3::from(*normal).norm() == 0.0 {
                return Err(invalid(&key("normal"), format!("{normal:?}"), "must not be zero"));
            }
            finite3(&key("velocity_m_s"), velocity_m_s, invalid)?;
            if let Some(t) = move_secs {
                non_negative(&key("move_secs"), *t, invalid)?;
            }
            non_negative(&key("friction"), *friction, invalid)
        }
    }
}
