//! # rod-ig-core
//!
//! Equilibrium shapes of a Kirchhoff elastic rod held by two grippers, and their inverse
//! geometry, after Roussel, Renaud & Taïx (2015), "Closed-forms of planar Kirchhoff elastic
//! rods: application to inverse geometry" (corrections in `docs/math.md`).
//!
//! The rod has unit length and unit stiffness, its base is held at the identity. An
//! equilibrium is parametrised by the base wrench a = μ(0): a ∈ R³ for the planar rod
//! (a3 = moment, a4, a5 = force), a ∈ R⁶ for the 3-D rod. Scaling to physical length and
//! stiffness is the caller's business (see the node and the CLI); this crate does no I/O.
//!
//! Modules:
//! - [`scalar`]: the [`scalar::Real`] trait and forward-mode dual numbers, so the closed forms
//!   give exact derivatives.
//! - [`dual`]: the one forward-mode dual number, generic over f64 and double-double.
//! - [`dd`]: double-double numbers and their dual numbers, on which the same closed forms run
//!   where f64 cancels (near the separatrix).
//! - [`elliptic`]: Jacobi elliptic functions and Legendre/Carlson integrals, accurate when the
//!   complementary parameter m1 = 1 − m is passed directly.
//! - `conjugate` (internal): the one stability scan — sampling g(t) = det J/D0, the first
//!   conjugate point, the margin and its error bound — that every rod model runs.
//! - [`planar`]: closed-form shape q(t), sensitivity J(t, a), stability and energy.
//! - [`ode`]: numerical integrators (adaptive Dormand–Prince 8(5,3) and fixed-step RK4) and the
//!   planar ODE reference with variational equations.
//! - [`solver`]: one inverse-geometry API for every rod model (the [`solver::RodModel`]
//!   trait, the paper's Newton, the robust search, least energy, all solutions, deadlines,
//!   observers).
//! - [`planar::ig`]: the planar closed forms' search behind it (atlas, multi-start, tracking).
//! - [`plan`]: stable gripper paths for the planar rod, planned over a roadmap of stable rods
//!   in a-space.
//! - [`rng`]: a small deterministic generator for reproducible samples.
//! - [`spatial`]: the 3-D rod by numerical integration, and its inverse geometry.
//! - [`ends`]: how each end is held (clamped, pinned, free).
//! - [`wrench`]: the wrenches the rod exerts on its two grippers, as wrist sensors read them.
#![warn(missing_docs)]

mod angle;
mod conjugate;
pub mod dd;
pub mod deadline;
pub mod dual;
mod eft;
pub mod elliptic;
pub mod ends;
mod error;
pub mod ode;
pub mod plan;
pub mod planar;
pub mod rng;
pub mod scalar;
mod simd;
pub mod solver;
pub mod spatial;
mod types;
pub mod wrench;

pub use error::RodError;
pub use types::{
    planar_det_leading_term, wrap_angle, PlanarJacobian, PlanarParams, PlanarPose, StabilityReport,
    StabilityVerdict, STABILITY_MARGIN_T_MIN, STABILITY_T_MIN,
};

// The README's Rust example is compiled and run as a doc-test.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;
