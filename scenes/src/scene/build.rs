//! Building a validated scene: its mesh, the effects it lists bound to the mesh's nodes, and the
//! nodes a selector picks.

use hox_sim::Vec3;
use hox_sim::effect::{Clamp, ContactPlane, Damping, Effect, Gravity};
use hox_sim::mesh::Mesh;

use super::{EffectSpec, NodeSelector, Scene, SceneMesh};
use crate::error::SceneError;

impl Scene {
    /// Mean displacement of the nodes of every non-empty physical group of the mesh file, for
    /// `positions` (empty for a box scene), metres.
    pub fn group_displacements(&self, positions: &[Vec3]) -> std::collections::BTreeMap<String, [f64; 3]> {
        let Some(imported) = self.mesh.imported() else { return Default::default() };
        let rest = &imported.mesh.rest_positions;
        imported
            .node_sets
            .iter()
            .filter(|(_, nodes)| !nodes.is_empty())
            .map(|(name, nodes)| {
                let sum: Vec3 = nodes.iter().map(|&n| positions[n as usize] - rest[n as usize]).sum();
                let u = sum / nodes.len() as f64;
                (name.clone(), [u.x, u.y, u.z])
            })
            .collect()
    }

    /// Builds the mesh (a mesh file's was read when the scene was validated).
    pub fn build_mesh(&self) -> Result<Mesh, SceneError> {
        match &self.mesh {
            SceneMesh::Box(b) => {
                b.build().map_err(|e| SceneError::Mesh { source_name: self.source.clone(), message: e.to_string() })
            }
            SceneMesh::File { imported, .. } => Ok(imported.mesh.clone()),
        }
    }

    /// The nodes effect `k`'s selector picks in `mesh`; selecting none is an error.
    pub fn selected_nodes(&self, mesh: &Mesh, k: usize, sel: &NodeSelector) -> Result<Vec<u32>, SceneError> {
        let nodes = match (&sel.group, self.mesh.imported()) {
            (Some(name), Some(imported)) => imported
                .node_set(name)
                .map_err(|e| SceneError::Invalid {
                    source_name: self.source.clone(),
                    key: format!("effects[{k}].nodes.group"),
                    value: format!("{name:?}"),
                    reason: e.to_string(),
                })?
                .to_vec(),
            _ => select_nodes(mesh, sel),
        };
        if nodes.is_empty() {
            return Err(SceneError::Invalid {
                source_name: self.source.clone(),
                key: format!("effects[{k}].nodes"),
                value: format!("{sel:?}"),
                reason: "selects no node of the mesh".into(),
            });
        }
        Ok(nodes)
    }

    /// The effects the scene lists, bound to `mesh`'s nodes.
    pub fn build_effects(&self, mesh: &Mesh) -> Result<Vec<Box<dyn Effect>>, SceneError> {
        let mut effects: Vec<Box<dyn Effect>> = Vec::new();
        for (k, e) in self.file.effects.iter().enumerate() {
            let select = |sel: &NodeSelector| self.selected_nodes(mesh, k, sel);
            effects.push(match e {
                EffectSpec::Gravity { acceleration_m_s2 } => Box::new(Gravity::new(Vec3::from(*acceleration_m_s2))),
                EffectSpec::Clamp { nodes } => Box::new(Clamp { nodes: select(nodes)? }),
                EffectSpec::Prescribed { nodes, .. } => {
                    Box::new(e.prescribed(select(nodes)?).expect("a prescribed spec"))
                }
                EffectSpec::Damping { rate_per_sec } => Box::new(Damping { rate_per_sec: *rate_per_sec }),
                EffectSpec::Contact { point_m, normal, velocity_m_s, move_secs, friction } => {
                    Box::new(ContactPlane::new(
                        Vec3::from(*point_m),
                        Vec3::from(*normal),
                        Vec3::from(*velocity_m_s),
                        move_secs.unwrap_or(f64::INFINITY),
                        *friction,
                    ))
                }
            });
        }
        let damping = self.params().damping_per_sec;
        if damping > 0.0 {
            effects.push(Box::new(Damping { rate_per_sec: damping }));
        }
        Ok(effects)
    }
}

/// Nodes picked by a selector. Plane selection uses a tolerance of 1e-9 × the body's size.
pub fn select_nodes(mesh: &Mesh, sel: &NodeSelector) -> Vec<u32> {
    let (lo, hi) = mesh.bounding_box();
    let tol = 1e-9 * (hi - lo).norm().max(1e-300);
    if let (Some(plane), Some(at)) = (&sel.plane, sel.at_m) {
        let d = axis_index(plane).unwrap_or(0);
        return mesh.nodes_where(|p| (p[d] - at).abs() <= tol);
    }
    if let (Some(a), Some(b)) = (sel.box_min_m, sel.box_max_m) {
        return mesh.nodes_where(|p| (0..3).all(|d| p[d] >= a[d] - tol && p[d] <= b[d] + tol));
    }
    Vec::new()
}

pub(crate) fn axis_index(name: &str) -> Option<usize> {
    match name.to_ascii_lowercase().as_str() {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}
