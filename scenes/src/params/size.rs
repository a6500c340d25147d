//! How large a box mesh may be: its elements and memory estimated before building it, the limits
//! ([`MAX_BOX_ELEMENTS`], [`MAX_BOX_BYTES`]) and the checks the grid and refinement entries make;
//! [`thousands`] writes the counts.

use hox_sim::mesh::structured::TetSplit;

use super::Params;
use super::applies::is_tetrahedral;

/// The largest mesh a box scene may ask for, elements: 24 times the paper's largest beam (P1
/// 81,920), whose run measured 63 MB of resident memory in all (about 25 MB above the binary's
/// own; [`box_bytes`] estimates 58 MB, an upper bound).
pub const MAX_BOX_ELEMENTS: u64 = 2_000_000;

/// The most memory a box scene may ask for by [`box_bytes`], bytes (a third of this machine's
/// 24 GiB): high-order elements reach it before the element limit.
pub const MAX_BOX_BYTES: u64 = 8_000_000_000;

/// Elements a box mesh of `p` would have (without building it).
pub fn box_elements(p: &Params) -> Option<u64> {
    let e = p.element;
    let cells: u64 = p.grid.iter().map(|&c| c as u64).product();
    let split = if is_tetrahedral(p) { p.split } else { TetSplit::default() };
    let per_cell = hox_sim::mesh::structured::elements_per_cell(e.shape(), split) as u64;
    let refine = u32::try_from(p.refine).ok().filter(|r| *r <= 20)?;
    Some(cells.saturating_mul(per_cell).saturating_mul(8u64.saturating_pow(refine)))
}

/// Rough memory a box mesh of `p` takes when simulated, bytes: per element its node indices and,
/// per quadrature point, the material gradients of its shape functions and the rest volume; per
/// node (about one per element for these meshes, more for high order) positions, velocities,
/// previous positions, rest positions, masses and the solver's scratch.
pub fn box_bytes(p: &Params) -> Option<u64> {
    let e = p.element;
    let nodes = e.num_nodes() as u64;
    let qp = hox_sim::fem::quadrature::rule(e.shape(), p.quadrature_degree.unwrap_or(e.default_quadrature_degree()))
        .map(|r| r.len() as u64)
        .unwrap_or(1);
    let per_element = nodes * 4 + qp * (nodes * 24 + 16) + nodes * 6 * 24;
    Some(box_elements(p)?.saturating_mul(per_element))
}

/// A box may ask for more elements or memory than a simulation can hold: refuse with the count
/// and the memory it would take.
pub(super) fn check_box_size(p: &Params) -> Result<(), String> {
    let (Some(elements), Some(bytes)) = (box_elements(p), box_bytes(p)) else { return Ok(()) };
    if elements <= MAX_BOX_ELEMENTS && bytes <= MAX_BOX_BYTES {
        return Ok(());
    }
    let [x, y, z] = p.grid;
    Err(format!(
        "{} {x}×{y}×{z}{} would be {} elements and take about {:.1} GB; at most {} elements and {:.0} GB",
        p.element.name().to_uppercase(),
        if p.refine > 0 { format!(" refined {} time(s)", p.refine) } else { String::new() },
        thousands(elements),
        bytes as f64 / 1e9,
        thousands(MAX_BOX_ELEMENTS),
        MAX_BOX_BYTES as f64 / 1e9
    ))
}

/// The size check, reported on the grid when nothing is refined ...
pub(super) fn check_grid_size(p: &Params) -> Result<(), String> {
    if p.refine == 0 { check_box_size(p) } else { Ok(()) }
}

/// ... and on the refinement otherwise (each multiplies the elements by 8).
pub(super) fn check_refine_size(p: &Params) -> Result<(), String> {
    if p.refine > 0 { check_box_size(p) } else { Ok(()) }
}

/// 5242880 → "5,242,880".
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (k, c) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}
