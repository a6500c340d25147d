//! `hox mesh`: build a scene's mesh and print its element and node counts and volume.

use super::{SceneArgs, load_scene};
use crate::config::{MeshArgs, overrides};
use anyhow::{Context, Result};

pub fn mesh_command(scene: &SceneArgs, mesh: &MeshArgs, json: bool) -> Result<()> {
    let scene = load_scene(scene)?.with_overrides(&overrides(mesh, None))?;
    let m = scene.build_mesh()?;
    let geometry = hox_sim::fem::geometry::precompute(&m, scene.settings().quadrature_degree)
        .with_context(|| format!("{}: the mesh has a bad element", scene.source))?;
    let mut out = serde_json::json!({
        "element": scene.mesh.element_names(),
        "elements": m.num_elements(),
        "nodes": m.num_nodes(),
        "volume_m3": hox_sim::fem::geometry::total_volume_m3(&geometry),
    });
    if let Some(imported) = scene.mesh.imported() {
        out["blocks"] = m
            .blocks
            .iter()
            .map(|b| serde_json::json!({"element": b.element_type.name(), "elements": b.len()}))
            .collect();
        out["groups"] = imported.node_sets.iter().map(|(name, nodes)| (name.clone(), serde_json::json!({"nodes": nodes.len(), "elements": imported.element_sets.get(name).map_or(0, Vec::len)}))).collect();
    }
    if json {
        println!("{out}");
    } else {
        println!(
            "{}: {} {} elements, {} nodes, volume {:.6} m³",
            scene.name(),
            out["elements"],
            out["element"].as_str().unwrap_or_default(),
            out["nodes"],
            out["volume_m3"].as_f64().unwrap_or_default()
        );
        if let Some(imported) = scene.mesh.imported() {
            println!("  physical groups: {}", imported.group_names());
        }
    }
    Ok(())
}
