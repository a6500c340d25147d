//! The number type a point law is written over, so that each law is written once and runs both
//! on one `f64` ([`Scalar`]: the materials' own functions and the scalar kernels) and on four
//! elements at a time, one per lane of a 256-bit register (the linear-tetrahedron batches of
//! `crate::xpbd::kernels::p1`, StVK's four-lane node law).
//!
//! A [`Lane`] offers the four arithmetic operations a law needs, a multiply–add that is fused
//! (one rounding) or not as the type decides, and one reduction, the sum of squares of a 3×3
//! matrix, which each type sums in its own order: [`Scalar`] as nalgebra's `norm_squared`
//! (column by column, unfused) and the four-lane type as one chain of fused multiply–adds. That is
//! what each kernel computed before the laws were shared, so results are the same bit for bit.
//! Matrices are row-major arrays, `m[r][c]` ([`M3`]).

use super::Mat3;

/// A 3×3 matrix of lanes, row-major: `m[r][c]`.
pub type M3<L> = [[L; 3]; 3];

/// One or more `f64`s computed in lockstep.
pub trait Lane: Copy {
    /// Every lane `v`.
    fn splat(v: f64) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    /// `self · b + c`, fused (one rounding) or not as the type decides.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// `Σ_{r,c} m_rc²`, summed in the type's own order (see the module doc).
    fn sum_of_squares(m: &M3<Self>) -> Self;
}

/// `a b + c`, fused (one rounding) when `FMA` (only where the CPU has it: in software it is slow).
#[inline(always)]
pub fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// One `f64`; with `FMA`, [`Lane::mul_add`] is fused ([`madd`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scalar<const FMA: bool>(pub f64);

impl<const FMA: bool> Lane for Scalar<FMA> {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Self(v)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(self.0 + o.0)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(self.0 - o.0)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(self.0 * o.0)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Self(madd::<FMA>(self.0, b.0, c.0))
    }
    /// As nalgebra's `norm_squared` (unfused, whatever `FMA`): `((m₀₀² + m₁₀²) + m₂₀²) + …`
    /// column by column, the columns summed in order.
    #[inline(always)]
    fn sum_of_squares(m: &M3<Self>) -> Self {
        let mut column = [0.0; 3];
        for c in 0..3 {
            column[c] = m[0][c].0 * m[0][c].0 + m[1][c].0 * m[1][c].0 + m[2][c].0 * m[2][c].0;
        }
        Self(column[0] + column[1] + column[2])
    }
}

// The generic helpers below use plain loops, no closures: a closure (as in `std::array::from_fn`)
// is a function of its own without the caller's `#[target_feature]`s, so the AVX intrinsics of
// the four-lane type would stay out-of-line calls inside it (3.6× the instructions of the P1
// batches, measured). `#[inline(always)]` functions are inlined into the caller first.

/// `a b` for 3×3 matrices of lanes: `(a b)_rc = a_r2 b_2c + (a_r1 b_1c + a_r0 b_0c)`, each `+` a
/// [`Lane::mul_add`] (nalgebra's order: its product never fuses).
#[inline(always)]
pub fn mat_mul<L: Lane>(a: &M3<L>, b: &M3<L>) -> M3<L> {
    let mut out = *a;
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = a[r][2].mul_add(b[2][c], a[r][1].mul_add(b[1][c], a[r][0].mul(b[0][c])));
        }
    }
    out
}

/// `aᵀ b` for 3×3 matrices of lanes, as [`mat_mul`].
#[inline(always)]
pub fn tr_mat_mul<L: Lane>(a: &M3<L>, b: &M3<L>) -> M3<L> {
    let mut out = *a;
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = a[2][r].mul_add(b[2][c], a[1][r].mul_add(b[1][c], a[0][r].mul(b[0][c])));
        }
    }
    out
}

/// An nalgebra matrix as a [`M3`] of [`Scalar`]s.
#[inline(always)]
pub fn from_mat3<const FMA: bool>(m: &Mat3) -> M3<Scalar<FMA>> {
    std::array::from_fn(|r| std::array::from_fn(|c| Scalar(m[(r, c)])))
}

/// A [`M3`] of [`Scalar`]s as an nalgebra matrix.
#[inline(always)]
pub fn to_mat3<const FMA: bool>(m: &M3<Scalar<FMA>>) -> Mat3 {
    Mat3::from_fn(|r, c| m[r][c].0)
}
