//! Quadrature rules on the reference shapes, selected by degree of exactness.
//!
//! Source: the `fenris-quadrature` crate (A. Longva), which ships
//! - the symmetric, positive-weight rules of F. D. Witherden and P. E. Vincent, "On the
//!   identification of symmetric quadrature rules for finite element methods", *Computers &
//!   Mathematics with Applications* 69(10), 2015, 1232–1241 (generated with polyquad), for the
//!   tetrahedron (degrees 1–10), prism (1–10) and pyramid (1–10): all their points are interior,
//!   so no rule samples the pyramid apex where its shape-function gradients are singular;
//! - Gauss–Legendre tensor-product rules for the hexahedron (below), from which hox also builds
//!   the **collapsed (conical-product) Gauss rules** for the tetrahedron above degree 10
//!   (degrees 11–21; A. H. Stroud, *Approximate Calculation of Multiple Integrals*, 1971, §2.6;
//!   M. G. Duffy, SIAM J. Numer. Anal. 19(6), 1982): with `n` Gauss points per direction on
//!   `[0, 1]³`, `x = u`, `y = (1 − u) v`, `z = (1 − u)(1 − v) t` and the weight times the
//!   Jacobian `(1 − u)² (1 − v)`. A monomial `x^a y^b z^c` of total degree `d` becomes a
//!   polynomial of degree `d + 2` in `u`, `≤ d + 1` in `v` and `≤ d` in `t`, so `n = ⌈(d + 3)/2⌉`
//!   integrates it exactly. Its `n³` points reach to within a few hundredths of every face (used
//!   to check that a state is an equilibrium of the near-exactly integrated energy,
//!   docs/STABILITY.md);
//! - Gauss–Legendre tensor-product rules for the hexahedron: degree `d` in each variable uses
//!   `⌈(d + 1)/2⌉` points per direction (the integrands of Q1/Q2 elements are tensor-product
//!   polynomials, which total-degree rules do not integrate exactly).
//!
//! fenris-quadrature defines its rules on `[-1,1]`-based domains; they are mapped affinely to
//! hox's (Gmsh's) reference domains (see [`crate::element`]), which preserves exactness:
//! tetrahedron `r = (ξ + 1)/2`, weights ×⅛; prism `(x, y) = (ξ + 1)/2`, `z = ζ`, weights ×¼;
//! pyramid `(x, y) = (ξ, η)`, `z = (ζ + 1)/2`, weights ×½.

use crate::element::ReferenceShape;

/// A quadrature rule on a reference shape: `∫ f ≈ Σ_q weights[q] f(points[q])`.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadratureRule {
    pub shape: ReferenceShape,
    /// The degree asked for; the rule is exact for polynomials of at least this degree (total
    /// degree for simplices, prisms and pyramids; degree in each variable for hexahedra).
    pub degree: usize,
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    pub fn len(&self) -> usize {
        self.points.len()
    }
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
    /// `Σ_q w_q f(r_q)`.
    pub fn integrate(&self, f: impl Fn(&[f64; 3]) -> f64) -> f64 {
        self.points.iter().zip(&self.weights).map(|(p, w)| w * f(p)).sum()
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QuadratureError {
    #[error("no quadrature rule of degree {degree} on the {shape:?} (available: 1 to {max})")]
    DegreeUnavailable { shape: ReferenceShape, degree: usize, max: usize },
}

/// The highest degree available per shape.
pub fn max_degree(shape: ReferenceShape) -> usize {
    match shape {
        ReferenceShape::Hexahedron | ReferenceShape::Tetrahedron => 21,
        _ => 10,
    }
}

/// The smallest rule on `shape` exact to at least `degree` (degree 0 is treated as 1).
pub fn rule(shape: ReferenceShape, degree: usize) -> Result<QuadratureRule, QuadratureError> {
    let degree = degree.max(1);
    let unavailable = || QuadratureError::DegreeUnavailable { shape, degree, max: max_degree(shape) };
    if degree > max_degree(shape) {
        return Err(unavailable());
    }
    use fenris_quadrature::{polyquad, tensor};
    let (weights, points): (Vec<f64>, Vec<[f64; 3]>) = match shape {
        ReferenceShape::Hexahedron => tensor::hexahedron_gauss(degree / 2 + 1),
        ReferenceShape::Tetrahedron if degree > 10 => {
            let (w, p) = tensor::hexahedron_gauss((degree + 3).div_ceil(2));
            w.iter()
                .zip(&p)
                .map(|(w, q)| {
                    let [u, v, t] = [0, 1, 2].map(|d| 0.5 * (q[d] + 1.0));
                    (w / 8.0 * (1.0 - u) * (1.0 - u) * (1.0 - v), [u, (1.0 - u) * v, (1.0 - u) * (1.0 - v) * t])
                })
                .unzip()
        }
        ReferenceShape::Tetrahedron => {
            let (w, p) = polyquad::tetrahedron(degree).map_err(|_| unavailable())?;
            let p = p.iter().map(|q| q.map(|c| 0.5 * (c + 1.0))).collect();
            (w.iter().map(|w| w / 8.0).collect(), p)
        }
        ReferenceShape::Prism => {
            let (w, p) = polyquad::prism(degree).map_err(|_| unavailable())?;
            let p = p.iter().map(|q| [0.5 * (q[0] + 1.0), 0.5 * (q[1] + 1.0), q[2]]).collect();
            (w.iter().map(|w| w / 4.0).collect(), p)
        }
        ReferenceShape::Pyramid => {
            let (w, p) = polyquad::pyramid(degree).map_err(|_| unavailable())?;
            let p = p.iter().map(|q| [q[0], q[1], 0.5 * (q[2] + 1.0)]).collect();
            (w.iter().map(|w| w / 2.0).collect(), p)
        }
    };
    Ok(QuadratureRule { shape, degree, points, weights })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::lagrange::{Exponents, total_degree_exponents};

    /// Exact integral of x^a y^b z^c over each reference shape.
    fn exact_monomial_integral(shape: ReferenceShape, [a, b, c]: Exponents) -> f64 {
        let fact = |n: u32| (1..=n).map(|k| k as f64).product::<f64>();
        // ∫_{-1}^{1} t^k dt
        let seg = |k: u32| if k % 2 == 1 { 0.0 } else { 2.0 / (k as f64 + 1.0) };
        match shape {
            // a! b! c! / (a + b + c + 3)!
            ReferenceShape::Tetrahedron => fact(a) * fact(b) * fact(c) / fact(a + b + c + 3),
            ReferenceShape::Hexahedron => seg(a) * seg(b) * seg(c),
            // triangle: a! b! / (a + b + 2)!
            ReferenceShape::Prism => fact(a) * fact(b) / fact(a + b + 2) * seg(c),
            // ∫_0^1 z^c ∫∫_{|x|,|y| ≤ 1−z} x^a y^b = ∫_0^1 z^c (2(1−z)^{a+1}/(a+1))(…) dz if a, b even
            ReferenceShape::Pyramid => {
                if a % 2 == 1 || b % 2 == 1 {
                    return 0.0;
                }
                let k = a + b + 2; // ∫_0^1 z^c (1−z)^k dz = c! k! / (c + k + 1)!
                4.0 / ((a + 1) as f64 * (b + 1) as f64) * fact(c) * fact(k) / fact(c + k + 1)
            }
        }
    }

    const SHAPES: [ReferenceShape; 4] =
        [ReferenceShape::Tetrahedron, ReferenceShape::Hexahedron, ReferenceShape::Prism, ReferenceShape::Pyramid];

    #[test]
    fn every_rule_is_exact_for_every_monomial_up_to_its_degree() {
        for shape in SHAPES {
            // every degree, but hexahedra only to 10 (their tensor-degree monomials grow as d³)
            let top = if shape == ReferenceShape::Hexahedron { 10 } else { max_degree(shape) };
            for degree in 1..=top {
                let rule = rule(shape, degree).unwrap();
                // total degree ≤ degree (hexahedra: also each variable ≤ degree)
                let monomials: Vec<Exponents> = if shape == ReferenceShape::Hexahedron {
                    crate::element::lagrange::tensor_exponents(degree as u32)
                } else {
                    total_degree_exponents(degree as u32)
                };
                for e in monomials {
                    let got = rule.integrate(|r| crate::element::lagrange::monomial(&e, r));
                    let want = exact_monomial_integral(shape, e);
                    assert!(
                        (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                        "{shape:?} degree {degree}, monomial {e:?}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn weights_are_positive_points_inside_and_the_pyramid_apex_is_never_sampled() {
        for shape in SHAPES {
            for degree in 1..=max_degree(shape) {
                let rule = rule(shape, degree).unwrap();
                assert!(rule.weights.iter().all(|&w| w > 0.0), "{shape:?} {degree}");
                assert!(rule.points.iter().all(|p| shape.contains(p, 1e-12)), "{shape:?} {degree}");
                let total: f64 = rule.weights.iter().sum();
                assert!((total - shape.volume()).abs() < 1e-13);
                if shape == ReferenceShape::Pyramid {
                    assert!(rule.points.iter().all(|p| p[2] < 1.0 - 1e-3), "apex sampled at degree {degree}");
                }
            }
        }
    }

    #[test]
    fn the_p1_default_is_one_point_and_bad_degrees_are_errors() {
        assert_eq!(rule(ReferenceShape::Tetrahedron, 1).unwrap().len(), 1);
        assert_eq!(rule(ReferenceShape::Hexahedron, 3).unwrap().len(), 8);
        assert_eq!(rule(ReferenceShape::Hexahedron, 5).unwrap().len(), 27);
        // above degree 10 on the tetrahedron: the collapsed Gauss rule, n = ⌈(d + 3)/2⌉ per direction
        assert_eq!(rule(ReferenceShape::Tetrahedron, 11).unwrap().len(), 7 * 7 * 7);
        assert_eq!(rule(ReferenceShape::Tetrahedron, 17).unwrap().len(), 10 * 10 * 10);
        let err = rule(ReferenceShape::Tetrahedron, 22).unwrap_err();
        assert!(err.to_string().contains("degree 22"), "{err}");
        let err = rule(ReferenceShape::Prism, 11).unwrap_err();
        assert!(err.to_string().contains("degree 11"), "{err}");
    }
}
