//! The tangent `C = ∂P/∂F` (a 9×9 matrix on column-major `vec(F)`, index `r + 3c` for `F_rc`)
//! contracted with vectors, written once for every Hessian of hox: the element Hessian's blocks
//! (`crate::fem::energy`), the static and implicit solvers' stiffness, VBD's node block and its
//! coarse correction.
//!
//! `C(a, b)_{rk} = Σ_{c,d} C_{(r+3c),(k+3d)} a_c b_d` ([`contract`]): for an element at one
//! quadrature point, the block of `∂²ψ/∂x_i∂x_j` per unit volume with `a = ∇_X N_i`,
//! `b = ∇_X N_j`. Where one `b` meets many `a` (VBD's coarse correction: every pair of coarse
//! nodes of an element) the sum is taken in two stages, [`contract_right`] then
//! [`contract_left`], the same sum in another order.
//!
//! Also here: [`FastLaw`], the point laws the XPBD sweep compiles inline, which a model offers
//! through its `fast_law` hook.

use super::{Lame, Mat3, Mat9};
use nalgebra::Vector3;

/// `C(a, b)_{rk} = Σ_{c,d} C_{(r+3c),(k+3d)} a_c b_d`.
#[inline]
pub fn contract(c: &Mat9, a: &Vector3<f64>, b: &Vector3<f64>) -> Mat3 {
    Mat3::from_fn(|r, k| {
        let mut sum = 0.0;
        for cc in 0..3 {
            for d in 0..3 {
                sum += c[(r + 3 * cc, k + 3 * d)] * a[cc] * b[d];
            }
        }
        sum
    })
}

/// The first stage for one `b`: `t[9r + 3c + k] = Σ_d C_{(r+3c),(k+3d)} b_d`.
#[inline]
pub fn contract_right(c: &Mat9, b: &Vector3<f64>) -> [f64; 27] {
    let mut t = [0.0; 27];
    for r in 0..3 {
        for cc in 0..3 {
            for k in 0..3 {
                t[9 * r + 3 * cc + k] = (0..3).map(|d| c[(r + 3 * cc, k + 3 * d)] * b[d]).sum();
            }
        }
    }
    t
}

/// The second stage: `C(a, b)_{rk} = Σ_c a_c t[9r + 3c + k]`.
#[inline]
pub fn contract_left(t: &[f64; 27], a: &Vector3<f64>) -> Mat3 {
    Mat3::from_fn(|r, k| (0..3).map(|cc| a[cc] * t[9 * r + 3 * cc + k]).sum())
}

/// A point law `(ψ(F), P(F))` the XPBD sweep has compiled inline (`crate::xpbd::kernels`),
/// offered by a model's `fast_law` hook with its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FastLaw {
    /// Saint-Venant–Kirchhoff with these Lamé parameters.
    StVenantKirchhoff(Lame),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_stages_sum_what_the_contraction_sums() {
        let c = Mat9::from_fn(|i, j| ((3 * i + 7 * j) % 11) as f64 - 5.0 + 0.25 * (i * j) as f64);
        let (a, b) = (Vector3::new(0.3, -1.2, 2.0), Vector3::new(-0.7, 0.4, 1.1));
        let one = contract(&c, &a, &b);
        let two = contract_left(&contract_right(&c, &b), &a);
        assert!((one - two).norm() <= 1e-12 * one.norm(), "{one} against {two}");
        // and each entry is the defining sum
        for r in 0..3 {
            for k in 0..3 {
                let mut s = 0.0;
                for cc in 0..3 {
                    for d in 0..3 {
                        s += c[(r + 3 * cc, k + 3 * d)] * a[cc] * b[d];
                    }
                }
                assert_eq!(one[(r, k)], s);
            }
        }
    }
}
