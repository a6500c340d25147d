//! Hyperelastic material models for the finite-element / XPBD solvers.
//!
//! Implements the constitutive laws used by Saillant et al., *High-Order
//! Elements in Position Based Dynamics*, plus three Neo-Hookean variants:
//!
//! | [`MaterialModel`] | short name | energy density ψ(F) | module |
//! | --- | --- | --- | --- |
//! | [`MaterialModel::StVenantKirchhoff`] | `stvk` | μ E:E + λ/2 (tr E)², E = ½(FᵀF − I) | [`stvk`] |
//! | [`MaterialModel::StableNeoHookean`] | `snh` | μ/2 (I_C − 3) + λ̂/2 (J − α)² − μ²/(2λ̂) | [`stable_neo_hookean`] |
//! | [`MaterialModel::StableNeoHookeanLog`] | `snh-log` | μ̂/2 (I_C − 3) + λ̂/2 (J − α)² − μ̂/2 log(I_C + 1) + c | [`stable_neo_hookean_log`] |
//! | [`MaterialModel::NeoHookean`] | `nh` | μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)² | [`neo_hookean`] |
//!
//! **The registry.** Each model is one file implementing [`HyperelasticModel`] and one entry of
//! [`MaterialModel::ALL`] (the table above is documentation); [`Material`] dispatches through
//! the law there (no per-model `match`), and the `every_registered_model_*` tests check every
//! registered model against finite differences. Point laws written once over a [`crate::math::lane::Lane`]
//! serve the SIMD kernels too ([`stvk::energy_and_pk1`]).
//!
//! Conventions shared by every model:
//!
//! * ψ is an energy per unit reference volume (J/m³ = Pa) and is exactly `0.0`
//!   at F = I; the first Piola–Kirchhoff stress P = ∂ψ/∂F is exactly zero there.
//! * The Lamé parameters come from Young's modulus E and Poisson ratio ν:
//!   μ = E / (2(1 + ν)), λ = Eν / ((1 + ν)(1 − 2ν)), and every model's
//!   linearisation at rest equals the linear-elasticity tensor
//!   μ(δ_ik δ_jl + δ_il δ_jk) + λ δ_ij δ_kl for those μ, λ.
//! * Fourth-order tensors are 9×9 matrices acting on vec(F) in nalgebra's
//!   column-major order: index = row + 3·col, so
//!   `dpdf[(row_p + 3*col_p, row_f + 3*col_f)] = ∂P[row_p,col_p] / ∂F[row_f,col_f]`.
//! * [`Material::split_terms`] exposes the two constraints of the "split" XPBD
//!   formulation (Macklin & Müller 2021, *A Constraint-based Formulation of
//!   Stable Neo-Hookean Materials*), `[deviatoric, hydrostatic]`, with
//!   ψ(F) = Σ_t k_t/2 · C_t(F)² + [`Material::split_energy_offset`], where the
//!   stiffnesses k_t are [`Material::split_stiffness_pa`]. The XPBD compliance
//!   of term t at a quadrature point of reference volume V_q is 1/(k_t · V_q).

use nalgebra::{SMatrix, SVector, Vector3};

type Vector9 = SVector<f64, 9>;

#[cfg(test)]
mod testing;

pub use crate::math::lane;
pub mod neo_hookean;
pub mod point_law;
mod psd;
pub mod stable_neo_hookean;
pub mod stable_neo_hookean_log;
pub mod stvk;
pub mod tangent;

pub use neo_hookean::NEO_HOOKEAN_J_FLOOR;
pub use psd::{project_psd, project_psd3};
pub use tangent::{FastLaw, contract, contract_left, contract_right};

/// 3×3 matrix of `f64` (deformation gradients, stresses).
pub use crate::math::Mat3;
/// [`HyperelasticModel::node_visit_kernel`]: unsafe to call only in that the model that returned
/// it checked what the CPU has; any visit of the width asked for is valid input.
pub type NodeVisitKernel = unsafe fn(Lame, NodeVisit<'_>) -> (Vector3<f64>, Mat3);
/// 9×9 matrix of `f64` acting on column-major vec(F) (index = row + 3·col).
pub type Mat9 = SMatrix<f64, 9, 9>;

/// A hyperelastic constitutive model: everything the solvers ask of a material law, at one
/// point, for Lamé parameters `l`. Each model lives in one file and is listed once in
/// [`MaterialModel::ALL`] (as reference elements are in [`crate::element::REGISTRY`]): adding a
/// model is its file, its `mod` line and one entry there (see [`MaterialModel::ALL`]), and the
/// registry tests check it (`every_registered_model_*` below).
///
/// **The constitutive core** is what a model must state: its names, `ψ(F)`, `P(F)` and
/// `∂P/∂F`. Everything else is an **optional solver capability** with a default written over
/// the core (fenris adapts its small core to each solver the same way):
/// - the tangent's contraction ([`HyperelasticModel::stress_contraction`]) and VBD's node
///   kernels ([`HyperelasticModel::node_block`], `node_force_and_block`, `node_visit`,
///   `node_visit_kernel`): defaults from `dpdf` and `energy_density_and_pk1`, overridden by a
///   model only for speed;
/// - the fast law XPBD's sweep compiles inline ([`HyperelasticModel::fast_law`]): default none,
///   the registered law is called;
/// - XPBD's split constraints ([`HyperelasticModel::split`], a [`SplitModel`]): default none,
///   and then the split formulation refuses the model by name (the energy formulation and the
///   implicit solvers need the core only).
pub trait HyperelasticModel: Sync + Send + 'static {
    /// Short, stable identifier (`"stvk"`), unique in the registry: scene files and the command
    /// line name the model by it, and models compare equal by it.
    fn name(&self) -> &'static str;
    /// Human-readable name.
    fn long_name(&self) -> &'static str;
    /// ψ(F) in J/m³, exactly 0 at F = I.
    fn energy_density(&self, l: Lame, f: &Mat3) -> f64;
    /// (ψ(F), P(F) = ∂ψ/∂F), sharing the common work.
    fn energy_density_and_pk1(&self, l: Lame, f: &Mat3) -> (f64, Mat3);
    /// dP/dF on column-major vec(F), exactly symmetric.
    fn dpdf(&self, l: Lame, f: &Mat3) -> Mat9;
    /// The tangent contracted with two vectors at one point, per unit volume:
    /// `C(a, b)_{rk} = Σ_{c,d} ∂P_{rc}/∂F_{kd} a_c b_d` — the 3×3 block of an element Hessian
    /// coupling the nodes whose material gradients are `a` and `b` (fenris'
    /// `compute_stress_contraction`). Default: [`contract`] of [`HyperelasticModel::dpdf`], the
    /// one place the sum is written.
    fn stress_contraction(&self, l: Lame, f: &Mat3, a: &Vector3<f64>, b: &Vector3<f64>) -> Mat3 {
        contract(&self.dpdf(l, f), a, b)
    }
    /// One node's 3×3 block of an element Hessian at one quadrature point, per unit volume:
    /// `B = C(g, g)` with `g = ∇_X N_a` ([`HyperelasticModel::stress_contraction`]), i.e. column
    /// `k` is `dP[e_k ⊗ g] g` — three directional derivatives where [`HyperelasticModel::dpdf`]
    /// takes nine (vertex block descent's per-node Hessian). Symmetric. Default: the contraction,
    /// symmetrised (the sum leaves round-off between the two halves).
    fn node_block(&self, l: Lame, f: &Mat3, g: &Vector3<f64>) -> Mat3 {
        let b = self.stress_contraction(l, f, g, g);
        (b + b.transpose()) * 0.5
    }
    /// One node's share at one point, per unit volume: the force direction `P(F) g` and the
    /// block `B(F, g)` of [`HyperelasticModel::node_block`], sharing the common work (what a
    /// vertex block descent visit asks for every point of every element around a node).
    /// Default: from [`HyperelasticModel::energy_density_and_pk1`] and `node_block`.
    fn node_force_and_block(&self, l: Lame, f: &Mat3, g: &Vector3<f64>) -> (Vector3<f64>, Mat3) {
        (self.energy_density_and_pk1(l, f).1 * g, self.node_block(l, f, g))
    }
    /// `Σ_q V_q (P(F_q) g_q, B(F_q, g_q))` over the points of one element visit
    /// ([`NodeVisit`]): one call per element, so a model can keep its point law inlined.
    /// Default: [`HyperelasticModel::node_force_and_block`] point by point.
    fn node_visit(&self, l: Lame, points: NodeVisit<'_>) -> (Vector3<f64>, Mat3) {
        points.sum(|f, g| self.node_force_and_block(l, f, g))
    }
    /// A kernel computing [`HyperelasticModel::node_visit`] for visits `width` lanes wide on
    /// this CPU, which a solver may resolve once and call at every visit without the dispatch
    /// (StVK: its four-lane AVX2 law). Default: none.
    fn node_visit_kernel(&self, _width: usize) -> Option<NodeVisitKernel> {
        None
    }
    /// A point law the XPBD sweep has compiled inline for this model ([`FastLaw`]), which it then
    /// runs instead of calling [`HyperelasticModel::energy_density_and_pk1`] through the
    /// registry (StVK: its Lamé parameters computed once per sweep). Default: none.
    fn fast_law(&self, _l: Lame) -> Option<FastLaw> {
        None
    }
    /// The model's split constraints for XPBD's split formulation, if it has them. Default:
    /// none (the split formulation then refuses the model).
    fn split(&self) -> Option<&dyn SplitModel> {
        None
    }
    /// The law is smooth for `det F` above this; below it the model may switch to a
    /// continuation (Neo-Hookean's ln J floor), where finite differences are meaningless.
    /// −∞: smooth everywhere.
    fn smooth_above_det_f(&self) -> f64 {
        f64::NEG_INFINITY
    }
}

/// An optional capability of a [`HyperelasticModel`]: the two constraints of XPBD's "split"
/// formulation (Macklin & Müller 2021), with `ψ(F) = Σ_t k_t/2 · C_t(F)² + c`; offered through
/// [`HyperelasticModel::split`].
pub trait SplitModel: Sync + Send {
    /// The split constraints `[deviatoric, hydrostatic]` at F.
    fn split_terms(&self, l: Lame, f: &Mat3) -> [SplitTerm; 2];
    /// Stiffness k_t (Pa) of each split term.
    fn split_stiffness_pa(&self, l: Lame) -> [f64; 2];
    /// The constant c with ψ = Σ_t k_t/2 C_t² + c.
    fn split_energy_offset(&self, l: Lame) -> f64;
    /// `∂²C_h/∂F²` of the hydrostatic term (9×9 on column-major vec(F), symmetric): what the mixed
    /// formulation's Hessian needs besides the model's tangent (`crate::fem::energy::mixed`).
    fn hydrostatic_hessian(&self, l: Lame, f: &Mat3) -> Mat9;
    /// `H_h(g, g)_{rk} = Σ_{c,d} ∂²C_h/∂F_{rc}∂F_{kd} g_c g_d`: one node's 3 × 3 block of
    /// [`SplitModel::hydrostatic_hessian`] (a vertex block descent visit of the mixed
    /// formulation). Default: [`contract`] of the 9 × 9.
    fn hydrostatic_node_block(&self, l: Lame, f: &Mat3, g: &Vector3<f64>) -> Mat3 {
        contract(&self.hydrostatic_hessian(l, f), g, g)
    }
}

/// One node's visit of one element (vertex block descent): the element's `F_q` at its points,
/// the node's material gradients `∇_X N_a(r_q)` and the volumes `V_q`, **lane-major**: the
/// points in chunks of `width` (4 for elements with several points, one AVX2 register per
/// chunk; 1 for one-point elements), each quantity's entry stored for the chunk's points side by
/// side, so a four-lane law loads a register per entry. Chunk `k`, point `j` of it:
/// `F_q[r][c] = f[(9k + 3r + c)·width + j]`, `∇N[c] = grads[(3k + c)·width + j]`,
/// `V_q = volumes[k·width + j]`; past the last point a chunk is padded with `V = 0`, `F = I`,
/// `∇N = 0`.
#[derive(Clone, Copy)]
pub struct NodeVisit<'a> {
    pub width: usize,
    pub f: &'a [f64],
    pub grads: &'a [f64],
    pub volumes: &'a [f64],
}

impl NodeVisit<'_> {
    /// The visit's `F_q`, `∇N` and `V_q` at point `j` of chunk `k`.
    #[inline]
    pub fn point(&self, k: usize, j: usize) -> (Mat3, Vector3<f64>, f64) {
        let w = self.width;
        let f = Mat3::from_fn(|r, c| self.f[(9 * k + 3 * r + c) * w + j]);
        let g = Vector3::from_fn(|c, _| self.grads[(3 * k + c) * w + j]);
        (f, g, self.volumes[k * w + j])
    }

    /// `Σ_q V_q point(F_q, g_q)`, point by point (padding skipped).
    #[inline]
    pub fn sum(&self, point: impl Fn(&Mat3, &Vector3<f64>) -> (Vector3<f64>, Mat3)) -> (Vector3<f64>, Mat3) {
        let (mut force, mut block) = (Vector3::zeros(), Mat3::zeros());
        for (p, &v) in self.volumes.iter().enumerate() {
            if v == 0.0 {
                continue;
            }
            let (f, g, _) = self.point(p / self.width, p % self.width);
            let (fq, bq) = point(&f, &g);
            force += fq * v;
            block += bq * v;
        }
        (force, block)
    }
}

/// A hyperelastic constitutive model, by reference to its registered law (compare
/// [`crate::element::ElementType`]). Models compare and hash by [`MaterialModel::name`].
#[derive(Clone, Copy)]
pub struct MaterialModel(&'static dyn HyperelasticModel);

// The built-in models keep the names they had as enum variants.
#[allow(non_upper_case_globals)]
impl MaterialModel {
    /// **The registry**: every model, in this order (menus, tests).
    ///
    /// Adding a model is its file `sim/src/material/NAME.rs` (a unit struct implementing
    /// [`HyperelasticModel`]), its `pub mod NAME;` line above, and one entry here,
    /// `MaterialModel(&NAME::Struct),`. Everything else reads the registry:
    /// [`MaterialModel::from_name`], the scene file's `material.model`, `--material`, the app's
    /// menu and their help texts (the parameter table's choices, `scenes/src/params/`), the
    /// kernels (through the law) and the tests: the `every_registered_model_*` tests below
    /// check it against finite differences, and `tests/tests/registries.rs` runs it through a
    /// scene with every element type. (A named constant such as
    /// [`MaterialModel::StVenantKirchhoff`] is only for code that wants that one model; the
    /// kernels' StVK fast path is optional speed, every other model takes the generic law.)
    pub const ALL: &'static [MaterialModel] = &[
        MaterialModel(&stvk::StVenantKirchhoff),
        MaterialModel(&stable_neo_hookean::StableNeoHookean),
        MaterialModel(&stable_neo_hookean_log::StableNeoHookeanLog),
        MaterialModel(&neo_hookean::NeoHookean),
    ];

    /// Saint-Venant–Kirchhoff (the model used in Saillant et al.). See [`stvk`].
    pub const StVenantKirchhoff: MaterialModel = MaterialModel(&stvk::StVenantKirchhoff);
    /// Stable Neo-Hookean (Smith, de Goes & Kim 2018) without the log(I_C + 1)
    /// term, as in Macklin & Müller 2021. See [`stable_neo_hookean`].
    pub const StableNeoHookean: MaterialModel = MaterialModel(&stable_neo_hookean::StableNeoHookean);
    /// Stable Neo-Hookean with Smith et al.'s log(I_C + 1) term (no collapse
    /// minimum at F = 0). See [`stable_neo_hookean_log`].
    pub const StableNeoHookeanLog: MaterialModel = MaterialModel(&stable_neo_hookean_log::StableNeoHookeanLog);
    /// Classic compressible Neo-Hookean with a ln J floor. See [`neo_hookean`].
    pub const NeoHookean: MaterialModel = MaterialModel(&neo_hookean::NeoHookean);

    /// The model's law.
    pub fn law(self) -> &'static dyn HyperelasticModel {
        self.0
    }

    /// Short, stable identifier: `"stvk"`, `"snh"`, `"snh-log"` or `"nh"`.
    pub fn name(self) -> &'static str {
        self.0.name()
    }

    /// Human-readable name.
    pub fn long_name(self) -> &'static str {
        self.0.long_name()
    }

    /// Parses a short name (`stvk`, `snh`, `snh-log`, `nh`), ignoring ASCII case and
    /// surrounding whitespace. The long names are accepted as well.
    pub fn from_name(s: &str) -> Option<Self> {
        let s = s.trim();
        Self::ALL.iter().copied().find(|m| s.eq_ignore_ascii_case(m.name()) || s.eq_ignore_ascii_case(m.long_name()))
    }
}

crate::math::by_name!(MaterialModel);

/// Lamé parameters, in pascals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lame {
    /// Shear modulus μ (Pa).
    pub mu_pa: f64,
    /// First Lamé parameter λ (Pa). Negative for ν < 0.
    pub lambda_pa: f64,
}

impl Lame {
    /// μ = E / (2(1 + ν)), λ = Eν / ((1 + ν)(1 − 2ν)).
    ///
    /// Pure formula, no validation: use [`Material::new`] for checked input.
    pub fn from_youngs_poisson(youngs_modulus_pa: f64, poisson_ratio: f64) -> Lame {
        let e = youngs_modulus_pa;
        let nu = poisson_ratio;
        Lame { mu_pa: e / (2.0 * (1.0 + nu)), lambda_pa: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) }
    }
}

/// Invalid material parameters.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum MaterialError {
    /// E is not a finite number > 0.
    #[error("Young's modulus must be a finite positive number of pascals, got {youngs_modulus_pa}")]
    YoungsModulus { youngs_modulus_pa: f64 },
    /// ν is not a finite number in the open interval (−1, 0.5).
    #[error("Poisson ratio must lie in (-1, 0.5) for {model} (λ → ∞ at 0.5), got {poisson_ratio}")]
    PoissonRatio { model: MaterialModel, poisson_ratio: f64 },
    /// ρ is not a finite number > 0.
    #[error("density must be a finite positive number of kg/m³, got {density_kg_m3}")]
    Density { density_kg_m3: f64 },
    /// The mixed formulation asked of a model without a split.
    #[error(
        "the mixed formulation measures a material's hydrostatic term over the element, and {model} has no \
         deviatoric/hydrostatic split; use stvk or nh"
    )]
    NoSplit { model: MaterialModel },
    /// The mixed formulation asked of a model whose deviatoric term is not stable alone.
    #[error(
        "the mixed formulation leaves {model}'s deviatoric term to hold each quadrature point alone, and that \
         term is not stable alone: its tangent at rest has the eigenvalue {min_eigenvalue_pa:.3e} Pa (it \
         carries a stress at rest that the hydrostatic term cancels, so a dilatation inside an element would \
         release energy); use stvk or nh"
    )]
    DeviatoricUnstable { model: MaterialModel, min_eigenvalue_pa: f64 },
    /// E and ν are individually valid but μ or λ overflows `f64`.
    #[error(
        "Young's modulus {youngs_modulus_pa} Pa with Poisson ratio {poisson_ratio} gives \
         non-finite Lamé parameters (μ = {mu_pa} Pa, λ = {lambda_pa} Pa)"
    )]
    NonFiniteLame { youngs_modulus_pa: f64, poisson_ratio: f64, mu_pa: f64, lambda_pa: f64 },
}

/// A validated hyperelastic material.
///
/// Construct with [`Material::new`]. The Lamé parameters are derived from the
/// public fields on every call (a few flops), so they can never go stale; if
/// you mutate the public fields yourself you bypass validation.
// `#[non_exhaustive]` would not stop struct-literal construction inside this
// crate; the private field does (outside this module).
#[allow(clippy::manual_non_exhaustive)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub model: MaterialModel,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub density_kg_m3: f64,
    /// Where the hydrostatic term of the model's split is measured: at each quadrature point
    /// (the default: ψ itself), or over each element (the mixed formulation; set through
    /// [`Material::with_volume_measure`], which checks the model can be measured so).
    pub volume_measure: VolumeMeasure,
    /// Forces construction through [`Material::new`].
    _validated: (),
}

/// Where a material's hydrostatic term is measured ([`Material::volume_measure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum VolumeMeasure {
    /// At every quadrature point: the element's energy is `Σ_q V_q ψ(F_q)`.
    #[default]
    Point,
    /// Over the element: the hydrostatic term of the split at the element's mean `C̄_h`, the
    /// deviatoric term at each point (the mixed formulation, `crate::fem::energy::mixed`).
    Element,
}

/// One split constraint at a quadrature point.
///
/// `grad_f_scaled` = `scale` · ∂C/∂F. For constraints of the form C = sqrt(g) ≥ 0
/// (whose gradient is 0/0 at C = 0) `scale` = C and `grad_f_scaled` = ∂(C²/2)/∂F,
/// which stays finite; for the others `scale` = 1 and `grad_f_scaled` = ∂C/∂F.
/// Where `scale` ≠ 0, ∂C/∂F = `grad_f_scaled` / `scale`.
#[derive(Clone, Copy, Debug)]
pub struct SplitTerm {
    /// C(F).
    pub value: f64,
    /// The factor folded into `grad_f_scaled` (C for sqrt forms, else 1).
    pub scale: f64,
    /// `scale` · ∂C/∂F.
    pub grad_f_scaled: Mat3,
}

/// An open interval `(min, max)` a material number must lie in (finite, and strictly inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpenRange {
    pub min: f64,
    pub max: f64,
}

impl OpenRange {
    /// Whether `x` is finite and strictly inside.
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite() && x > self.min && x < self.max
    }
}

/// Young's modulus E in pascals: finite and > 0. The rule [`Material::new`] checks; the parameter
/// table's range for E is this (`hox_scenes::params`), so a scene is checked once.
pub const YOUNGS_MODULUS_PA: OpenRange = OpenRange { min: 0.0, max: f64::INFINITY };
/// Poisson's ratio ν: in (−1, 0.5) for every model (λ → ∞ at 0.5).
pub const POISSON_RATIO: OpenRange = OpenRange { min: -1.0, max: 0.5 };
/// Density ρ in kg/m³: finite and > 0.
pub const DENSITY_KG_M3: OpenRange = OpenRange { min: 0.0, max: f64::INFINITY };

impl Material {
    /// Validates E, ν and ρ against [`YOUNGS_MODULUS_PA`], [`POISSON_RATIO`] and
    /// [`DENSITY_KG_M3`], then the pair (E, ν) ([`Material::from_checked_ranges`]).
    pub fn new(
        model: MaterialModel,
        youngs_modulus_pa: f64,
        poisson_ratio: f64,
        density_kg_m3: f64,
    ) -> Result<Material, MaterialError> {
        if !YOUNGS_MODULUS_PA.contains(youngs_modulus_pa) {
            return Err(MaterialError::YoungsModulus { youngs_modulus_pa });
        }
        // Every model needs a finite λ, hence the open upper bound 0.5.
        if !POISSON_RATIO.contains(poisson_ratio) {
            return Err(MaterialError::PoissonRatio { model, poisson_ratio });
        }
        if !DENSITY_KG_M3.contains(density_kg_m3) {
            return Err(MaterialError::Density { density_kg_m3 });
        }
        Material::from_checked_ranges(model, youngs_modulus_pa, poisson_ratio, density_kg_m3)
    }

    /// A material from numbers the caller has already checked against [`YOUNGS_MODULUS_PA`],
    /// [`POISSON_RATIO`] and [`DENSITY_KG_M3`] (the parameter table does, with these ranges: a
    /// scene's E is checked once on its way to the kernel). Only what no single range can say is
    /// checked here: that the pair (E, ν) gives finite Lamé parameters. The ranges are asserted in
    /// debug builds.
    pub fn from_checked_ranges(
        model: MaterialModel,
        youngs_modulus_pa: f64,
        poisson_ratio: f64,
        density_kg_m3: f64,
    ) -> Result<Material, MaterialError> {
        debug_assert!(YOUNGS_MODULUS_PA.contains(youngs_modulus_pa), "E = {youngs_modulus_pa} Pa unchecked");
        debug_assert!(POISSON_RATIO.contains(poisson_ratio), "ν = {poisson_ratio} unchecked");
        debug_assert!(DENSITY_KG_M3.contains(density_kg_m3), "ρ = {density_kg_m3} kg/m³ unchecked");
        let lame = Lame::from_youngs_poisson(youngs_modulus_pa, poisson_ratio);
        // λ + μ = E / (2(1+ν)(1−2ν)) is what stable Neo-Hookean divides by
        // (with the log term, λ + 5μ/6, > 0 for ν > −1 and finite when λ + μ is).
        if !(lame.mu_pa.is_finite() && lame.lambda_pa.is_finite() && (lame.mu_pa + lame.lambda_pa).is_finite()) {
            return Err(MaterialError::NonFiniteLame {
                youngs_modulus_pa,
                poisson_ratio,
                mu_pa: lame.mu_pa,
                lambda_pa: lame.lambda_pa,
            });
        }
        Ok(Material {
            model,
            youngs_modulus_pa,
            poisson_ratio,
            density_kg_m3,
            volume_measure: VolumeMeasure::Point,
            _validated: (),
        })
    }

    /// This material with its hydrostatic term measured at `measure`. Measuring it over the element
    /// needs the model's split (`NoSplit` else) with a deviatoric term that is stable alone: the
    /// tangent a point keeps at rest, `∂P/∂F − k_h (G_h ⊗ G_h + C_h ∂²C_h/∂F²) + p ∂²C_h/∂F²` with
    /// the element's pressure `p = k_h C_h` there, i.e. `∂P/∂F − k_h G_h ⊗ G_h` at F = I, positive
    /// semi-definite (`DeviatoricUnstable` else: stable Neo-Hookean's, whose deviatoric term
    /// carries μ at rest, balanced by a pressure −μ that then softens every point's dilatation).
    pub fn with_volume_measure(self, measure: VolumeMeasure) -> Result<Material, MaterialError> {
        if measure == VolumeMeasure::Element {
            let Some(split) = self.model.law().split() else {
                return Err(MaterialError::NoSplit { model: self.model });
            };
            let (l, i) = (self.lame(), Mat3::identity());
            let [_, h] = split.split_terms(l, &i);
            let k_h = split.split_stiffness_pa(l)[1];
            let g = Vector9::from_column_slice(h.grad_f_scaled.as_slice());
            let a = self.dpdf(&i) - g * g.transpose() * k_h;
            let sym = (a + a.transpose()) * 0.5;
            let min = sym.symmetric_eigenvalues().min();
            let scale = sym.amax();
            if min < -1e-9 * scale {
                return Err(MaterialError::DeviatoricUnstable { model: self.model, min_eigenvalue_pa: min });
            }
        }
        Ok(Material { volume_measure: measure, ..self })
    }

    /// Lamé parameters μ, λ of this material.
    pub fn lame(&self) -> Lame {
        Lame::from_youngs_poisson(self.youngs_modulus_pa, self.poisson_ratio)
    }

    /// ψ(F) in J/m³, exactly 0 at F = I for every model.
    pub fn energy_density(&self, f: &Mat3) -> f64 {
        self.model.law().energy_density(self.lame(), f)
    }

    /// First Piola–Kirchhoff stress P = ∂ψ/∂F (Pa).
    pub fn pk1(&self, f: &Mat3) -> Mat3 {
        self.energy_density_and_pk1(f).1
    }

    /// (ψ(F), P(F)), sharing the common work.
    pub fn energy_density_and_pk1(&self, f: &Mat3) -> (f64, Mat3) {
        self.model.law().energy_density_and_pk1(self.lame(), f)
    }

    /// dP/dF as a 9×9 matrix on column-major vec(F) (index = row + 3·col):
    /// `dpdf[(row_p + 3*col_p, row_f + 3*col_f)] = ∂P[row_p,col_p] / ∂F[row_f,col_f]`.
    /// Exactly symmetric (it is the Hessian of ψ).
    pub fn dpdf(&self, f: &Mat3) -> Mat9 {
        self.model.law().dpdf(self.lame(), f)
    }

    /// [`Material::dpdf`] projected to the nearest (Frobenius) positive
    /// semi-definite matrix: symmetric eigen-decomposition with negative
    /// eigenvalues clamped to 0. Returned unchanged when already PSD.
    /// Non-finite input is returned as is.
    /// The point law the XPBD sweep runs inline for this material, if its model offers one
    /// ([`HyperelasticModel::fast_law`]).
    pub fn fast_law(&self) -> Option<FastLaw> {
        if self.volume_measure != VolumeMeasure::Point {
            return None;
        }
        self.model.law().fast_law(self.lame())
    }

    /// One node's 3×3 Hessian block per unit volume at `f` ([`HyperelasticModel::node_block`]).
    pub fn node_block(&self, f: &Mat3, g: &Vector3<f64>) -> Mat3 {
        self.model.law().node_block(self.lame(), f, g)
    }

    /// `(P(F) g, B(F, g))` per unit volume ([`HyperelasticModel::node_force_and_block`]) with the
    /// Lamé parameters `l` of this material ([`Material::lame`], computed once by a caller that
    /// visits many points).
    #[inline]
    pub fn node_force_and_block(&self, l: Lame, f: &Mat3, g: &Vector3<f64>) -> (Vector3<f64>, Mat3) {
        self.model.law().node_force_and_block(l, f, g)
    }

    /// `Σ_q V_q (P(F_q) g_q, B(F_q, g_q))` over one element visit
    /// ([`HyperelasticModel::node_visit`]).
    #[inline]
    pub fn node_visit(&self, l: Lame, points: NodeVisit<'_>) -> (Vector3<f64>, Mat3) {
        self.model.law().node_visit(l, points)
    }

    /// [`HyperelasticModel::node_visit_kernel`].
    /// None when the hydrostatic term is measured over the element (the kernels are the point law's).
    pub fn node_visit_kernel(&self, width: usize) -> Option<NodeVisitKernel> {
        if self.volume_measure != VolumeMeasure::Point {
            return None;
        }
        self.model.law().node_visit_kernel(width)
    }

    pub fn dpdf_projected(&self, f: &Mat3) -> Mat9 {
        project_psd(&self.dpdf(f))
    }

    /// The two split constraints `[deviatoric, hydrostatic]` at F
    /// (see each model's module doc for their definitions).
    ///
    /// # Panics
    /// If the model has no split constraints ([`Material::has_split`]; a simulation refuses the
    /// split formulation for such a model before any step).
    pub fn split_terms(&self, f: &Mat3) -> [SplitTerm; 2] {
        self.split_law().split_terms(self.lame(), f)
    }

    /// Stiffness k_t (Pa) of each split term, so that
    /// ψ(F) = Σ_t k_t/2 · C_t(F)² + [`Material::split_energy_offset`].
    /// XPBD compliance is 1/(k_t · V_q).
    ///
    /// The hydrostatic stiffness of `stvk` and `nh` is λ, which is negative
    /// for ν < 0 (and 0 for ν = 0); `snh` uses λ̂ = λ + μ > 0; `snh-log` uses
    /// [μ̂, λ̂] = [4μ/3, λ + 5μ/6], both > 0.
    pub fn split_stiffness_pa(&self) -> [f64; 2] {
        self.split_law().split_stiffness_pa(self.lame())
    }

    /// The constant c (J/m³) with ψ(F) = Σ_t k_t/2 · C_t(F)² + c:
    /// 0 for `stvk` and `nh`, −3μ/2 − μ²/(2λ̂) for `snh`,
    /// μ̂ (log 2 − 3/2) − 9μ̂²/(32λ̂) for `snh-log`.
    pub fn split_energy_offset(&self) -> f64 {
        self.split_law().split_energy_offset(self.lame())
    }

    /// Whether the model offers XPBD's split constraints ([`HyperelasticModel::split`]).
    pub fn has_split(&self) -> bool {
        self.model.law().split().is_some()
    }

    /// `∂²C_h/∂F²` of the hydrostatic split term ([`SplitModel::hydrostatic_hessian`]).
    ///
    /// # Panics
    /// As [`Material::split_terms`].
    pub fn hydrostatic_hessian(&self, f: &Mat3) -> Mat9 {
        self.split_law().hydrostatic_hessian(self.lame(), f)
    }

    /// [`SplitModel::hydrostatic_node_block`].
    ///
    /// # Panics
    /// As [`Material::split_terms`].
    pub fn hydrostatic_node_block(&self, f: &Mat3, g: &Vector3<f64>) -> Mat3 {
        self.split_law().hydrostatic_node_block(self.lame(), f, g)
    }

    fn split_law(&self) -> &dyn SplitModel {
        match self.model.law().split() {
            Some(split) => split,
            None => panic!("{}: no split constraints (the split formulation refuses it)", self.model),
        }
    }
}

// ---------------------------------------------------------------------------
// Shared kinematics helpers.

/// cof F = det(F) F⁻ᵀ, built from cross products of the columns f0, f1, f2:
/// cof F = [f1×f2, f2×f0, f0×f1]. Defined (and smooth) for singular F too.
fn cofactor(f: &Mat3) -> Mat3 {
    let a: Vector3<f64> = f.column(0).into_owned();
    let b: Vector3<f64> = f.column(1).into_owned();
    let c: Vector3<f64> = f.column(2).into_owned();
    Mat3::from_columns(&[b.cross(&c), c.cross(&a), a.cross(&b)])
}

/// Directional derivative of [`cofactor`] at F along dF:
/// d cof = [df1×f2 + f1×df2, df2×f0 + f2×df0, df0×f1 + f0×df1].
fn cofactor_directional(f: &Mat3, df: &Mat3) -> Mat3 {
    let a: Vector3<f64> = f.column(0).into_owned();
    let b: Vector3<f64> = f.column(1).into_owned();
    let c: Vector3<f64> = f.column(2).into_owned();
    let da: Vector3<f64> = df.column(0).into_owned();
    let db: Vector3<f64> = df.column(1).into_owned();
    let dc: Vector3<f64> = df.column(2).into_owned();
    Mat3::from_columns(&[db.cross(&c) + b.cross(&dc), dc.cross(&a) + c.cross(&da), da.cross(&b) + a.cross(&db)])
}

/// J − 1 = det(F) − 1 without the cancellation of `det(F) - 1.0` near rest:
/// with H = F − I, det(I + H) = 1 + tr H + ½((tr H)² − tr(H²)) + det H.
fn det_minus_one(f: &Mat3) -> f64 {
    let h = f - Mat3::identity();
    let tr = h.trace();
    tr + 0.5 * (tr * tr - (h * h).trace()) + h.determinant()
}

/// I_C − 3 = ‖F‖²_F − 3, computed as 2 tr H + ‖H‖² (H = F − I) to stay exact at rest.
fn first_invariant_minus_three(f: &Mat3) -> f64 {
    let h = f - Mat3::identity();
    2.0 * h.trace() + h.norm_squared()
}

/// Assembles the 9×9 tangent from a directional derivative dP(F; dF) applied
/// to the 9 unit matrices (column j ↔ vec index j = row + 3·col), and
/// symmetrises it (the exact tangent is a Hessian, so this only removes rounding).
/// [`HyperelasticModel::node_block`] from the directional derivative `dP[dF]`.
fn node_block_from_directional(dp: impl Fn(&Mat3) -> Mat3, g: &Vector3<f64>) -> Mat3 {
    let mut b = Mat3::zeros();
    for k in 0..3 {
        let mut df = Mat3::zeros();
        df.set_row(k, &g.transpose());
        b.set_column(k, &(dp(&df) * g));
    }
    (b + b.transpose()) * 0.5
}

fn dpdf_from_directional(dp: impl Fn(&Mat3) -> Mat3) -> Mat9 {
    let mut out = Mat9::zeros();
    for j in 0..9 {
        let mut df = Mat3::zeros();
        df[j] = 1.0;
        let col = dp(&df);
        for i in 0..9 {
            out[(i, j)] = col[i];
        }
    }
    (out + out.transpose()) * 0.5
}

#[cfg(test)]
mod tests;
