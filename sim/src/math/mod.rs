//! The number types below every other room: the lane a point law is written over ([`lane`]: one
//! `f64` or a SIMD register), the SIMD register types behind one trait ([`wide`]) — four lanes
//! on AVX2 ([`f64x4`]), eight on AVX-512 ([`f64x8`]) and two in a web page (`f64x2`, wasm
//! `simd128`), each with the runtime check that the
//! CPU can run it — the raw shared pointer parallel sweeps write through ([`shared`]), and how a
//! pass over the nodes is cut between threads ([`par`]).
//! It reads no other room (as Rapier keeps its SIMD number type in a `math` module below
//! `dynamics`): the materials, the XPBD kernels and the solvers all build on it.

pub mod lane;
pub mod par;
pub mod shared;
pub mod soa;

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) mod f64x2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod f64x4;
#[cfg(target_arch = "x86_64")]
pub(crate) mod f64x8;
#[cfg(any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")))]
pub(crate) mod wide;

/// Equality, hashing, `Debug` (`Type(name)`) and `Display` (`name`) of a registry handle by its
/// entry's name, which its registry keeps unique: the element types, the material models and the
/// integrators are each a reference to a registered entry.
macro_rules! by_name {
    ($t:ident) => {
        impl PartialEq for $t {
            fn eq(&self, other: &Self) -> bool {
                self.name() == other.name()
            }
        }
        impl Eq for $t {}
        impl std::hash::Hash for $t {
            fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
                self.name().hash(state)
            }
        }
        impl std::fmt::Debug for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, concat!(stringify!($t), "({})"), self.name())
            }
        }
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}
pub(crate) use by_name;

/// A 3×3 matrix of f64 (deformation gradients, stresses).
pub type Mat3 = nalgebra::Matrix3<f64>;
