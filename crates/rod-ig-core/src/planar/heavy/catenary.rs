//! A long cable's shape before any solve: the catenary through the grippers with a tension
//! boundary layer at each clamp (matched asymptotics, docs/weight.md "The catenary seed").
//!
//! For w ≫ 1 a heavy rod held at both ends is, away from its ends, a perfect cable: its
//! internal force is along its tangent, n(t) = T(t) (cos θ, sin θ), and with n(t) = n(0) − w t ĝ
//! the tangent angle is θ_c(t) = atan2(V₀ + w t, H) in the frame where gravity points along −y.
//! Its chord fixes (H, V₀): with z = w X / (2H) (X the horizontal chord, Y the vertical one,
//! arc length 1), sinh z / z = √(1 − Y²) / X and sinh m = Y z / (X sinh z), V₀ = H sinh(m − z).
//! Near a clamp the bending stiffness turns the tangent from θ_c to the clamp's angle within
//! ℓ = 1/√T: the elastica under a uniform tension T, θ'' = T sin(θ − φ), whose decaying
//! solution is θ − φ = 4 atan(tan(Δ/4) e^{−s √T}). The seed is the catenary's angle plus
//! both layers; its node states (angle, curvature, positions integrated from the angle) start
//! Newton on the multiple-shooting equations at the full weight, with no continuation in w.

use super::cable::Cable;
use super::Gravity;
use crate::{wrap_angle, PlanarPose, RodError};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Sub-intervals per segment of the quadrature that integrates the seed's positions.
const QUADRATURE_STEPS: usize = 16;
/// Horizontal chords shorter than this have no catenary worth seeding from (a vertical chord:
/// the cable folds on itself).
const MIN_HORIZONTAL_CHORD: f64 = 1e-6;

/// The catenary of unit length through (0, 0) and (x, y), gravity along −y, weight w:
/// n(t) = (h_signed, v0 + w t).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Catenary {
    /// Horizontal force, signed as the chord's x.
    horizontal: f64,
    /// Vertical force at the base.
    v0: f64,
    weight: f64,
    /// An arch: the rod is compressed, its tangent along −n (else a hanging cable, along n).
    compressed: bool,
}

impl Catenary {
    /// The catenary through (x, y) (module docs), or `None` when there is none: the chord is
    /// not shorter than the cable, or vertical.
    fn through(x: f64, y: f64, weight: f64) -> Option<Self> {
        let span = x.abs();
        if !(span > MIN_HORIZONTAL_CHORD) || !(x.hypot(y) < 1.0) || !(weight > 0.0) {
            return None;
        }
        let q = (1.0 - y * y).sqrt() / span;
        let z = sinhc_inverse(q)?;
        let h = weight * span / (2.0 * z);
        let m = (y * z / (span * z.sinh())).asinh();
        let v0 = h * (m - z).sinh();
        (h.is_finite() && v0.is_finite()).then_some(Self {
            horizontal: h.copysign(x),
            v0,
            weight,
            compressed: false,
        })
    }

    /// The internal force at t.
    fn force(&self, t: f64) -> [f64; 2] {
        [self.horizontal, self.v0 + self.weight * t]
    }

    /// θ_c(t).
    fn angle(&self, t: f64) -> f64 {
        let n = self.force(t);
        // Continuous along the rod: with H < 0 the force turns through the −x axis, where
        // atan2 jumps by 2π; there the angle is taken in (π/2, 3π/2).
        let along = if n[0] >= 0.0 {
            n[1].atan2(n[0])
        } else {
            PI - n[1].atan2(-n[0])
        };
        if self.compressed {
            along + PI
        } else {
            along
        }
    }

    /// θ_c'(t) = H w / (H² + V(t)²).
    fn curvature(&self, t: f64) -> f64 {
        let n = self.force(t);
        self.horizontal * self.weight / (n[0] * n[0] + n[1] * n[1])
    }

    /// The tension |n(t)|.
    fn tension(&self, t: f64) -> f64 {
        let n = self.force(t);
        n[0].hypot(n[1])
    }
}

/// The z > 0 with sinh z / z = q (q > 1), by Newton on ln(sinh z / z) − ln q (increasing and
/// convex in z), from a start above the root.
fn sinhc_inverse(q: f64) -> Option<f64> {
    if !(q > 1.0) || !q.is_finite() {
        return None;
    }
    // sinh z / z ≥ 1 + z²/6 and ≥ e^z / (4z) (z ≥ 1/2), so both √(6(q − 1)) and
    // 2 ln(4q) + 1 are above the root: Newton on an increasing convex function converges from
    // above monotonically.
    let mut z = (6.0 * (q - 1.0)).sqrt().min(2.0 * (4.0 * q).ln() + 1.0);
    let log_sinhc = |z: f64| {
        if z < 1e-2 {
            z * z / 6.0 - z.powi(4) / 180.0
        } else {
            // ln sinh z without overflow: z + ln((1 − e^{−2z}) / 2).
            z + (-(-2.0 * z).exp_m1() / 2.0).ln() - z.ln()
        }
    };
    for _ in 0..200 {
        let f = log_sinhc(z) - q.ln();
        let df = if z < 1e-2 {
            z / 3.0 - z.powi(3) / 45.0
        } else {
            1.0 / z.tanh() - 1.0 / z
        };
        let step = f / df;
        if !(step.is_finite()) {
            return None;
        }
        z -= step;
        if !(z > 0.0) {
            return None;
        }
        if step.abs() <= 1e-12 * z || f.abs() <= 1e-15 * q.ln() {
            return Some(z);
        }
    }
    None
}

/// A tension boundary layer: the angle θ − φ = 4 atan(A e^{−s/ℓ}) and its derivative in s,
/// s the distance from the clamp.
#[derive(Clone, Copy, Debug)]
struct Layer {
    amplitude: f64,
    rate: f64,
}

impl Layer {
    /// The layer that turns the tangent by `turn` ∈ (−π, π] under tension `tension`.
    fn new(turn: f64, tension: f64) -> Self {
        Self {
            amplitude: (turn / 4.0).tan(),
            rate: tension.sqrt(),
        }
    }

    fn angle(&self, s: f64) -> f64 {
        4.0 * (self.amplitude * (-s * self.rate).exp()).atan()
    }

    /// d/ds of [`Layer::angle`].
    fn slope(&self, s: f64) -> f64 {
        let e = self.amplitude * (-s * self.rate).exp();
        -4.0 * self.rate * e / (1.0 + e * e)
    }
}

/// The seed's angle and curvature along the rod, base frame.
struct SeedShape {
    catenary: Catenary,
    base: Layer,
    tip: Layer,
    /// Base-frame angle = gravity-frame angle − this.
    rotation: f64,
}

impl SeedShape {
    fn state(&self, t: f64) -> (f64, f64) {
        let theta =
            self.catenary.angle(t) + self.base.angle(t) + self.tip.angle(1.0 - t) - self.rotation;
        let kappa = self.catenary.curvature(t) + self.base.slope(t) - self.tip.slope(1.0 - t);
        (theta, kappa)
    }
}

/// The cable, both ends clamped, whose node states are the catenary through `target` with its
/// two tension layers (module docs), and the target lifted to the seed's tip angle; `None`
/// when there is no such catenary (the chord is not shorter than the cable, or vertical).
pub fn seed(
    target: &PlanarPose,
    gravity: &Gravity,
) -> Result<Option<(Cable, PlanarPose)>, RodError> {
    let frame = GravityFrame::of(gravity);
    let (x, y) = frame.to_gravity([target.x, target.y]);
    Catenary::through(x, y, gravity.weight())
        .map(|c| seeded(c, frame, target, gravity))
        .transpose()
}

/// The seed of [`seed`] with the base force n(0) = `force` (base frame) in place of the
/// chord's catenary: the perfect cable whose tangent follows n(t) = n(0) − w t ĝ, with its two
/// layers. A start for Newton from a caller's `a0` at large w, whose own integration from the
/// base has lost its digits; the tip of the seed is wherever that cable ends.
pub fn seed_with_force(
    force: [f64; 2],
    target: &PlanarPose,
    gravity: &Gravity,
) -> Result<Option<(Cable, PlanarPose)>, RodError> {
    let frame = GravityFrame::of(gravity);
    let (horizontal, v0) = frame.to_gravity(force);
    if !(horizontal.abs() > 0.0) || !v0.is_finite() || !(gravity.weight() > 0.0) {
        return Ok(None);
    }
    // The rod is taken compressed (an arch) when its mid-length force points against the
    // chord, along which a perfect cable's tangent runs there.
    let mid = force_at_mid(force, gravity);
    let c = Catenary {
        horizontal,
        v0,
        weight: gravity.weight(),
        compressed: mid[0] * target.x + mid[1] * target.y < 0.0,
    };
    seeded(c, frame, target, gravity).map(Some)
}

/// n(½) = n(0) − w ĝ / 2.
fn force_at_mid(force: [f64; 2], gravity: &Gravity) -> [f64; 2] {
    let l = gravity.load();
    [force[0] - 0.5 * l[0], force[1] - 0.5 * l[1]]
}

/// The rotation between the base frame and the frame where gravity points along −y.
#[derive(Clone, Copy, Debug)]
struct GravityFrame {
    /// Base-frame angle + this = gravity-frame angle.
    rotation: f64,
    sin: f64,
    cos: f64,
}

impl GravityFrame {
    fn of(gravity: &Gravity) -> Self {
        let g = gravity.direction();
        let rotation = -FRAC_PI_2 - g[1].atan2(g[0]);
        let (sin, cos) = rotation.sin_cos();
        Self { rotation, sin, cos }
    }

    fn to_gravity(self, v: [f64; 2]) -> (f64, f64) {
        (
            self.cos * v[0] - self.sin * v[1],
            self.sin * v[0] + self.cos * v[1],
        )
    }

    fn to_base(self, v: [f64; 2]) -> [f64; 2] {
        [
            self.cos * v[0] + self.sin * v[1],
            -self.sin * v[0] + self.cos * v[1],
        ]
    }
}

/// The cable of `catenary` with a layer at each clamp (the base's angle 0, the tip's
/// `target.theta`), and the target lifted to its tip angle.
fn seeded(
    catenary: Catenary,
    frame: GravityFrame,
    target: &PlanarPose,
    gravity: &Gravity,
) -> Result<(Cable, PlanarPose), RodError> {
    let rotation = frame.rotation;
    let base_turn = wrap_angle(rotation - catenary.angle(0.0));
    let tip_turn = wrap_angle(target.theta + rotation - catenary.angle(1.0));
    let mut shape = SeedShape {
        catenary,
        base: Layer::new(base_turn, catenary.tension(0.0)),
        tip: Layer::new(tip_turn, catenary.tension(1.0)),
        rotation,
    };
    // The angles are found modulo 2π: the clamped base's is 0 exactly, not 2π k.
    shape.rotation += TAU * (shape.state(0.0).0 / TAU).round();
    let force = frame.to_base(catenary.force(0.0));
    let cable = Cable::from_states(gravity, force, |t| shape.state(t), QUADRATURE_STEPS)?;
    let lifted = super::cable::lift_near(target, shape.state(1.0).0);
    Ok((cable, lifted))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_catenary_passes_through_its_chord() {
        for &(x, y, w) in &[
            (0.8, 0.0, 2000.0),
            (0.5, -0.3, 300.0),
            (-0.6, 0.4, 1e4),
            (0.01, 0.2, 500.0),
        ] {
            let c = Catenary::through(x, y, w).unwrap();
            // Integrate the unit tangent n/|n| by Simpson on a fine grid.
            let k = 20_000;
            let (mut px, mut py) = (0.0, 0.0);
            for i in 0..k {
                let (a, b) = (i as f64 / k as f64, (i + 1) as f64 / k as f64);
                for (wgt, t) in [(1.0, a), (4.0, 0.5 * (a + b)), (1.0, b)] {
                    let th = c.angle(t);
                    px += wgt * th.cos() / (6.0 * k as f64);
                    py += wgt * th.sin() / (6.0 * k as f64);
                }
            }
            assert!(
                (px - x).abs() < 1e-6 && (py - y).abs() < 1e-6,
                "{x} {y} {w}: {px} {py}"
            );
        }
        assert!(Catenary::through(0.0, 0.5, 100.0).is_none());
        assert!(Catenary::through(1.0, 0.0, 100.0).is_none());
        assert!(Catenary::through(f64::NAN, 0.0, 100.0).is_none());
    }

    #[test]
    fn sinhc_inverse_is_an_inverse() {
        for &q in &[1.0 + 1e-12, 1.0001, 1.5, 10.0, 1e6, 1e300] {
            let z = sinhc_inverse(q).unwrap();
            let back = if z < 700.0 {
                z.sinh() / z
            } else {
                f64::INFINITY
            };
            assert!(
                ((back / q).ln()).abs() < 1e-9 || q > 1e250,
                "{q}: {z} {back}"
            );
        }
        assert!(sinhc_inverse(1.0).is_none());
        assert!(sinhc_inverse(f64::NAN).is_none());
    }

    /// The seed alone puts Newton at the full weight within its basin for the level cable
    /// (no continuation): ≤ 8 iterations from w = 200 to 10⁴, d = 0.5 … 0.95, to the hanging
    /// rod, stable, whose grippers each hold half of the weight (a5 = −w/2: the mirror
    /// symmetry, exact); at w = 2,000, d = 0.8, its sag is the reference 0.2676.
    #[test]
    fn newton_from_the_seed_finds_the_hanging_cable() {
        for w in [200.0, 2_000.0, 1e4] {
            for d in [0.5, 0.8, 0.95] {
                let g = Gravity::new(w, [0.0, -1.0]).unwrap();
                let (mut c, lifted) = seed(&PlanarPose::new(d, 0.0, 0.0), &g).unwrap().unwrap();
                let it = c.solve(&lifted).unwrap();
                assert!(it <= 8, "w {w} d {d}: {it} iterations");
                assert!(c.second_variation().unwrap().stable());
                assert!(
                    (c.params()[2] + w / 2.0).abs() < 1e-9 * w,
                    "{:?}",
                    c.params()
                );
                if w == 2_000.0 && d == 0.8 {
                    let sag = c
                        .shape(2001)
                        .unwrap()
                        .iter()
                        .map(|p| -p.y)
                        .fold(0.0, f64::max);
                    assert!((sag - 0.2676).abs() < 5e-5, "sag {sag}");
                }
            }
        }
    }

    /// Gravity turned all around the level cable (w = 2,000, 0.8 apart): the seed puts Newton
    /// within its basin whatever the direction (≤ 8 iterations, measured 4–6), also where the
    /// catenary's horizontal force is negative (gravity with a +y component: its angle passes
    /// through ±π, and the base's comes out as 2π; before both were handled, every such
    /// direction failed and the search fell back to its slower starts).
    #[test]
    fn the_seed_holds_for_every_gravity_direction() {
        for k in 0..16 {
            let psi = k as f64 * std::f64::consts::PI / 8.0;
            let g = Gravity::new(2_000.0, [psi.cos(), psi.sin()]).unwrap();
            let target = PlanarPose::new(0.8, 0.0, 0.0);
            let Some((mut c, lifted)) = seed(&target, &g).unwrap() else {
                // Gravity along the chord: a vertical chord, no catenary.
                assert!(psi.sin().abs() < 1e-12, "ψ = {psi}");
                continue;
            };
            let it = c
                .solve(&lifted)
                .unwrap_or_else(|e| panic!("ψ = {psi}: {e}"));
            assert!(it <= 8, "ψ = {psi}: {it} iterations");
            assert!(c.second_variation().unwrap().stable(), "ψ = {psi}");
        }
    }

    /// Gravity in any direction and a tilted tip: the seed's rod is an equilibrium on target
    /// after Newton, and a vertical chord has no catenary (`None`, not an error).
    #[test]
    fn the_seed_follows_gravity_and_declines_vertical_chords() {
        let g = Gravity::new(3_000.0, [0.6, -0.8]).unwrap();
        let target = PlanarPose::new(0.5, -0.4, -0.7);
        let (mut c, lifted) = seed(&target, &g).unwrap().unwrap();
        c.solve(&lifted).unwrap();
        let tip = c.tip().unwrap();
        assert!((tip.x - 0.5).abs() < 1e-10 && (tip.y + 0.4).abs() < 1e-10);
        assert!(crate::wrap_angle(tip.theta + 0.7).abs() < 1e-10);
        let down = Gravity::new(500.0, [0.0, -1.0]).unwrap();
        assert!(seed(&PlanarPose::new(0.0, -0.5, 0.0), &down)
            .unwrap()
            .is_none());
    }
}
