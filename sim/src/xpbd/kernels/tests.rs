use super::*;
use crate::Vec3;
use crate::fem::energy::element_grads;
use crate::fem::energy::tests::{elements, materials};
use crate::xpbd::constraint::project_energy_constraint;

/// The specialised sweep projects one element exactly as the generic kernel does, up to the
/// order of floating-point operations, for every element type and material (a node count
/// without one is declined, for the generic kernel); the colour-packed copy holds the same data.
#[test]
fn specialised_sweep_matches_the_generic_kernel() {
    for (et, mesh, geo) in elements() {
        let n = et.num_nodes();
        // a node count without a specialised sweep is optional speed: the sweep declines it and
        // the caller takes the generic kernel (every built-in element has one)
        let specialised = SPECIALISED_NODE_COUNTS.contains(&n);
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
            project_energy_constraint(
                &mut expected,
                &mesh.rest_positions,
                &w,
                element_grads(g, 0),
                g.volumes(0),
                &material,
                1e4,
                &mut lambda_expected,
            );

            let (serial, colour) =
                (PackedBlock::in_element_order(block, g), PackedBlock::in_colour_order(block, g, &[vec![0]]));
            for data in [serial.data(), colour.data()] {
                let mut x = deformed.clone();
                let mut lambdas = vec![0.0];
                // SAFETY: one thread, sizes from the mesh.
                let done = unsafe {
                    energy_sweep(
                        n,
                        &material,
                        Positions::new(&mut x),
                        &mesh.rest_positions,
                        &w,
                        &data,
                        0..1,
                        Multipliers::new(&mut lambdas),
                        1e4,
                    )
                };
                if !specialised {
                    assert_eq!(done, None, "{et}: no specialised sweep");
                    continue;
                }
                assert_eq!(done, Some(Ok(1)), "{et}");
                let scale = expected.iter().zip(&deformed).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                assert!(scale > 0.0, "{et} {:?}: nothing moved", material.model);
                let gap = x.iter().zip(&expected).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                assert!(gap <= 1e-12 * scale.max(1.0), "{et} {:?}: {gap:e}", material.model);
                assert!(
                    (lambdas[0] - lambda_expected).abs() <= 1e-12 * lambda_expected.abs(),
                    "{et} {:?}",
                    material.model
                );
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
        energy_sweep(
            et.num_nodes(),
            &material,
            Positions::new(&mut x),
            &mesh.rest_positions,
            &w,
            &PackedBlock::in_element_order(&mesh.blocks[0], &geo[0]).data(),
            0..1,
            Multipliers::new(&mut lambdas),
            1e4,
        )
    };
    assert!(matches!(done, Some(Err(NonFiniteElement { element: 0, .. }))), "{done:?}");
    assert_eq!(x.iter().map(|p| p.x).collect::<Vec<_>>(), before.iter().map(|p| p.x).collect::<Vec<_>>());
}

/// The 2 × 0.5 × 0.5 m P1 beam of 8 × 2 × 2 cells refined `refine` times, its geometry,
/// colouring and colour-packed block.
fn p1_beam(refine: usize) -> (crate::mesh::Mesh, Vec<crate::fem::geometry::BlockGeometry>, Vec<Vec<u32>>, PackedBlock) {
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    let mesh = BoxMeshSpec {
        grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [8, 2, 2] },
        element_type: crate::element::ElementType::from_name("p1").unwrap(),
        split: TetSplit::Five,
        refine,
    }
    .build()
    .unwrap();
    let geo = crate::fem::geometry::precompute(&mesh, None).unwrap();
    let colours = crate::xpbd::colouring::colour_elements(&mesh.blocks[0], mesh.num_nodes());
    let packed = PackedBlock::in_colour_order(&mesh.blocks[0], &geo[0], &colours);
    (mesh, geo, colours, packed)
}

/// The colour sweep of a P1 beam over the colour-packed data projects exactly what the generic
/// kernel does element after element in the same order, up to round-off.
#[test]
fn p1_colour_sweep_matches_the_generic_kernel() {
    let (mesh, geo, colours, packed) = p1_beam(0);
    let block = &mesh.blocks[0];
    let material = materials()[0];
    let deformed: Vec<Vec3> = mesh
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| p + 0.02 * Vec3::new((i as f64).sin(), (i as f64 * 0.3).cos(), (i as f64 * 1.7).sin()))
        .collect();
    let w: Vec<f64> = mesh.rest_positions.iter().map(|p| if p.x < 1e-12 { 0.0 } else { 1.0 }).collect();
    let inv_dt2 = 9e6;

    let mut expected = deformed.clone();
    let mut lambdas_expected = vec![0.0; block.len()];
    for &e in colours.iter().flatten() {
        let e = e as usize;
        let nodes = block.element(e);
        if nodes.iter().all(|&n| w[n as usize] == 0.0) {
            continue;
        }
        let mut x: Vec<Vec3> = nodes.iter().map(|&n| expected[n as usize]).collect();
        let rest: Vec<Vec3> = nodes.iter().map(|&n| mesh.rest_positions[n as usize]).collect();
        let we: Vec<f64> = nodes.iter().map(|&n| w[n as usize]).collect();
        project_energy_constraint(
            &mut x,
            &rest,
            &we,
            element_grads(&geo[0], e),
            geo[0].volumes(e),
            &material,
            inv_dt2,
            &mut lambdas_expected[e],
        );
        for (xi, &n) in x.iter().zip(nodes) {
            expected[n as usize] = *xi;
        }
    }

    let mut x = deformed.clone();
    let mut lambdas = vec![0.0; block.len()];
    let mut done = 0;
    for c in 0..packed.num_colours() {
        // SAFETY: one thread, sizes from the mesh.
        let r = unsafe {
            energy_sweep(
                4,
                &material,
                Positions::new(&mut x),
                &mesh.rest_positions,
                &w,
                &packed.data(),
                packed.colour(c),
                Multipliers::new(&mut lambdas),
                inv_dt2,
            )
        };
        done += r.unwrap().unwrap();
    }
    assert!(done > 0);
    let scale = expected.iter().zip(&deformed).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    let gap = x.iter().zip(&expected).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
    assert!(scale > 0.0 && gap <= 1e-12 * scale.max(1.0), "{gap:e} against {scale:e}");
    for (a, b) in lambdas.iter().zip(&lambdas_expected) {
        assert!((a - b).abs() <= 1e-10 * b.abs().max(1e-12), "{a} {b}");
    }
}

/// The P1 sweeps form `F = D_s D_m⁻¹` from the positions alone (not `I + (D_s − D_m) D_m⁻¹`): a
/// beam at rest, batched and scalar, every material, stays at rest to round-off, and a beam
/// moved rigidly (translated and rotated) keeps its shape: no energy is made from nothing.
#[test]
fn a_p1_body_at_rest_or_moved_rigidly_stays_undeformed_without_the_rest_positions_in_f() {
    let (mesh, _, _, packed) = p1_beam(1);
    let rest = &mesh.rest_positions;
    let w: Vec<f64> = rest.iter().map(|p| if p.x < 1e-12 { 0.0 } else { 1.0 }).collect();
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    let rigid: Vec<Vec3> =
        rest.iter().map(|p| Vec3::new(c * p.x - s * p.y + 3.0, s * p.x + c * p.y - 1.0, p.z + 7.0)).collect();
    for material in materials() {
        for batched in [false, true] {
            for start in [rest.clone(), rigid.clone()] {
                let mut x = start.clone();
                let mut lambdas = vec![0.0; mesh.blocks[0].len()];
                sweep_colours_of(4, &material, &packed, rest, &w, &mut x, &mut lambdas, batched).unwrap();
                let moved = x.iter().zip(&start).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                assert!(moved <= 1e-12, "{:?}, batched {batched}: moved {moved:e} m", material.model);
                assert!(lambdas.iter().all(|l| l.abs() <= 1e-9), "{:?}, batched {batched}", material.model);
            }
        }
    }
}

/// Every colour of `packed` (`n` nodes per element) through [`colour_sweep`] with `material`,
/// batched or not; the first error stops.
#[allow(clippy::too_many_arguments)]
fn sweep_colours_of(
    n: usize,
    material: &crate::material::Material,
    packed: &PackedBlock,
    rest: &[Vec3],
    w: &[f64],
    x: &mut [Vec3],
    lambdas: &mut [f64],
    batched: bool,
) -> Result<u64, NonFiniteElement> {
    let mut done = 0;
    for c in 0..packed.num_colours() {
        // SAFETY: one thread, sizes from the mesh.
        done += unsafe {
            colour_sweep(
                n,
                material,
                Positions::new(x),
                rest,
                w,
                packed,
                c,
                packed.colour(c),
                Multipliers::new(lambdas),
                9e6,
                batched,
            )
        }
        .unwrap()?;
    }
    Ok(done)
}

/// The sweep's StVK ([`Stvk`], nalgebra's column-major form, kept for speed) is the material's
/// one StVK point law ([`crate::material::stvk::energy_and_pk1`]) bit for bit, with and without
/// fused multiply–adds, so the two cannot drift apart.
#[test]
fn the_sweeps_stvk_is_the_materials_point_law_bit_for_bit() {
    use crate::material::Mat3;
    use crate::material::stvk::energy_and_pk1;
    use crate::math::lane::{Scalar, from_mat3, to_mat3};
    let law = Stvk { mu_pa: 1.1e6, lambda_pa: 2.3e6 };
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
    };
    for _ in 0..2000 {
        let f = Mat3::from_fn(|r, c| if r == c { 1.0 } else { 0.0 } + next());
        let (psi, p) = law.energy_and_pk1::<false>(&f);
        let (psi_l, p_l) = energy_and_pk1::<Scalar<false>>(Scalar(law.mu_pa), Scalar(law.lambda_pa), &from_mat3(&f));
        assert_eq!((psi.to_bits(), p.map(f64::to_bits)), (psi_l.0.to_bits(), to_mat3(&p_l).map(f64::to_bits)));
        let (psi, p) = law.energy_and_pk1::<true>(&f);
        let (psi_l, p_l) = energy_and_pk1::<Scalar<true>>(Scalar(law.mu_pa), Scalar(law.lambda_pa), &from_mat3(&f));
        assert_eq!((psi.to_bits(), p.map(f64::to_bits)), (psi_l.0.to_bits(), to_mat3(&p_l).map(f64::to_bits)));
    }
}

/// Four same-colour elements per register (AVX2) and eight (AVX-512, where the CPU has it), for
/// every element type (the linear tetrahedron also at a raised quadrature degree, through the
/// generic batch) and every material, on curved elements (every rest node moved by a smooth
/// map): the one-at-a-time colour sweep's positions and multipliers up to round-off, the same
/// pinned elements skipped, and the same element and node named when a correction comes out
/// non-finite (in the register's second-to-last lane), with the same nodes scattered before it.
#[cfg(target_arch = "x86_64")]
#[test]
fn batches_of_four_and_eight_match_the_scalar_colour_sweep_for_every_element_type_and_material() {
    let widths: Vec<usize> = [4, 8].into_iter().filter(|&l| lanes_available(l)).collect();
    if !widths.contains(&8) {
        eprintln!("this CPU has no AVX-512 F: the eight-lane batches are not run here");
    }
    for lanes in widths {
        batches_match_the_scalar_colour_sweep(lanes);
    }
}

#[cfg(target_arch = "x86_64")]
fn batches_match_the_scalar_colour_sweep(lanes: usize) {
    use crate::mesh::structured::{BoxGrid, BoxMeshSpec, TetSplit};
    let cases = [
        ("p1", Some(2)),
        ("p1", None),
        ("p2", None),
        ("p3", None),
        ("q1", None),
        ("q2", None),
        ("prism", None),
        ("pyramid", None),
    ];
    let mut partial_cases = 0;
    for (name, degree) in cases {
        let mut mesh = BoxMeshSpec {
            grid: BoxGrid { min_m: Vec3::zeros(), max_m: Vec3::new(2.0, 0.5, 0.5), cells: [8, 4, 4] },
            element_type: crate::element::ElementType::from_name(name).unwrap(),
            split: TetSplit::Five,
            refine: 0,
        }
        .build()
        .unwrap();
        for p in &mut mesh.rest_positions {
            *p += 0.04 * Vec3::new((3.0 * p.y + p.z).sin(), (2.0 * p.x).sin(), (2.5 * p.x + p.y).cos());
        }
        let geo = crate::fem::geometry::precompute(&mesh, degree).unwrap();
        let block = &mesh.blocks[0];
        let n = block.nodes_per_element();
        let colours = crate::xpbd::colouring::colour_elements(block, mesh.num_nodes());
        let packed = PackedBlock::in_colour_order_with_lanes(block, &geo[0], &colours, lanes);
        let what = format!("{name} (quadrature degree {degree:?}, {lanes} lanes)");
        assert!(packed.colour_batches.last().copied().unwrap_or(0) > 0, "{what}: some elements in batches");
        let deformed: Vec<Vec3> = mesh
            .rest_positions
            .iter()
            .enumerate()
            .map(|(i, p)| p + 0.03 * Vec3::new((i as f64).sin(), (i as f64 * 0.3).cos(), (i as f64 * 1.7).sin()))
            .collect();
        let w: Vec<f64> = mesh
            .rest_positions
            .iter()
            .enumerate()
            .map(|(i, p)| if p.x < 0.3 { 0.0 } else { 1.0 + 0.01 * (i % 7) as f64 })
            .collect();
        let elements = block.len();
        for material in materials() {
            let what = format!("{what} {:?}", material.model);
            let run = |batched: bool, x: &mut Vec<Vec3>, lambdas: &mut Vec<f64>| {
                let mut done = 0;
                for _ in 0..3 {
                    lambdas.fill(0.0);
                    done +=
                        sweep_colours_of(n, &material, &packed, &mesh.rest_positions, &w, x, lambdas, batched).unwrap();
                }
                done
            };
            let (mut x1, mut l1) = (deformed.clone(), vec![0.0; elements]);
            let (mut x4, mut l4) = (deformed.clone(), vec![0.0; elements]);
            let (done1, done4) = (run(false, &mut x1, &mut l1), run(true, &mut x4, &mut l4));
            assert_eq!(done1, done4, "{what}");
            let scale = x1.iter().zip(&deformed).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            let gap = x1.iter().zip(&x4).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            assert!(scale > 1e-4 && gap <= 1e-11 * scale, "{what}: {gap:e} against {scale:e}");
            for (a, b) in l1.iter().zip(&l4) {
                assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-12), "{what}: {a} {b}");
            }
            for (i, (a, b)) in x4.iter().zip(&deformed).enumerate() {
                if w[i] == 0.0 {
                    assert_eq!(a, b, "{what}: a pinned node stays");
                }
            }
        }
        // a non-finite node first met (in sweep order) in the second-to-last lane of a full
        // batch, then in the last element of a colour's partial batch (its other lanes padding)
        let mut first_seen = vec![usize::MAX; mesh.num_nodes()];
        for (k, element) in packed.nodes.chunks_exact(n).enumerate() {
            for &nd in element {
                first_seen[nd as usize] = first_seen[nd as usize].min(k);
            }
        }
        let batched_end = |c: usize| packed.colour(c).start + lanes * (packed.colour(c).len() / lanes);
        let first_met = |k: usize| {
            let node = packed.nodes[n * k + n - 1] as usize;
            first_seen[node] == k && w[node] > 0.0
        };
        let in_full = (0..packed.num_colours())
            .flat_map(|c| (packed.colour(c).start..batched_end(c)).map(move |k| (c, k)))
            .find(|&(c, k)| (k - packed.colour(c).start) % lanes == lanes - 2 && first_met(k))
            .map(|(_, k)| k)
            .expect("a node first met in the second-to-last lane");
        let in_partial = (0..packed.num_colours())
            .filter(|&c| batched_end(c) < packed.colour(c).end)
            .map(|c| packed.colour(c).end - 1)
            .find(|&k| first_met(k));
        partial_cases += usize::from(in_partial.is_some());
        for k in std::iter::once(in_full).chain(in_partial) {
            nan_at(name, n, &packed, &mesh.rest_positions, &w, &deformed, k);
        }
    }
    assert!(partial_cases > 0, "{lanes} lanes: a NaN in a partial batch was tried");
}

/// A NaN put on the last node of packed element `k`: the batched and one-at-a-time colour
/// sweeps name the same element and node and scatter the same positions before it.
#[cfg(target_arch = "x86_64")]
fn nan_at(name: &str, n: usize, packed: &PackedBlock, rest: &[Vec3], w: &[f64], deformed: &[Vec3], k: usize) {
    let elements = packed.len();
    {
        let bad_node = packed.nodes[n * k + n - 1];
        let material = materials()[0];
        let (mut x1, mut l1) = (deformed.to_vec(), vec![0.0; elements]);
        let (mut x4, mut l4) = (deformed.to_vec(), vec![0.0; elements]);
        x1[bad_node as usize].y = f64::NAN;
        x4[bad_node as usize].y = f64::NAN;
        let r1 = sweep_colours_of(n, &material, packed, rest, w, &mut x1, &mut l1, false);
        let r4 = sweep_colours_of(n, &material, packed, rest, w, &mut x4, &mut l4, true);
        let bad = r1.unwrap_err();
        assert_eq!(bad, r4.unwrap_err(), "{name}");
        assert_eq!(bad.node, bad_node, "{name}");
        assert_eq!(bad.element, packed.element_ids.as_ref().unwrap()[k] as usize, "{name}");
        for (a, b) in x1.iter().zip(&x4) {
            assert!((a - b).norm() <= 1e-12 || a.y.is_nan() && b.y.is_nan(), "{name}: {a} {b}");
        }
    }
}

/// The register width follows the colours: long colours take eight lanes where the CPU has
/// AVX-512 (four where it has not), short ones keep four, where half-empty batches of eight
/// cost more than they save.
#[test]
fn long_colours_take_eight_lanes_and_short_ones_keep_four() {
    let long: Vec<Vec<u32>> = (0..10).map(|c| (0..64).map(|e| 64 * c + e).collect()).collect();
    let short: Vec<Vec<u32>> = (0..20).map(|c| (0..4).map(|e| 4 * c + e).collect()).collect();
    let ragged: Vec<Vec<u32>> = (0..20).map(|c| (0..5).map(|e| 5 * c + e).collect()).collect();
    let eight = widest_available() == Some(8);
    assert_eq!(auto_lanes(&long), if eight { 8 } else { 4 });
    assert_eq!(auto_lanes(&short), 4, "one half-empty batch of eight per colour");
    // 5 per colour: 2 batches of four against 1 of eight; 4: 1 against 1
    assert_eq!(auto_lanes(&ragged), if eight { 8 } else { 4 });
    assert_eq!(auto_lanes(&[]), 4);
}
