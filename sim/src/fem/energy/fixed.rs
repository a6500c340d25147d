//! The element energy and gradient of [`super`] with the node count a compile-time constant:
//! for each element `F_q = I + Σ_i u_i ⊗ ∇_X N_i(r_q)` (`u_i = x_i − X_i`),
//! `U_e = Σ_q V_q ψ(F_q)` and `∇_i U_e = Σ_q V_q P(F_q) ∇_X N_i(r_q)`, with the per-node loops over
//! structure-of-arrays rows padded to [`LANES`] (one AVX2 register with fused multiply–adds where
//! the CPU has them, [`crate::math::soa`]) and the material law a [`PointMaterial`] (StVK's Lamé
//! parameters computed once per pass instead of once per point). [`point_energy_and_gradient`]
//! is the one place this sum is written for fixed node counts: XPBD's specialised sweep
//! (`crate::xpbd::kernels`) projects with it, and the mesh passes of [`super`]
//! ([`super::total_energy_and_gradient`], [`super::total_energy`]) — what Newton, the static
//! solver and the residuals evaluate — run it element by element. Results equal the generic
//! kernel's ([`super::element_energy_and_gradient`]) up to the order of floating-point
//! operations (tested for every element type and material).

use crate::Vec3;
use crate::fem::geometry::BlockGeometry;
use crate::material::point_law::{AnyMaterial, PointMaterial, Stvk};
use crate::material::{FastLaw, Mat3, Material};
use crate::math::soa::{LANES, axpy_lanes, fma_lanes};
use crate::mesh::ElementBlock;

/// One quadrature point's `V ψ(F)`, `F = I + Σ_i u_i ⊗ g_i` summed in [`LANES`] partial sums
/// (`u[a][i]`, `g[b][i]`: rows padded with zeros from the element's node count to `P`), and with
/// `GRAD` `grad[a][i] += (V P(F) g_i)_a`.
#[inline(always)]
pub fn point_energy_and_gradient<const P: usize, const FMA: bool, const GRAD: bool, M: PointMaterial>(
    u: &[[f64; P]; 3],
    g: [&[f64; P]; 3],
    v: f64,
    material: &M,
    grad: &mut [[f64; P]; 3],
) -> f64 {
    // F_ab = δ_ab + Σ_i u_ai g_bi, summed in LANES partial sums (one vector register)
    let mut acc = [[[0.0; LANES]; 3]; 3];
    for c in 0..P / LANES {
        for a in 0..3 {
            for b in 0..3 {
                let r = c * LANES..(c + 1) * LANES;
                fma_lanes::<FMA>(&mut acc[a][b], &u[a][r.clone()], &g[b][r]);
            }
        }
    }
    let mut f = Mat3::identity();
    for a in 0..3 {
        for b in 0..3 {
            let s = &acc[a][b];
            f[(a, b)] += (s[0] + s[1]) + (s[2] + s[3]);
        }
    }
    let (psi, p) = material.energy_and_pk1::<FMA>(&f);
    if GRAD {
        let vp = p * v;
        for a in 0..3 {
            let (p0, p1, p2) = (vp[(a, 0)], vp[(a, 1)], vp[(a, 2)]);
            for c in 0..P / LANES {
                let r = c * LANES..(c + 1) * LANES;
                let out: &mut [f64; LANES] = (&mut grad[a][r.clone()]).try_into().expect("LANES");
                for (pb, gb) in [p0, p1, p2].into_iter().zip(g) {
                    axpy_lanes::<FMA>(out, pb, &gb[r.clone()]);
                }
            }
        }
    }
    v * psi
}

/// One block's mesh pass: its elements, their geometry, the rest positions and the positions.
#[derive(Clone)]
pub(super) struct Pass<'a> {
    pub block: &'a ElementBlock,
    pub geometry: &'a BlockGeometry,
    pub rest: &'a [Vec3],
    pub x: &'a [Vec3],
    /// The block's elements this pass visits.
    pub elements: std::ops::Range<usize>,
}

/// `Σ_e U_e` over the pass's block, and with `GRAD` each element's `∇_i U_e` added to
/// `grad_out` in element order; the material gradients read from the geometry's node-major
/// layout into one point's rows at a time (not kept packed: the static solver's 100k-unknown P3
/// would hold a second, padded copy of them).
#[inline(always)]
fn block_pass<const N: usize, const P: usize, const FMA: bool, const GRAD: bool, M: PointMaterial>(
    pass: Pass<'_>,
    material: &M,
    grad_out: &mut [Vec3],
) -> f64 {
    let Pass { block, geometry, rest, x, elements } = pass;
    let mut total = 0.0;
    for e in elements {
        let nodes: &[u32; N] = block.element(e).try_into().expect("N nodes");
        let mut u = [[0.0; P]; 3];
        for i in 0..N {
            let d = x[nodes[i] as usize] - rest[nodes[i] as usize];
            for a in 0..3 {
                u[a][i] = d[a];
            }
        }
        let grads = super::element_grads(geometry, e);
        let mut grad = [[0.0; P]; 3];
        let mut energy = 0.0;
        for (gq, &v) in grads.chunks_exact(N).zip(geometry.volumes(e)) {
            let mut g = [[0.0; P]; 3];
            for i in 0..N {
                for b in 0..3 {
                    g[b][i] = gq[i][b];
                }
            }
            energy += point_energy_and_gradient::<P, FMA, GRAD, M>(&u, [&g[0], &g[1], &g[2]], v, material, &mut grad);
        }
        total += energy;
        if GRAD {
            for i in 0..N {
                grad_out[nodes[i] as usize] += Vec3::new(grad[0][i], grad[1][i], grad[2][i]);
            }
        }
    }
    total
}

/// [`block_pass`] compiled for AVX2 with FMA (selected at run time).
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn block_pass_avx2<const N: usize, const P: usize, const GRAD: bool, M: PointMaterial>(
    pass: Pass<'_>,
    material: &M,
    grad_out: &mut [Vec3],
) -> f64 {
    block_pass::<N, P, true, GRAD, M>(pass, material, grad_out)
}

/// [`block_pass`] for this block's node count and `material` (StVK through [`Stvk`], any other
/// model through [`AnyMaterial`]), with fused multiply–adds where the CPU has AVX2 and FMA; None
/// when the node count has no specialised kernel (the caller takes the generic one). With
/// `GRAD`, `grad_out` (one entry per mesh node) must be as long as the mesh's nodes.
pub(super) fn block_energy_and_gradient<const GRAD: bool>(
    pass: Pass<'_>,
    material: &Material,
    grad_out: &mut [Vec3],
) -> Option<f64> {
    block_energy_and_gradient_fused::<GRAD>(pass, material, grad_out, true)
}

/// [`block_energy_and_gradient`] with fused multiply–adds where `fma` allows them (they run
/// only where the CPU has AVX2 and FMA; the tests run both ways).
pub(super) fn block_energy_and_gradient_fused<const GRAD: bool>(
    pass: Pass<'_>,
    material: &Material,
    grad_out: &mut [Vec3],
    fma: bool,
) -> Option<f64> {
    #[cfg(target_arch = "x86_64")]
    let wide = fma && crate::math::f64x4::available();
    #[cfg(not(target_arch = "x86_64"))]
    let _ = fma;
    macro_rules! with_law {
        ($n:literal, $p:literal, $law:expr) => {{
            let law = $law;
            #[cfg(target_arch = "x86_64")]
            if wide {
                // SAFETY: AVX2 and FMA were detected.
                return Some(unsafe { block_pass_avx2::<$n, $p, GRAD, _>(pass, &law, grad_out) });
            }
            Some(block_pass::<$n, $p, false, GRAD, _>(pass, &law, grad_out))
        }};
    }
    macro_rules! dispatch {
        ($(($n:literal, $p:literal)),*) => {
            match pass.block.nodes_per_element() {
                $($n => if let Some(FastLaw::StVenantKirchhoff(l)) = material.fast_law() {
                    with_law!($n, $p, Stvk { mu_pa: l.mu_pa, lambda_pa: l.lambda_pa })
                } else {
                    with_law!($n, $p, AnyMaterial(material))
                },)*
                _ => None,
            }
        };
    }
    crate::fem::specialised_node_counts!(dispatch)
}

/// Whether blocks of `nodes_per_element` nodes have a kernel here.
pub(super) fn has_kernel(nodes_per_element: usize) -> bool {
    macro_rules! listed {
        ($(($n:literal, $p:literal)),*) => {
            matches!(nodes_per_element, $($n)|*)
        };
    }
    crate::fem::specialised_node_counts!(listed)
}
