use super::lanes::LaneView;
use super::node::{carry_points, solve_spd3};
use super::*;
use crate::element::ElementType;
use crate::fem::geometry::{deformation_gradient, precompute};

/// [`carry_points`] on the fused path where `fused` says the CPU has it.
///
/// # Safety
/// [`carry_points`]'s; `fused` from [`Fused::detect`].
use crate::fem::energy::element_grads;
use crate::material::Material;
use nalgebra::Matrix3;
unsafe fn carry_on_this_cpu(fused: Fused, incidence: &NodeIncidence, i: usize, d: Vec3, lanes: &[LaneView<'_>]) {
    #[cfg(target_arch = "x86_64")]
    if fused.0 {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn carry_fused(incidence: &NodeIncidence, i: usize, d: Vec3, lanes: &[LaneView<'_>]) {
            // SAFETY: the caller's promise
            unsafe { carry_points::<true>(incidence, i, d, lanes) }
        }
        // SAFETY: the caller's promise
        return unsafe { carry_fused(incidence, i, d, lanes) };
    }
    // SAFETY: the caller's promise
    unsafe { carry_points::<false>(incidence, i, d, lanes) }
}

/// `H⁻¹ f` of the hand-written 3 × 3 Cholesky is nalgebra's on random SPD matrices, and not
/// positive definite (a zero or negative pivot) or non-finite input gives `None`.
#[test]
fn solve_spd3_matches_a_cholesky_solve_and_refuses_what_is_not_positive_definite() {
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for _ in 0..200 {
        let a = Matrix3::from_fn(|_, _| next());
        let h = a * a.transpose() + Matrix3::identity() * 0.01;
        let f = Vec3::new(next(), next(), next());
        let want = h.cholesky().unwrap().solve(&f);
        let got = solve_spd3(&h, &f).unwrap();
        assert!((got - want).norm() <= 1e-10 * want.norm(), "{got} vs {want}");
    }
    let f = Vec3::new(1.0, 2.0, 3.0);
    for bad in [
        Matrix3::from_diagonal(&Vec3::new(1.0, 0.0, 1.0)),
        Matrix3::from_diagonal(&Vec3::new(1.0, 1.0, -2.0)),
        Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        Matrix3::from_diagonal(&Vec3::new(f64::NAN, 1.0, 1.0)),
    ] {
        assert_eq!(solve_spd3(&bad, &f), None, "{bad}");
    }
}

/// The cached `F_q` carried along node moves are the `F_q` recomputed from the moved
/// positions (to rounding), on every element type, a mixed mesh's shared nodes included.
#[test]
fn carried_point_gradients_match_recomputed_ones_for_every_element_type() {
    for et in ElementType::all() {
        let mesh = super::super::tests::one_cell_cantilever(et);
        let geometry = precompute(&mesh, None).unwrap();
        let incidence = NodeIncidence::new(&mesh);
        // from a deformed start, refreshed and carried on this CPU's path (fused where it
        // has AVX2 and FMA), against a plain refresh of the end positions
        let mut x: Vec<Vec3> = mesh
            .rest_positions
            .iter()
            .enumerate()
            .map(|(i, p)| p + Vec3::new(0.003 * (i % 5) as f64, 0.002 * (i % 3) as f64, -0.004 * (i % 2) as f64))
            .collect();
        let fused = Fused::detect();
        let material = Material::new(crate::material::MaterialModel::StVenantKirchhoff, 1.0e5, 0.3, 1000.0).unwrap();
        let mut cached = PointLanes::new(&mesh, &geometry);
        cached.refresh(&mesh, &x, fused);
        for (k, i) in (0..mesh.num_nodes()).step_by(3).enumerate() {
            let d = Vec3::new(0.01 * k as f64, -0.02, 0.015 * (k % 4) as f64);
            x[i] += d;
            let lanes = LaneView::of(&mut cached, &material);
            // SAFETY: one thread; the fused path only where the CPU has AVX2 and FMA
            unsafe { carry_on_this_cpu(fused, &incidence, i, d, &lanes) };
        }
        let mut fresh = PointLanes::new(&mesh, &geometry);
        fresh.refresh(&mesh, &x, Fused(false));
        // and both are the F_q of the element's own gather (lane-major, padding F = I)
        let mut moved = false;
        for ((lanes, block), g) in fresh.blocks.iter().zip(&mesh.blocks).zip(&geometry) {
            let (n, points) = (g.nodes_per_element, g.points_per_element);
            for e in 0..block.len() {
                let nodes = block.element(e);
                let (xe, re): (Vec<_>, Vec<_>) =
                    nodes.iter().map(|&i| (x[i as usize], mesh.rest_positions[i as usize])).unzip();
                let grads = element_grads(g, e);
                let len = 9 * lanes.chunks * lanes.width;
                let f_e = &lanes.f[e * len..][..len];
                for p in 0..lanes.chunks * lanes.width {
                    let (k, j) = (p / lanes.width, p % lanes.width);
                    let expected = if p < points {
                        deformation_gradient(&xe, &re, &grads[p * n..(p + 1) * n])
                    } else {
                        Matrix3::identity()
                    };
                    moved |= (expected - Matrix3::identity()).norm() > 1e-3;
                    let got = Matrix3::from_fn(|r, c| f_e[(9 * k + 3 * r + c) * lanes.width + j]);
                    assert!((got - expected).norm() < 1e-12, "{et}: lane-major {got} vs gathered {expected}");
                }
            }
        }
        for (a, b) in cached.blocks.iter().zip(&fresh.blocks) {
            for (u, v) in a.f.iter().zip(&b.f) {
                assert!((u - v).abs() < 1e-12, "{et}: carried {u} vs recomputed {v}");
            }
        }
        assert!(moved, "{et}: no F_q moved");
    }
}
