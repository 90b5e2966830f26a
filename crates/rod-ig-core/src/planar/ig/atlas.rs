//! A coarse atlas of stable rods indexed by their tip, to start the robust solver near a
//! solution.
//!
//! Built once per process, lazily and in deadline-bounded steps ([`get`]), from rays of the weighted scaling
//! a(s) = (s a3, s² a4, s² a5): the rod a restricted to [0, s] and rescaled to unit length is
//! the rod a(s), so its tip is (x(s)/s, y(s)/s, θ(s)) and it is stable iff det J(τ, a) > 0 for
//! τ ≤ s (docs/math.md §5). One RK4 integration of a ray end-point with its variational equations
//! therefore yields a whole family of stable rods and their tips, up to the first conjugate
//! point. The ray end-points are a low-discrepancy (Halton) sample of a box somewhat larger than
//! the public box |a3| ≤ 10, |a4|, |a5| ≤ 100.
//!
//! The target space (x, y, θ mod 2π) is cut into cells; each cell keeps a few seeds of distinct
//! solution branches (parameters far apart), the one nearest the cell centre per branch.

use super::scan;
use crate::{wrap_angle, PlanarParams, PlanarPose};
use nalgebra::{Matrix3, Vector3};
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Cells per unit of x and y (x, y ∈ [−1, 1]).
const NXY: usize = 40;
/// Cells in θ ∈ [−π, π).
const NT: usize = 40;
/// Length of the per-cell short lists.
const NEAR: usize = 6;
/// Largest |a3| of any atlas seed (the beyond-the-box tier's rays).
pub(crate) const SEED_A3_MAX: f64 = 36.0;
/// Largest |a4|, |a5| of any atlas seed.
pub(crate) const SEED_A45_MAX: f64 = 300.0;

/// Which atlas: the paper's box, which every robust solve uses, or the shell beyond it, built
/// only when a solve needs it (issue 42: 13 % of reachable workspace targets have stable rods
/// only beyond the box, |a3| up to ~30, |F| up to ~500, too sensitive for a start inside it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tier {
    /// Rays of |a3| ≤ 14, |a4|, |a5| ≤ 150 (somewhat larger than the public box).
    Box,
    /// Rays of |a3| ≤ 36, |a4|, |a5| ≤ 300 (and twice as many near the separatrix),
    /// seeds kept only outside the first tier's box.
    Beyond,
}

/// How a tier's rays are drawn and integrated.
struct Spec {
    /// Ray end-points, a Halton sample of the box.
    rays: usize,
    /// Ray end-points near the separatrix λ4 = 0.
    separatrix_rays: usize,
    /// Their relative offsets from it: log-uniform over this many decades below 1.
    separatrix_decades: f64,
    /// RK4 steps per ray, at least...
    steps: usize,
    /// ... this many per unit of the ray's curvature scale max(|a3|, √‖F‖), so that h |a3|
    /// and h √‖F‖ stay ≲ 0.1 on the long rays beyond the box (0: `steps` alone).
    steps_per_scale: f64,
    /// Half-widths of the end-point box.
    a3_max: f64,
    a45_max: f64,
    /// Seeds (distinct branches) kept per cell.
    per_cell: usize,
    /// Seeds inside this box (a3, a4 and a5 half-widths) are left to the tier that has them.
    inner: Option<(f64, f64)>,
}

impl Tier {
    fn spec(self) -> &'static Spec {
        match self {
            Tier::Box => &Spec {
                rays: 8000,
                separatrix_rays: 8000,
                separatrix_decades: 6.0,
                steps: 128,
                steps_per_scale: 0.0,
                a3_max: 14.0,
                a45_max: 150.0,
                per_cell: 4,
                inner: None,
            },
            Tier::Beyond => &Spec {
                rays: 16000,
                // The last stable rods it missed lie 3e-7 (relative) from the separatrix with
                // |J(1, a)| ~ 2e5 and no Newton basin 1e-4 wide: reached only from seeds on
                // their own ray. 9 decades and twice the rays found 6 more of 2,600 workspace
                // targets; 3× found 10 more but its build peaks past a `track` stream's 64 MB
                // bound (76 MB; 57 MB with 2×); 6× found none more than 3×.
                separatrix_rays: 32000,
                separatrix_decades: 9.0,
                steps: 128,
                steps_per_scale: 10.0,
                a3_max: SEED_A3_MAX,
                a45_max: SEED_A45_MAX,
                per_cell: 6,
                inner: Some((14.0, 150.0)),
            },
        }
    }

    fn index(self) -> usize {
        self as usize
    }

    /// Chunks of rays.
    fn chunks(self) -> usize {
        let spec = self.spec();
        (spec.rays + spec.separatrix_rays).div_ceil(RAYS_PER_CHUNK)
    }
}
/// Weight of the angle in the target-space distance.
pub(crate) const W_THETA: f64 = 0.5;

#[derive(Clone, Copy, Debug)]
pub(crate) struct Seed {
    pub a: [f64; 3],
    pub tip: [f64; 3], // x, y, wrapped θ
    /// J(1, a)⁻¹ (from the ray's RK4 variational solution), for a free first Newton step.
    pub jinv: Matrix3<f64>,
}

/// A start proposed by the atlas: the seed, and the Newton step from it toward the target
/// computed with the stored J⁻¹ (paper eq. 3.1), with the seed's residual norm.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Start {
    pub a: PlanarParams,
    pub predicted: Option<(PlanarParams, f64)>,
}

pub(crate) struct Atlas {
    /// Cell start offsets into `seeds` (len = cells + 1).
    offsets: Vec<u32>,
    seeds: Vec<Seed>,
    /// Per cell, offsets into `near` (len = cells + 1).
    near_offsets: Vec<u32>,
    /// Per cell, the indices of the NEAR seeds nearest its centre in its neighbourhood.
    near: Vec<u32>,
}

static ATLASES: [OnceLock<Atlas>; 2] = [OnceLock::new(), OnceLock::new()];

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
pub(crate) fn same_branch(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (a[0] - b[0]).abs() / 2.0 + (a[1] - b[1]).abs() / 20.0 + (a[2] - b[2]).abs() / 20.0 < 1.0
}

/// A ray end-point near the separatrix λ4 = a5² − a3²(a3²/4 + a4) = 0 (docs/math.md §1–2:
/// the boundary between cases I and II, where m → 1 and the tip depends on a so sharply that
/// uniform sampling leaves its neighbourhood without seeds). λ4 scales as s⁴ along a ray, so the
/// whole ray stays at the same relative offset from the separatrix. Offsets are log-uniform.
fn separatrix_endpoint(spec: &Spec, i: u64) -> Option<PlanarParams> {
    // a3 denser near 0 (nearly straight, tensioned rods are the most sensitive there).
    let w = 2.0 * halton(i, 2) - 1.0;
    let a3 = w * w.abs() * spec.a3_max;
    let a4 = (2.0 * halton(i, 3) - 1.0) * spec.a45_max;
    let base = a3 * a3 * (a3 * a3 / 4.0 + a4);
    let u = halton(i, 5);
    let v = halton(i, 7);
    // Relative offset ±10^(−decades..0) of the scale a3⁴/4 + |a4| a3² (+1 to stay away from 0).
    let scale = a3 * a3 * (a3 * a3 / 4.0 + a4.abs()) + 1.0;
    let sign = if v < 0.5 { -1.0 } else { 1.0 };
    let l4 = sign * scale * 10f64.powf(-spec.separatrix_decades * u);
    let a5sq = base + l4;
    if a5sq.is_nan() || a5sq <= 0.0 {
        return None;
    }
    let a5 = a5sq.sqrt() * if (2.0 * v).fract() < 0.5 { -1.0 } else { 1.0 };
    (a5.abs() <= spec.a45_max).then(|| PlanarParams::new(a3, a4, a5))
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

/// Rays integrated per chunk of the build (≈ 0.5 ms of work: the granularity at which a
/// request's deadline is polled while the atlas is being built).
const RAYS_PER_CHUNK: usize = 32;
/// A piece of work still missing this long after it was handed out is handed out again.
const LOST_WORK: Duration = Duration::from_millis(200);
/// Cells whose seeds one piece of the gathering moves into the atlas (one x slab, ≈ 0.5 ms):
/// gathered at once, the ~10 MB of seeds took 19 ms under the lock, past the deadline of the
/// request that filed the last chunk.
const CELLS_PER_GATHER: usize = NXY * NT;

/// The atlas under construction, in three phases of small pieces: chunks of rays integrated
/// into seeds, the seeds gathered in cell order by x slab, then the cells' short lists by x
/// slab. The request that triggers the build is charged only the pieces its deadline allows
/// (issue 24: no request answers later than its deadline) and the next request resumes;
/// threads that need the atlas build it together, each computing the pieces it claims outside
/// the lock (the gathering's pieces under it). Seeds are filed in ray order whatever thread
/// computed them, so the atlas is the same on every run.
struct Builder {
    /// [`Tier::chunks`].
    chunks: usize,
    /// [`Spec::per_cell`].
    per_cell: usize,
    cells: Vec<Vec<(Seed, f64)>>,
    /// Pieces handed out so far: chunks 0..chunks, then slabs (the gathering between them is
    /// done by whichever thread asks next, under the lock).
    handed_out: usize,
    /// When each piece was (last) handed out.
    handed_at: Vec<Instant>,
    /// Chunks computed but not yet filed (waiting for an earlier one).
    pending: BTreeMap<usize, Vec<Seed>>,
    /// Chunks filed, in order.
    filed: usize,
    /// The seeds being gathered in cell order once every chunk is filed, and the next cell.
    gathering: Option<(Atlas, usize)>,
    /// The seeds and cell offsets once they are gathered (short lists still empty).
    seeded: Option<Arc<Atlas>>,
    /// Short lists per slab, as they are computed.
    slabs: Vec<Option<SlabLists>>,
}

/// The short lists of one x slab: per cell (in index order) its length, and the seed indices.
struct SlabLists {
    lengths: Vec<u32>,
    near: Vec<u32>,
}

static BUILDERS: [Mutex<Option<Builder>>; 2] = [Mutex::new(None), Mutex::new(None)];

/// How long a thread waits for pieces other threads are computing before it asks again.
const WAIT: Duration = Duration::from_micros(50);

/// What a thread does next for the build.
enum Step {
    Chunk(usize),
    /// The next piece of the gathering ([`Builder::gather_piece`], under the lock).
    Gather,
    Slab(usize, Arc<Atlas>),
    /// Another thread computes the pieces still missing.
    Wait,
    Done(Atlas),
}

/// The atlas, built on first use within the current deadline ([`crate::deadline`]) on every
/// core: `None` when the deadline passes first. The work done is kept and resumed by the next
/// call; threads calling it together share the build (each polls the deadline between pieces
/// of ≈ 0.5 ms).
pub(crate) fn get(tier: Tier) -> Option<&'static Atlas> {
    if let Some(atlas) = ATLASES[tier.index()].get() {
        return Some(atlas);
    }
    let deadline = crate::deadline::handoff();
    let helpers = std::thread::available_parallelism().map_or(1, |n| n.get()) - 1;
    std::thread::scope(|scope| {
        for _ in 0..helpers {
            scope.spawn(move || {
                let _deadline = deadline.enter();
                build(tier)
            });
        }
        build(tier)
    })
}

/// Builds pieces of the atlas until it is complete or the deadline passes.
fn build(tier: Tier) -> Option<&'static Atlas> {
    let slot = &ATLASES[tier.index()];
    loop {
        if let Some(atlas) = slot.get() {
            return Some(atlas);
        }
        if crate::deadline::expired() {
            return None;
        }
        let work = {
            let mut guard = lock_builder(tier);
            if slot.get().is_some() {
                continue;
            }
            let work = guard.get_or_insert_with(|| Builder::new(tier)).next_work();
            if matches!(work, Step::Done(_)) {
                *guard = None;
            }
            work
        };
        // Each piece is charged before it is done (the deadline polled between pieces).
        crate::deadline::charge(match work {
            Step::Wait => WAIT.as_micros() as u64,
            Step::Done(_) => 0,
            _ => crate::deadline::units::ATLAS_PIECE,
        });
        match work {
            Step::Chunk(c) => {
                let seeds = chunk_seeds(tier, c);
                if let Some(b) = lock_builder(tier).as_mut() {
                    b.file_chunk(c, seeds);
                }
            }
            Step::Gather => {
                if let Some(b) = lock_builder(tier).as_mut() {
                    b.gather_piece();
                }
            }
            Step::Slab(ix, seeded) => {
                let lists = seeded.short_lists(ix);
                if let Some(b) = lock_builder(tier).as_mut() {
                    b.slabs[ix].get_or_insert(lists);
                }
            }
            Step::Wait => std::thread::sleep(WAIT),
            Step::Done(atlas) => {
                let _ = slot.set(atlas);
            }
        }
    }
}

/// The builder's lock. A panic in another thread leaves a consistent state (a piece handed
/// out and never delivered is handed out again, [`Builder::next_work`]).
fn lock_builder(tier: Tier) -> std::sync::MutexGuard<'static, Option<Builder>> {
    BUILDERS[tier.index()]
        .lock()
        .unwrap_or_else(|p| p.into_inner())
}

/// The atlas, built now if needed whatever the time it takes (no deadline applies).
pub(crate) fn get_blocking(tier: Tier) -> &'static Atlas {
    let _unbounded = crate::deadline::unbounded();
    loop {
        if let Some(atlas) = get(tier) {
            return atlas;
        }
    }
}

impl Builder {
    fn new(tier: Tier) -> Self {
        let chunks = tier.chunks();
        Self {
            chunks,
            per_cell: tier.spec().per_cell,
            cells: vec![Vec::new(); NXY * NXY * NT],
            handed_out: 0,
            handed_at: Vec::with_capacity(chunks + NXY),
            pending: BTreeMap::new(),
            filed: 0,
            gathering: None,
            seeded: None,
            slabs: (0..NXY).map(|_| None).collect(),
        }
    }

    /// The next piece of work.
    fn next_work(&mut self) -> Step {
        let now = Instant::now();
        if self.handed_out < self.chunks {
            return self.hand_out(now);
        }
        if self.filed < self.chunks {
            return self.missing(self.filed, now, Step::Chunk(self.filed));
        }
        let Some(seeded) = self.seeded.clone() else {
            return if self.gathering.is_some() {
                Step::Gather
            } else {
                Step::Wait
            };
        };
        if self.handed_out < self.chunks + NXY {
            let ix = self.handed_out - self.chunks;
            self.hand_out(now);
            return Step::Slab(ix, seeded);
        }
        if let Some(ix) = self.slabs.iter().position(Option::is_none) {
            return self.missing(self.chunks + ix, now, Step::Slab(ix, seeded));
        }
        Step::Done(self.assemble(seeded))
    }

    fn hand_out(&mut self, now: Instant) -> Step {
        self.handed_at.push(now);
        self.handed_out += 1;
        Step::Chunk(self.handed_out - 1)
    }

    /// Piece `id` is handed out but not delivered: `again` if its thread seems to have died
    /// (a piece takes ~0.5 ms), else wait for it.
    fn missing(&mut self, id: usize, now: Instant, again: Step) -> Step {
        if now.duration_since(self.handed_at[id]) > LOST_WORK {
            self.handed_at[id] = now;
            again
        } else {
            Step::Wait
        }
    }

    /// Files chunk `c` (and every pending chunk after it that is now in order).
    fn file_chunk(&mut self, c: usize, seeds: Vec<Seed>) {
        if c >= self.filed {
            // A chunk computed twice (handed out again) is filed once.
            self.pending.entry(c).or_insert(seeds);
        }
        while let Some(seeds) = self.pending.remove(&self.filed) {
            for seed in seeds {
                file_seed(&mut self.cells, seed, self.per_cell);
            }
            self.filed += 1;
        }
        if self.filed == self.chunks && self.seeded.is_none() && self.gathering.is_none() {
            let total = self.cells.iter().map(Vec::len).sum();
            let atlas = Atlas {
                offsets: Vec::with_capacity(self.cells.len() + 1),
                seeds: Vec::with_capacity(total),
                near_offsets: Vec::new(),
                near: Vec::new(),
            };
            self.gathering = Some((atlas, 0));
        }
    }

    /// Moves the seeds of the next [`CELLS_PER_GATHER`] cells into the atlas being gathered,
    /// in cell order; after the last cell, the atlas's seeds and offsets are complete (short
    /// lists still empty).
    fn gather_piece(&mut self) {
        let Some((atlas, next)) = self.gathering.as_mut() else {
            return;
        };
        let end = (*next + CELLS_PER_GATHER).min(self.cells.len());
        for cell in &mut self.cells[*next..end] {
            atlas.offsets.push(atlas.seeds.len() as u32);
            atlas
                .seeds
                .extend(std::mem::take(cell).into_iter().map(|(s, _)| s));
        }
        *next = end;
        if end == self.cells.len() {
            if let Some((mut atlas, _)) = self.gathering.take() {
                atlas.offsets.push(atlas.seeds.len() as u32);
                self.cells = Vec::new();
                self.seeded = Some(Arc::new(atlas));
            }
        }
    }

    /// The complete atlas: the seeds with every slab's short lists in cell order.
    fn assemble(&mut self, seeded: Arc<Atlas>) -> Atlas {
        self.seeded = None;
        let mut atlas = Arc::try_unwrap(seeded).unwrap_or_else(|shared| Atlas {
            offsets: shared.offsets.clone(),
            seeds: shared.seeds.clone(),
            near_offsets: Vec::new(),
            near: Vec::new(),
        });
        atlas.near_offsets.reserve(NXY * NXY * NT + 1);
        for slab in self.slabs.iter_mut().filter_map(Option::take) {
            let mut start = atlas.near.len() as u32;
            for len in slab.lengths {
                atlas.near_offsets.push(start);
                start += len;
            }
            atlas.near.extend(slab.near);
        }
        atlas.near_offsets.push(atlas.near.len() as u32);
        atlas
    }
}

/// The candidate seeds of chunk `c`'s rays, in ray order.
fn chunk_seeds(tier: Tier, c: usize) -> Vec<Seed> {
    let spec = tier.spec();
    let mut out = Vec::new();
    let mut buf = Vec::with_capacity(spec.steps);
    let end = ((c + 1) * RAYS_PER_CHUNK).min(spec.rays + spec.separatrix_rays);
    for i in c * RAYS_PER_CHUNK..end {
        ray_seeds(spec, i as u64, &mut buf, &mut out);
    }
    out
}

/// Integrates ray `i` and appends its stable rods as seeds.
fn ray_seeds(
    spec: &Spec,
    i: u64,
    buf: &mut Vec<(f64, f64, f64, f64, Matrix3<f64>)>,
    out: &mut Vec<Seed>,
) {
    let a = if (i as usize) < spec.rays {
        PlanarParams::new(
            (2.0 * halton(i + 1, 2) - 1.0) * spec.a3_max,
            (2.0 * halton(i + 1, 3) - 1.0) * spec.a45_max,
            (2.0 * halton(i + 1, 5) - 1.0) * spec.a45_max,
        )
    } else {
        match separatrix_endpoint(spec, i + 1) {
            Some(a) => a,
            None => return,
        }
    };
    buf.clear();
    let mut t1 = f64::INFINITY;
    let scale = a[0].abs().max(a[1].hypot(a[2]).sqrt());
    let steps = spec.steps.max((spec.steps_per_scale * scale) as usize);
    let ok = scan::integrate(&a, steps, |t, x, y, th, j, det| {
        if t >= crate::STABILITY_T_MIN && det <= 0.0 {
            t1 = t;
            return false;
        }
        buf.push((t, x, y, th, *j));
        true
    });
    if ok.is_none() {
        return;
    }
    for &(t, x, y, th, j) in buf.iter() {
        // Keep a margin from the first conjugate point (seeds deep inside A_stable).
        if t < 0.05 || t > 0.985 * t1 {
            continue;
        }
        let inside = |(m3, m45): (f64, f64)| {
            (t * a[0]).abs() <= m3 && (t * t * a[1]).abs() <= m45 && (t * t * a[2]).abs() <= m45
        };
        if spec.inner.is_some_and(inside) {
            continue;
        }
        out.extend(scaled_seed(&a, t, x, y, th, &j));
    }
}

/// The rod a(t) = (t a3, t² a4, t² a5) of ray `a` at `t` as a seed, with J⁻¹ at its tip:
/// positions scale by 1/t, and ∂/∂a(t) = ∂/∂a · diag(1/t, 1/t², 1/t²).
fn scaled_seed(
    a: &PlanarParams,
    t: f64,
    x: f64,
    y: f64,
    th: f64,
    j: &Matrix3<f64>,
) -> Option<Seed> {
    let tip = [x / t, y / t, wrap_angle(th)];
    let d = Matrix3::from_diagonal(&Vector3::new(1.0 / t, 1.0 / t, 1.0));
    let s = Matrix3::from_diagonal(&Vector3::new(1.0 / t, 1.0 / (t * t), 1.0 / (t * t)));
    let jinv = (d * j * s).try_inverse()?;
    jinv.iter().all(|v| v.is_finite()).then_some(Seed {
        a: [t * a[0], t * t * a[1], t * t * a[2]],
        tip,
        jinv,
    })
}

/// Files `seed` into its cell: one seed per branch, the one nearest the cell centre, at most
/// `per_cell` branches (the farthest replaced).
fn file_seed(cells: &mut [Vec<(Seed, f64)>], seed: Seed, per_cell: usize) {
    let Some((ix, iy, it)) = cell_of(seed.tip[0], seed.tip[1], seed.tip[2]) else {
        return;
    };
    let d = tip_distance2(&seed.tip, &centre(ix, iy, it));
    let cell = &mut cells[index(ix, iy, it)];
    if let Some(slot) = cell.iter_mut().find(|(s, _)| same_branch(&s.a, &seed.a)) {
        if d < slot.1 {
            *slot = (seed, d);
        }
    } else if cell.len() < per_cell {
        cell.push((seed, d));
    } else if let Some(worst) = cell
        .iter_mut()
        .max_by(|p, q| p.1.total_cmp(&q.1))
        .filter(|w| d < w.1)
    {
        *worst = (seed, d);
    }
}

impl Atlas {
    /// Per cell of the x slab `ix` (in index order), the NEAR seeds of its 3×3×3
    /// neighbourhood nearest the cell centre.
    fn short_lists(&self, ix: usize) -> SlabLists {
        let mut lists = SlabLists {
            lengths: Vec::with_capacity(NXY * NT),
            near: Vec::with_capacity(NXY * NT * NEAR),
        };
        let mut tmp = Vec::new();
        // By distance then index: a total order, so the lists do not depend on the order of
        // collection.
        let order = |p: &(f64, u32), q: &(f64, u32)| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1));
        for iy in 0..NXY {
            for it in 0..NT {
                tmp.clear();
                self.collect(ix, iy, it, 1, &centre(ix, iy, it), &mut tmp);
                if tmp.len() > NEAR {
                    tmp.select_nth_unstable_by(NEAR, order);
                    tmp.truncate(NEAR);
                }
                tmp.sort_unstable_by(order);
                lists.lengths.push(tmp.len() as u32);
                lists.near.extend(tmp.iter().map(|p| p.1));
            }
        }
        lists
    }

    /// Number of seeds.
    pub(crate) fn len(&self) -> usize {
        self.seeds.len()
    }

    /// The parameters of seed `k` (< [`Self::len`]).
    pub(crate) fn seed_params(&self, k: usize) -> PlanarParams {
        PlanarParams::from(self.seeds[k].a)
    }

    fn cell(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Appends (distance² to `tgt`, seed index) for the seeds within `radius` cells.
    fn collect(
        &self,
        ix: usize,
        iy: usize,
        it: usize,
        radius: usize,
        tgt: &[f64; 3],
        out: &mut Vec<(f64, u32)>,
    ) {
        let r = radius as i64;
        let nt = NT as i64;
        let (t_lo, t_hi) = if 2 * r + 1 >= nt {
            (0, nt - 1)
        } else {
            (it as i64 - r, it as i64 + r)
        };
        for jx in (ix as i64 - r).max(0)..=(ix as i64 + r).min(NXY as i64 - 1) {
            for jy in (iy as i64 - r).max(0)..=(iy as i64 + r).min(NXY as i64 - 1) {
                for jt in t_lo..=t_hi {
                    let jt = jt.rem_euclid(nt) as usize;
                    for k in self.cell(index(jx as usize, jy as usize, jt)) {
                        out.push((tip_distance2(&self.seeds[k].tip, tgt), k as u32));
                    }
                }
            }
        }
    }

    /// Seeds within `radius` cells of the target's cell (θ periodic), sorted by tip distance
    /// to the target, appended to `out` as (distance², seed index).
    pub(crate) fn candidates(&self, target: &PlanarPose, radius: usize, out: &mut Vec<(f64, u32)>) {
        let tgt = [target.x, target.y, wrap_angle(target.theta)];
        let Some((ix, iy, it)) = cell_of(tgt[0], tgt[1], tgt[2]) else {
            return;
        };
        let start = out.len();
        self.collect(ix, iy, it, radius, &tgt, out);
        out[start..].sort_by(|p, q| p.0.total_cmp(&q.0));
    }

    /// The precomputed short list of the target's cell, sorted by tip distance to the target.
    pub(crate) fn near_list(&self, target: &PlanarPose, out: &mut Vec<(f64, u32)>) {
        let tgt = [target.x, target.y, wrap_angle(target.theta)];
        let Some((ix, iy, it)) = cell_of(tgt[0], tgt[1], tgt[2]) else {
            return;
        };
        let c = index(ix, iy, it);
        let start = out.len();
        let near = &self.near[self.near_offsets[c] as usize..self.near_offsets[c + 1] as usize];
        // One allocation of the right size (growing by pushes reallocated twice per solve).
        out.reserve(near.len());
        for &k in near {
            out.push((tip_distance2(&self.seeds[k as usize].tip, &tgt), k));
        }
        out[start..].sort_by(|p, q| p.0.total_cmp(&q.0));
    }

    /// ‖Υ(a_s) − b‖ for seed `k` (angle wrapped; from the stored tip).
    pub(crate) fn seed_residual(&self, k: u32, target: &PlanarPose) -> f64 {
        let s = &self.seeds[k as usize];
        Vector3::new(
            s.tip[0] - target.x,
            s.tip[1] - target.y,
            wrap_angle(s.tip[2] - target.theta),
        )
        .norm()
    }

    /// The start for seed `k` toward `target`: the seed, and its predicted Newton step
    /// a1 = a_s − J(1, a_s)⁻¹ (Υ(a_s) − b), clipped to the local solver's trust box.
    pub(crate) fn start(&self, k: u32, target: &PlanarPose) -> Start {
        let s = &self.seeds[k as usize];
        let a = PlanarParams::from(s.a);
        let f = Vector3::new(
            s.tip[0] - target.x,
            s.tip[1] - target.y,
            wrap_angle(s.tip[2] - target.theta),
        );
        let p = s.jinv * f;
        let size = (p[0].abs() / 4.0)
            .max(p[1].abs() / 40.0)
            .max(p[2].abs() / 40.0);
        let p = if size > 1.0 { p / size } else { p };
        let a1 = a - p;
        Start {
            a,
            predicted: a1.iter().all(|v| v.is_finite()).then_some((a1, f.norm())),
        }
    }
}

/// The atlas seed nearest `target` in tip space (searching up to 3 cells away).
/// `None` too when the deadline passes before the atlas is built.
pub(crate) fn nearest(target: &PlanarPose) -> Option<PlanarParams> {
    let atlas = get(Tier::Box)?;
    let mut v = Vec::new();
    atlas.near_list(target, &mut v);
    for r in 1..=3 {
        if let Some(&(_, k)) = v.first() {
            return Some(PlanarParams::from(atlas.seeds[k as usize].a));
        }
        atlas.candidates(target, r, &mut v);
    }
    v.first()
        .map(|&(_, k)| PlanarParams::from(atlas.seeds[k as usize].a))
}
