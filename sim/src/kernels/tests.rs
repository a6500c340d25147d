use super::*;
use crate::constraint::project_energy_constraint;
use crate::energy::element_grads;
use crate::energy::tests::{elements, materials};

/// The specialised sweep projects one element exactly as the generic kernel does, up to the
/// order of floating-point operations, for every element type and material; the colour-packed
/// copy holds the same data.
#[test]
fn specialised_sweep_matches_the_generic_kernel() {
    for (et, mesh, geo) in elements() {
        let n = et.num_nodes();
        assert!(SPECIALISED_NODE_COUNTS.contains(&n), "{et}");
        let g = &geo[0];
        let block = &mesh.blocks[0];
        let deformed: Vec<Vec3> = mesh
            .rest_positions
            .iter()
            .enumerate()
            .map(|(i, p)| p + 0.05 * Vec3::new((i as f64 * 0.7).sin(), (i as f64 * 1.3).cos(), (i as f64 * 0.4).sin()))
            .collect();
        let w: Vec<f64> = (0..mesh.num_nodes()).map(|i| if i == 0 { 0.0 } else { 1.0 + 0.1 * i as f64 }).collect();
        for material in materials() {
            let mut expected = deformed.clone();
            let mut lambda_expected = 0.0;
            project_energy_constraint(&mut expected, &mesh.rest_positions, &w, element_grads(g, 0), g.volumes(0), &material, 1e4, &mut lambda_expected);

            let (serial, colour) = (PackedBlock::in_element_order(block, g), PackedBlock::in_colour_order(block, g, &[vec![0]]));
            for data in [serial.data(), colour.data()] {
                let mut x = deformed.clone();
                let mut lambdas = vec![0.0];
                // SAFETY: one thread, sizes from the mesh.
                let done = unsafe {
                    energy_sweep(n, &material, Positions::new(&mut x), &mesh.rest_positions, &w, &data, 0..1, Multipliers::new(&mut lambdas), 1e4)
                };
                assert_eq!(done, Some(Ok(1)), "{et}");
                let scale = expected.iter().zip(&deformed).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                assert!(scale > 0.0, "{et} {:?}: nothing moved", material.model);
                let gap = x.iter().zip(&expected).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                assert!(gap <= 1e-12 * scale.max(1.0), "{et} {:?}: {gap:e}", material.model);
                assert!((lambdas[0] - lambda_expected).abs() <= 1e-12 * lambda_expected.abs(), "{et} {:?}", material.model);
                assert_eq!(x[0], deformed[0], "a pinned node stays");
            }
        }
    }
}

#[test]
fn a_non_finite_correction_is_reported_and_not_scattered() {
    let (et, mesh, geo) = elements().remove(0);
    let mut x = mesh.rest_positions.clone();
    x[1].y = f64::INFINITY;
    let before = x.clone();
    let w = vec![1.0; mesh.num_nodes()];
    let mut lambdas = vec![0.0];
    let material = materials()[0];
    // SAFETY: one thread, sizes from the mesh.
    let done = unsafe {
        energy_sweep(et.num_nodes(), &material, Positions::new(&mut x), &mesh.rest_positions, &w, &PackedBlock::in_element_order(&mesh.blocks[0], &geo[0]).data(), 0..1, Multipliers::new(&mut lambdas), 1e4)
    };
    assert!(matches!(done, Some(Err(NonFiniteElement { element: 0, .. }))), "{done:?}");
    assert_eq!(x.iter().map(|p| p.x).collect::<Vec<_>>(), before.iter().map(|p| p.x).collect::<Vec<_>>());
}
