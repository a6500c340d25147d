//! Projection to positive semi-definite: the nearest (Frobenius) PSD matrix to the symmetric
//! part of a tangent `∂P/∂F` (9×9, [`project_psd`]) or of a node's 3×3 Hessian block
//! ([`project_psd3`]), for Newton's method and vertex block descent far from equilibrium
//! (Teran, Sifakis, Irving & Fedkiw 2005, "Robust quasistatic finite elements and flesh
//! simulation", §4: clamp the negative eigenvalues).

use super::Mat9;
use nalgebra::{Matrix3, SymmetricEigen};

/// The nearest (Frobenius) positive semi-definite matrix to the symmetric part of `m`, written
/// once for each size: negative eigenvalues clamped to 0; the symmetric part unchanged when
/// already PSD (checked first by a Cholesky factorisation, which positive definite matrices —
/// most of a solve's — pass); non-finite input returned as is.
macro_rules! project_psd_fn {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($ty:ty)) => {
        $(#[$doc])*
        $vis fn $name(m: &$ty) -> $ty {
            if !m.iter().all(|x| x.is_finite()) {
                return *m;
            }
            let sym = (m + m.transpose()) * 0.5;
            // positive definite (a Cholesky factor exists): already its own projection, and
            // the eigen-decomposition below, tens of times dearer, is skipped
            if sym.cholesky().is_some() {
                return sym;
            }
            match SymmetricEigen::try_new(sym, f64::EPSILON, 10_000) {
                Some(eig) => {
                    if eig.eigenvalues.iter().all(|&l| l >= 0.0) {
                        return sym;
                    }
                    let clamped = eig.eigenvalues.map(|l| l.max(0.0));
                    let q = &eig.eigenvectors;
                    let out = q * <$ty>::from_diagonal(&clamped) * q.transpose();
                    (out + out.transpose()) * 0.5
                }
                // Not expected for finite symmetric input; fall back to a PSD
                // (diagonal, clamped) approximation rather than failing.
                None => <$ty>::from_diagonal(&sym.diagonal().map(|d| d.max(0.0))),
            }
        }
    };
}

project_psd_fn!(
    /// Nearest PSD matrix (Frobenius norm) to the symmetric part of `m` (a `dP/dF`).
    pub fn project_psd(Mat9)
);
project_psd_fn!(
    /// [`project_psd3`] past its positive-definite test.
    fn project_psd3_general(Matrix3<f64>)
);

/// Nearest PSD matrix to the symmetric part of a 3 × 3 block (a node's Hessian block in vertex
/// block descent). A block whose leading minors are all positive (Sylvester's criterion: positive
/// definite, the usual case) is its own projection, told in a dozen flops.
#[inline]
pub fn project_psd3(m: &Matrix3<f64>) -> Matrix3<f64> {
    let (a, d, f) = (m[(0, 0)], m[(1, 1)], m[(2, 2)]);
    let b = 0.5 * (m[(0, 1)] + m[(1, 0)]);
    let c = 0.5 * (m[(0, 2)] + m[(2, 0)]);
    let e = 0.5 * (m[(1, 2)] + m[(2, 1)]);
    let minor2 = a * d - b * b;
    let det = a * (d * f - e * e) - b * (b * f - e * c) + c * (b * e - d * c);
    // NaN fails every comparison and goes on to the general path
    if a > 0.0 && minor2 > 0.0 && det > 0.0 {
        return Matrix3::new(a, b, c, b, d, e, c, e, f);
    }
    project_psd3_general(m)
}
