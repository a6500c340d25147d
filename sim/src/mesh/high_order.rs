//! Raising the order of a linear mesh (P1 → P2/P3, Q1 → Q2, and so on for any registered
//! element of order > 1) with shared high-order nodes.
//!
//! Each node of the target element sits at reference point `r`; its position is mapped by the
//! linear element, `X = Σ_j N^lin_j(r) X_j`. A node is identified by the global vertices whose
//! linear weights `N^lin_j(r)` are non-zero together with those weights: an edge node by its
//! two end vertices and the fraction along the edge, a face node by the face's vertices, and so
//! on. Two elements that share an edge or face therefore produce the same key for the same
//! point whatever their local orientations, which makes the nodes shared and consistently
//! oriented by construction, with no coordinate matching.

use super::{ElementBlock, Mesh, MeshError};
use crate::Vec3;
use crate::element::ElementType;
use std::collections::HashMap;

/// The linear element on the same reference shape as `target` (p1 for tetrahedra, q1 for
/// hexahedra), or None if the target is already linear.
pub fn linear_counterpart(target: ElementType) -> Option<ElementType> {
    if target.order() == 1 {
        return None;
    }
    ElementType::linear(target.shape())
}

/// Converts every block of `mesh` whose linear type matches `target`'s shape to `target`.
pub fn raise_order(mesh: &Mesh, target: ElementType) -> Result<Mesh, MeshError> {
    let Some(linear) = linear_counterpart(target) else {
        return Ok(mesh.clone());
    };
    let mut positions = mesh.rest_positions.clone();
    let mut keys: HashMap<Vec<(u32, i64)>, u32> = HashMap::new();
    let mut blocks = Vec::with_capacity(mesh.blocks.len());
    // Linear weights of every target node.
    let weights: Vec<Vec<f64>> = target
        .nodes()
        .iter()
        .map(|r| {
            let mut w = vec![0.0; linear.num_nodes()];
            linear.shape_functions(r, &mut w);
            w
        })
        .collect();
    for b in &mesh.blocks {
        if b.element_type != linear {
            if b.element_type.shape() == target.shape() {
                return Err(MeshError::InvalidRequest(format!(
                    "cannot raise a {} block to {}",
                    b.element_type, target
                )));
            }
            blocks.push(b.clone());
            continue;
        }
        let mut conn = Vec::with_capacity(b.len() * target.num_nodes());
        for verts in b.elements() {
            for (k, w) in weights.iter().enumerate() {
                if k < linear.num_nodes() {
                    conn.push(verts[k]);
                    continue;
                }
                let mut key: Vec<(u32, i64)> = verts
                    .iter()
                    .zip(w)
                    .filter(|(_, w)| w.abs() > 1e-12)
                    .map(|(&v, &w)| (v, (w * 1e9).round() as i64))
                    .collect();
                key.sort_unstable();
                let id = *keys.entry(key).or_insert_with(|| {
                    let p: Vec3 = verts.iter().zip(w).map(|(&v, &w)| mesh.rest_positions[v as usize] * w).sum();
                    positions.push(p);
                    (positions.len() - 1) as u32
                });
                conn.push(id);
            }
        }
        blocks.push(ElementBlock::new(target, conn));
    }
    Ok(Mesh { rest_positions: positions, blocks })
}
