//! A coarse atlas of stable rods indexed by their tip, to start the robust solver near a
//! solution.
//!
//! Built once per process (lazily, [`std::sync::OnceLock`]) from rays of the weighted scaling
//! a(s) = (s a3, s² a4, s² a5): the rod a restricted to [0, s] and rescaled to unit length is
//! the rod a(s), so its tip is (x(s)/s, y(s)/s, θ(s)) and it is stable iff det J(τ, a) > 0 for
//! τ ≤ s (FINDINGS §5). One RK4 integration of a ray end-point with its variational equations
//! therefore yields a whole family of stable rods and their tips, up to the first conjugate
//! point. The ray end-points are a low-discrepancy (Halton) sample of a box somewhat larger than
//! the public box |a3| ≤ 10, |a4|, |a5| ≤ 100.
//!
//! The target space (x, y, θ mod 2π) is cut into cells; each cell keeps a few seeds of distinct
//! solution branches (parameters far apart), the one nearest the cell centre per branch.

use super::scan;
use crate::{wrap_angle, PlanarParams, PlanarPose};
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

/// Cells per unit of x and y (x, y ∈ [−1, 1]).
const NXY: usize = 40;
/// Cells in θ ∈ [−π, π).
const NT: usize = 40;
/// Seeds kept per cell.
const K: usize = 4;
/// Ray end-points.
const RAYS: usize = 8000;
/// RK4 steps per ray.
const STEPS: usize = 200;
/// Half-widths of the end-point box.
const A3_MAX: f64 = 14.0;
const A45_MAX: f64 = 150.0;
/// Weight of the angle in the target-space distance.
pub(crate) const W_THETA: f64 = 0.5;

#[derive(Clone, Copy, Debug)]
pub(crate) struct Seed {
    pub a: [f64; 3],
    pub tip: [f64; 3], // x, y, wrapped θ
}

pub(crate) struct Atlas {
    /// Cell start offsets into `seeds` (len = cells + 1).
    offsets: Vec<u32>,
    seeds: Vec<Seed>,
}

static ATLAS: OnceLock<Atlas> = OnceLock::new();

/// The atlas, built on first use.
pub(crate) fn get() -> &'static Atlas {
    ATLAS.get_or_init(build)
}

#[inline]
fn cell_of(x: f64, y: f64, th: f64) -> Option<(usize, usize, usize)> {
    let fx = ((x + 1.0) * 0.5 * NXY as f64).floor();
    let fy = ((y + 1.0) * 0.5 * NXY as f64).floor();
    let ft = ((wrap_angle(th) + PI) / TAU * NT as f64).floor();
    if !(fx >= 0.0 && fx < NXY as f64 && fy >= 0.0 && fy < NXY as f64 && ft.is_finite()) {
        return None;
    }
    let it = (ft as i64).rem_euclid(NT as i64) as usize;
    Some((fx as usize, fy as usize, it))
}

#[inline]
fn index(ix: usize, iy: usize, it: usize) -> usize {
    (ix * NXY + iy) * NT + it
}

fn centre(ix: usize, iy: usize, it: usize) -> [f64; 3] {
    [
        (ix as f64 + 0.5) * 2.0 / NXY as f64 - 1.0,
        (iy as f64 + 0.5) * 2.0 / NXY as f64 - 1.0,
        (it as f64 + 0.5) * TAU / NT as f64 - PI,
    ]
}

#[inline]
pub(crate) fn tip_distance2(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    let dx = p[0] - q[0];
    let dy = p[1] - q[1];
    let dt = W_THETA * wrap_angle(p[2] - q[2]);
    dx * dx + dy * dy + dt * dt
}

/// Same solution branch (for keeping distinct seeds in a cell).
fn same_branch(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (a[0] - b[0]).abs() / 2.0 + (a[1] - b[1]).abs() / 20.0 + (a[2] - b[2]).abs() / 20.0 < 1.0
}

/// Radical inverse in base `b` (Halton sequence).
fn halton(mut i: u64, b: u64) -> f64 {
    let mut f = 1.0;
    let mut r = 0.0;
    let bf = b as f64;
    while i > 0 {
        f /= bf;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

fn build() -> Atlas {
    let ncells = NXY * NXY * NT;
    let mut cells: Vec<Vec<(Seed, f64)>> = vec![Vec::new(); ncells];
    let mut buf: Vec<(f64, f64, f64, f64)> = Vec::with_capacity(STEPS);
    for i in 0..RAYS as u64 {
        let a = PlanarParams::new(
            (2.0 * halton(i + 1, 2) - 1.0) * A3_MAX,
            (2.0 * halton(i + 1, 3) - 1.0) * A45_MAX,
            (2.0 * halton(i + 1, 5) - 1.0) * A45_MAX,
        );
        buf.clear();
        let mut t1 = f64::INFINITY;
        let ok = scan::integrate(&a, STEPS, |t, x, y, th, det| {
            if t >= 0.02 && det <= 0.0 {
                t1 = t;
                return false;
            }
            buf.push((t, x, y, th));
            true
        });
        if ok.is_none() {
            continue;
        }
        for &(t, x, y, th) in buf.iter() {
            // Keep a margin from the first conjugate point (seeds deep inside A_stable).
            if t < 0.05 || t > 0.93 * t1 {
                continue;
            }
            let tip = [x / t, y / t, wrap_angle(th)];
            let Some((ix, iy, it)) = cell_of(tip[0], tip[1], tip[2]) else {
                continue;
            };
            let seed = Seed {
                a: [t * a[0], t * t * a[1], t * t * a[2]],
                tip,
            };
            let d = tip_distance2(&tip, &centre(ix, iy, it));
            let cell = &mut cells[index(ix, iy, it)];
            if let Some(slot) = cell.iter_mut().find(|(s, _)| same_branch(&s.a, &seed.a)) {
                if d < slot.1 {
                    *slot = (seed, d);
                }
            } else if cell.len() < K {
                cell.push((seed, d));
            } else if let Some(worst) = cell
                .iter_mut()
                .max_by(|p, q| p.1.total_cmp(&q.1))
                .filter(|w| d < w.1)
            {
                *worst = (seed, d);
            }
        }
    }
    let mut offsets = Vec::with_capacity(ncells + 1);
    let mut seeds = Vec::new();
    for c in cells {
        offsets.push(seeds.len() as u32);
        seeds.extend(c.into_iter().map(|(s, _)| s));
    }
    offsets.push(seeds.len() as u32);
    Atlas { offsets, seeds }
}

impl Atlas {
    /// Number of seeds.
    pub(crate) fn len(&self) -> usize {
        self.seeds.len()
    }

    fn cell(&self, i: usize) -> &[Seed] {
        let lo = self.offsets[i] as usize;
        let hi = self.offsets[i + 1] as usize;
        &self.seeds[lo..hi]
    }

    /// Seeds in the cells within `radius` cells of the target's cell (θ periodic), sorted by
    /// tip distance to the target, appended to `out` as (distance², a).
    pub(crate) fn candidates(
        &self,
        target: &PlanarPose,
        radius: usize,
        out: &mut Vec<(f64, PlanarParams)>,
    ) {
        let tgt = [target.x, target.y, wrap_angle(target.theta)];
        let Some((ix, iy, it)) = cell_of(tgt[0], tgt[1], tgt[2]) else {
            return;
        };
        let r = radius as i64;
        let start = out.len();
        for dx in -r..=r {
            let jx = ix as i64 + dx;
            if jx < 0 || jx >= NXY as i64 {
                continue;
            }
            for dy in -r..=r {
                let jy = iy as i64 + dy;
                if jy < 0 || jy >= NXY as i64 {
                    continue;
                }
                for dt in -r..=r {
                    if 2 * r + 1 > NT as i64 && dt > -r + NT as i64 - 1 {
                        break;
                    }
                    let jt = (it as i64 + dt).rem_euclid(NT as i64) as usize;
                    for s in self.cell(index(jx as usize, jy as usize, jt)) {
                        out.push((tip_distance2(&s.tip, &tgt), PlanarParams::from(s.a)));
                    }
                }
            }
        }
        out[start..].sort_by(|p, q| p.0.total_cmp(&q.0));
    }
}

/// The atlas seed nearest `target` in tip space (searching up to 3 cells away).
pub(crate) fn nearest(target: &PlanarPose) -> Option<PlanarParams> {
    let atlas = get();
    let mut v = Vec::new();
    for r in 0..=3 {
        v.clear();
        atlas.candidates(target, r, &mut v);
        if let Some(&(_, a)) = v.first() {
            return Some(a);
        }
    }
    None
}
