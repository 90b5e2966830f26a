//! Closed-form planar Kirchhoff rod (Roussel, Renaud & Taïx 2015, §2.2, with the corrections of
//! `docs/math.md`): shape q(t) = (x, y, θ)(t), sensitivity J(t, a) = ∂q(t)/∂a,
//! stability (Bretl & McCarthy: det J(t, a) > 0 on (0, 1]) and elastic energy.
//!
//! Conventions: a = (a3, a4, a5) = μ(0) (base moment and force), unit length and stiffness,
//! base at the identity; θ is unwrapped (θ(t) = ∫₀ᵗ κ); J has rows (x, y, θ) and columns
//! (a3, a4, a5).
//!
//! The closed form is written once, generic over [`crate::scalar::Real`]: in `f64` it gives the
//! pose, in [`crate::scalar::Dual3`] seeded with the identity on a it gives the exact J in the
//! same pass. All cases of docs/math.md §2 are covered: I (λ4 > 0), II (λ4 < 0, via the m > 1
//! transform), III (λ4 = 0 exactly), the circle (a4 = a5 = 0) and the straight rod
//! (a3 = a5 = 0), with a3 = 0 (ε = +1), a5 = 0, small force (m → 0, D form) and the
//! near-separatrix regime (m1 = 1 − m from λ4) handled without cancellation.
//!
//! Every entry point asks its question through one dispatcher (`planar/dispatch.rs`, its table of
//! formulations in order), which alone decides which formulation (`planar/formulation/`: the closed
//! form, the small-angle expansion, the ill-conditioned routes, the Taylor series, the full
//! evaluation) answers a rod: so they share one domain and one refusal.
//!
//! This file is the front only: it declares the modules and re-exports the public names, and
//! nothing inside `planar/` imports through it (`scripts/checks/front_only.py`, run by the test
//! suite). The entry points live in `entry.rs`.

mod closed;
pub(crate) mod dispatch;
mod energy;
mod entry;
mod extended;
mod formulation;
pub mod heavy;
pub mod ig;
pub mod model;
mod pendulum;
mod shape;
mod small_angle;
mod soliton;
mod stability;
mod taylor;

pub use closed::Case;
pub use dispatch::{route, Quantity, Route};
pub use entry::{
    energy, evaluate, pose_and_jacobian, stability, stability_verdict, tip, tip_and_jacobian,
    Evaluation,
};
pub use model::{check_target, PlanarClosedForm, PlanarReference};
pub use shape::PlanarRod;

#[cfg(test)]
mod tests;
