//! The wrenches the rod exerts on its two grippers (issue 52, item 2).
//!
//! **Convention.** Each wrench is the force and moment the rod exerts on a gripper, in that
//! gripper's own frame, about its grasp point: what a wrist force-torque sensor between the
//! flange and the gripper reads (the gripper's own weight aside). Units: the unit rod's, force
//! EI/L², moment EI/L (the node and the CLI scale them).
//!
//! - **Base**: the internal wrench μ(0) = a, in the base frame: force (a4, a5) (3-D
//!   (a4, a5, a6)), moment a3 (3-D (a1, a2, a3)). The node has published it as `rod/base_wrench`
//!   since its first version.
//! - **Tip**: −μ(1) in the tip frame: force −R(1)ᵀ n(1), moment −m(1), where n(1) is the internal
//!   force at the tip in the base frame, (a4, a5) − w ĝ with weight, and m(1) the internal
//!   moment (planar: κ(1)). Without weight the two wrenches balance: in the base frame the
//!   forces sum to zero and the moments about the base to zero; with weight they carry it,
//!   base force + tip force (base frame) = w ĝ.
//!
//! Planar, without weight, κ(1) follows from the tip alone by the moment balance
//! κ' = a4 sin θ − a5 cos θ (docs/math.md §1): κ(1) = a3 + a4 y(1) − a5 x(1). 3-D, the world
//! moment about the base is conserved (docs/math.md §10), M(1) = a_m (with weight
//! a_m − P(1) × w ĝ, P = ∫p), and m(1) = R(1)ᵀ(M(1) − p(1) × n(1)).

use crate::{PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};

/// A planar wrench: force (x, y) in a gripper's frame and moment about its grasp point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanarWrench {
    /// Force in the gripper's frame.
    pub force: [f64; 2],
    /// Moment about the grasp point (counter-clockwise positive).
    pub moment: f64,
}

/// A 3-D wrench: force and moment in a gripper's frame, about its grasp point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SpatialWrench {
    /// Force in the gripper's frame.
    pub force: [f64; 3],
    /// Moment about the grasp point.
    pub moment: [f64; 3],
}

/// The wrenches the rod exerts on its base and tip grippers (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GripperWrenches<W> {
    /// On the base gripper, in the base frame.
    pub base: W,
    /// On the tip gripper, in the tip frame.
    pub tip: W,
}

/// Planar wrenches from a, the tip pose, the internal force at the tip n(1) (base frame) and
/// the tip curvature κ(1) (module docs).
pub fn planar(
    a: &PlanarParams,
    tip: &PlanarPose,
    tip_force: [f64; 2],
    tip_curvature: f64,
) -> GripperWrenches<PlanarWrench> {
    let (s, c) = tip.theta.sin_cos();
    let [nx, ny] = tip_force;
    GripperWrenches {
        base: PlanarWrench {
            force: [a[1], a[2]],
            moment: a[0],
        },
        tip: PlanarWrench {
            force: [-(c * nx + s * ny), -(c * ny - s * nx)],
            moment: -tip_curvature,
        },
    }
}

/// κ(1) of the weightless planar rod from its tip (module docs).
pub fn weightless_tip_curvature(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    a[0] + a[1] * tip.y - a[2] * tip.x
}

/// 3-D wrenches from a = (moment, force), the tip pose, and the world wrench at the tip: the
/// internal force n(1) and the moment about the base M(1), both in the base frame.
pub fn spatial(
    a: &crate::spatial::SpatialParams,
    tip: &crate::spatial::SpatialPose,
    tip_force: nalgebra::Vector3<f64>,
    tip_moment_about_base: nalgebra::Vector3<f64>,
) -> GripperWrenches<SpatialWrench> {
    let r_inv = tip.rotation.inverse();
    let f = r_inv * tip_force;
    let m = r_inv * (tip_moment_about_base - tip.position.cross(&tip_force));
    GripperWrenches {
        base: SpatialWrench {
            force: [a[3], a[4], a[5]],
            moment: [a[0], a[1], a[2]],
        },
        tip: SpatialWrench {
            force: [-f.x, -f.y, -f.z],
            moment: [-m.x, -m.y, -m.z],
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar;

    /// Weightless: the tip curvature by the moment balance is the rod's own κ(1), and the two
    /// wrenches balance in the base frame.
    #[test]
    fn weightless_planar_wrenches_balance() {
        for a in [
            PlanarParams::new(1.3, -20.0, 4.0),
            PlanarParams::new(-0.4, 35.0, -2.5),
            PlanarParams::new(3.0, 0.0, 0.0),
        ] {
            let rod = planar::PlanarRod::new(&a).unwrap();
            let tip = rod.tip();
            let k1 = weightless_tip_curvature(&a, &tip);
            assert!((k1 - rod.curvature(1.0)).abs() < 1e-9, "{a:?}");
            let w = planar(&a, &tip, [a[1], a[2]], k1);
            // The tip force back in the base frame, and the moments about the base.
            let (s, c) = tip.theta.sin_cos();
            let [fx, fy] = w.tip.force;
            let world = [c * fx - s * fy, s * fx + c * fy];
            assert!((world[0] + w.base.force[0]).abs() < 1e-12);
            assert!((world[1] + w.base.force[1]).abs() < 1e-12);
            let moment = w.base.moment + w.tip.moment + tip.x * world[1] - tip.y * world[0];
            assert!(moment.abs() < 1e-9, "{a:?}: {moment}");
        }
    }
}
