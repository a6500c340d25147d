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

/// P1's node patches under the mixed formulation ([`super::patch`]): a node's patch gradient is
/// the patch energy's gradient at that node, its local energy changes as the whole energy does
/// when the node moves, and the means carried along node moves are those of the moved positions.
#[test]
fn a_node_s_patch_share_is_the_patch_energy_s_and_its_means_follow_the_node() {
    use super::patch::Patches;
    use crate::fem::energy::mixed::patch::energy_and_gradient;
    use crate::material::VolumeMeasure;
    let mesh = super::super::tests::beam(ElementType::from_name("p1").unwrap(), [3, 2, 2]);
    let geometry = precompute(&mesh, None).unwrap();
    let incidence = NodeIncidence::new(&mesh);
    let material = Material::new(crate::material::MaterialModel::NeoHookean, 1.0e5, 0.49, 1000.0)
        .unwrap()
        .with_volume_measure(VolumeMeasure::Element)
        .unwrap();
    let mut x: Vec<Vec3> = mesh
        .rest_positions
        .iter()
        .enumerate()
        .map(|(i, p)| p + Vec3::new(0.01 * (i % 5) as f64, 0.007 * (i % 3) as f64, -0.012 * (i % 4) as f64))
        .collect();
    let fused = Fused::detect();
    let mut lanes = PointLanes::new(&mesh, &geometry);
    lanes.refresh(&mesh, &x, fused);
    let mut patches = Patches::new(&mesh, &geometry, &material, &incidence).expect("P1 mixed has patches");
    patches.refresh(&mesh, &material, &LaneView::of(&mut lanes, &material));
    {
        let means = crate::fem::energy::mixed::patch::NodeMeans::new(&mesh, &geometry, &material, &x);
        for a in 0..mesh.num_nodes() {
            let (c, f) = patches.mean(a);
            assert!((c - means.c_bar[a]).abs() < 1e-12 && (f - means.f_bar[a]).norm() < 1e-12, "node {a}: refreshed");
        }
    }
    let mut moved_any = false;
    for (k, i) in (0..mesh.num_nodes()).step_by(4).enumerate() {
        let mut gradient = vec![Vec3::zeros(); x.len()];
        let before = energy_and_gradient(&mesh, &geometry, &material, &x, Some(&mut gradient));
        let view_lanes = LaneView::of(&mut lanes, &material);
        let (view, _) = patches.view();
        // SAFETY: one thread
        let (share, block) = unsafe { view.node_share(&material, i, &view_lanes) };
        let scale = gradient[i].norm().max(1e-3);

        assert!((share - gradient[i]).norm() <= 1e-9 * scale, "node {i}: share {share} vs gradient {}", gradient[i]);
        assert!(block.symmetric_eigenvalues().min() >= -1e-9 * block.norm(), "node {i}: block {block}");
        // SAFETY: one thread
        let local_before = unsafe { view.local_energy(&material, i, &view_lanes) };
        let d = Vec3::new(0.004 * (k % 3) as f64, -0.003, 0.002 * (k % 2) as f64);
        x[i] += d;
        // SAFETY: one thread
        unsafe {
            carry_on_this_cpu(fused, &incidence, i, d, &view_lanes);
            view.carry(&material, i, &d, &view_lanes);
        }
        // SAFETY: one thread
        let local_after = unsafe { view.local_energy(&material, i, &view_lanes) };
        let after = energy_and_gradient(&mesh, &geometry, &material, &x, None);
        let (whole, local) = (after - before, local_after - local_before);
        assert!((whole - local).abs() <= 1e-9 * whole.abs().max(1e-6), "node {i}: ΔU {whole} vs local {local}");
        moved_any |= whole.abs() > 1e-6;
    }
    assert!(moved_any, "no move changed the energy");
    // the carried means are the means of the moved positions
    let means = crate::fem::energy::mixed::patch::NodeMeans::new(&mesh, &geometry, &material, &x);
    let mut fresh = Patches::new(&mesh, &geometry, &material, &incidence).unwrap();
    lanes.refresh(&mesh, &x, fused);
    fresh.refresh(&mesh, &material, &LaneView::of(&mut lanes, &material));
    for (a, (&c, f)) in means.c_bar.iter().zip(&means.f_bar).enumerate() {
        let (c_fresh, f_fresh) = fresh.mean(a);
        let (c_kept, f_kept) = patches.mean(a);
        assert!((c_fresh - c).abs() < 1e-12 && (f_fresh - f).norm() < 1e-12, "node {a}: refresh vs NodeMeans");
        assert!((c_kept - c).abs() < 1e-12 && (f_kept - f).norm() < 1e-12, "node {a}: carried vs NodeMeans");
    }
}

/// Nodes of one colour of [`super::patch::colour_two_apart`] share no patch: no node lies in an
/// element with each of two nodes of one colour.
#[test]
fn nodes_coloured_two_apart_share_no_patch() {
    let mesh = super::super::tests::beam(ElementType::from_name("p1").unwrap(), [4, 2, 2]);
    let incidence = NodeIncidence::new(&mesh);
    let colours = super::patch::colour_two_apart(&mesh, &incidence);
    let mut colour_of = vec![usize::MAX; mesh.num_nodes()];
    for (c, nodes) in colours.iter().enumerate() {
        for &n in nodes {
            assert_eq!(colour_of[n as usize], usize::MAX, "node {n} coloured twice");
            colour_of[n as usize] = c;
        }
    }
    assert!(colour_of.iter().all(|&c| c != usize::MAX), "a node without a colour");
    for a in 0..mesh.num_nodes() {
        let mut patch: Vec<u32> = incidence
            .of(a)
            .iter()
            .flat_map(|inc| mesh.blocks[inc.block as usize].element(inc.element as usize).iter().copied())
            .collect();
        patch.sort_unstable();
        patch.dedup();
        let mut seen = std::collections::HashMap::new();
        for &n in &patch {
            if let Some(other) = seen.insert(colour_of[n as usize], n) {
                panic!("nodes {other} and {n} share colour {} and node {a}'s patch", colour_of[n as usize]);
            }
        }
    }
}
