//! The substep's loops over the nodes, outside the constraint sweep: the prediction
//! `x̃ = x + h v` (the previous positions kept), XPBD's velocity update `v = (x − x_prev) / h`
//! (Macklin et al., "XPBD", 2016, Algorithm 1), and the finite check after the effects' hooks.
//! On a large mesh they run on every thread of rayon's pool, a contiguous chunk each; every
//! node's update is its own, so the result does not depend on the cut.

use super::settings::Sweep;
use crate::Vec3;
use rayon::prelude::*;

pub use crate::math::par::NODE_LOOP_MIN_NODES_PER_THREAD;
use crate::math::par::chunk_len;

/// How many chunks the substep's node loops are cut into for `nodes` nodes: one (serial) for the
/// element-order sweep (the serial reference), else [`crate::math::par::chunks`].
pub(super) fn chunks(nodes: usize, sweep: Sweep) -> usize {
    if !sweep.is_colour() {
        return 1;
    }
    crate::math::par::chunks(nodes)
}

/// `prev = x; x += h v`, in one pass per node.
pub(super) fn predict(prev: &mut [Vec3], x: &mut [Vec3], v: &[Vec3], h: f64, chunks: usize) {
    let one = |prev: &mut [Vec3], x: &mut [Vec3], v: &[Vec3]| {
        for ((p, x), v) in prev.iter_mut().zip(x.iter_mut()).zip(v) {
            *p = *x;
            *x += v * h;
        }
    };
    if chunks > 1 {
        let c = chunk_len(x.len(), chunks);
        prev.par_chunks_mut(c).zip(x.par_chunks_mut(c)).zip(v.par_chunks(c)).for_each(|((p, x), v)| one(p, x, v));
    } else {
        one(prev, x, v);
    }
}

/// `v = (x − x_prev) / h`, `inv_h` = 1/h.
pub(super) fn update_velocities(v: &mut [Vec3], x: &[Vec3], prev: &[Vec3], inv_h: f64, chunks: usize) {
    let one = |v: &mut [Vec3], x: &[Vec3], prev: &[Vec3]| {
        for ((v, x), xp) in v.iter_mut().zip(x).zip(prev) {
            *v = (x - xp) * inv_h;
        }
    };
    if chunks > 1 {
        let c = chunk_len(x.len(), chunks);
        v.par_chunks_mut(c).zip(x.par_chunks(c)).zip(prev.par_chunks(c)).for_each(|((v, x), p)| one(v, x, p));
    } else {
        one(v, x, prev);
    }
}

/// Whether every position and velocity is finite, as far as one branch-free pass tells:
/// `0 · (x + v)` is 0 unless a coordinate is not finite (or the sum overflows, a false alarm the
/// caller's search for the bad node then clears). No chain of additions, so it vectorises.
pub(super) fn all_finite(x: &[Vec3], v: &[Vec3], chunks: usize) -> bool {
    let one = |x: &[Vec3], v: &[Vec3]| {
        let mut ok = true;
        for (x, v) in x.iter().zip(v) {
            ok &= (x.x + x.y + x.z + v.x + v.y + v.z) * 0.0 == 0.0;
        }
        ok
    };
    if chunks > 1 {
        let c = chunk_len(x.len(), chunks);
        x.par_chunks(c).zip(v.par_chunks(c)).all(|(x, v)| one(x, v))
    } else {
        one(x, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each loop gives the same bits cut in one chunk or several, and the finite check finds a
    /// NaN or an infinity in a position or a velocity, in any chunk.
    #[test]
    fn node_loops_give_the_same_bits_in_any_cut_and_catch_every_non_finite_value() {
        let n = 1001;
        let x0: Vec<Vec3> =
            (0..n).map(|i| Vec3::new(i as f64 * 0.1, (i as f64).sin(), 1.0 / (1.0 + i as f64))).collect();
        let v: Vec<Vec3> = (0..n).map(|i| Vec3::new((i as f64).cos(), -0.5, i as f64 * 1e-3)).collect();
        let h = 1.0 / 3000.0;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        let run = |chunks: usize| {
            pool.install(|| {
                let (mut prev, mut x, mut vel) = (vec![Vec3::zeros(); n], x0.clone(), vec![Vec3::zeros(); n]);
                predict(&mut prev, &mut x, &v, h, chunks);
                assert_eq!(prev, x0);
                x[7].y += 1e-4;
                update_velocities(&mut vel, &x, &prev, 1.0 / h, chunks);
                assert!(all_finite(&x, &vel, chunks));
                (x, vel)
            })
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(3));
        assert!((one.1[7].y - (v[7].y + 1e-4 / h)).abs() < 1e-6);
        for chunks in [1, 2, 3] {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for node in [0, 500, n - 1] {
                    let (mut x, mut vel) = one.clone();
                    x[node].z = bad;
                    assert!(!pool.install(|| all_finite(&x, &vel, chunks)), "{bad} in x[{node}], {chunks} chunks");
                    x[node].z = 0.0;
                    vel[node].x = bad;
                    assert!(!pool.install(|| all_finite(&x, &vel, chunks)), "{bad} in v[{node}], {chunks} chunks");
                }
            }
        }
    }
}
