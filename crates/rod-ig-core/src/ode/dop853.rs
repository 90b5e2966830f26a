//! Dormand–Prince 8(5,3) embedded Runge–Kutta pair with 7th-order dense output.
//!
//! Method: Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
//! §II.5 and §II.10 (Table 5.4 "DOP853"): a 12-stage 8th-order method whose local error is
//! estimated by a combination of a 5th-order and a 3rd-order embedded formula
//! (err = h·err5² / √(err5² + 0.01·err3²) in the weighted RMS norm), plus three extra stages
//! for a continuous extension of order 7. The numerical coefficients below are the published
//! ones (Hairer's `dop853`), written here as literals.
//!
//! The state is a fixed-size array `[f64; N]`; the stepper allocates nothing.

#![allow(clippy::excessive_precision)] // published coefficients, kept digit for digit

use super::{OdeError, OdeOptions, OdeStats};
use std::ops::ControlFlow;

// ---- Nodes c_i -------------------------------------------------------------------------------
const C2: f64 = 0.526001519587677318785587544488e-01;
const C3: f64 = 0.789002279381515978178381316732e-01;
const C4: f64 = 0.118350341907227396726757197510e+00;
const C5: f64 = 0.281649658092772603273242802490e+00;
const C6: f64 = 0.333333333333333333333333333333e+00;
const C7: f64 = 0.25e+00;
const C8: f64 = 0.307692307692307692307692307692e+00;
const C9: f64 = 0.651282051282051282051282051282e+00;
const C10: f64 = 0.6e+00;
const C11: f64 = 0.857142857142857142857142857142e+00;
const C14: f64 = 0.1e+00;
const C15: f64 = 0.2e+00;
const C16: f64 = 0.777777777777777777777777777778e+00;

// ---- 8th-order weights b_i -------------------------------------------------------------------
const B1: f64 = 5.42937341165687622380535766363e-2;
const B6: f64 = 4.45031289275240888144113950566e0;
const B7: f64 = 1.89151789931450038304281599044e0;
const B8: f64 = -5.8012039600105847814672114227e0;
const B9: f64 = 3.1116436695781989440891606237e-1;
const B10: f64 = -1.52160949662516078556178806805e-1;
const B11: f64 = 2.01365400804030348374776537501e-1;
const B12: f64 = 4.47106157277725905176885569043e-2;

// ---- 3rd-order error weights (b − bhh) -------------------------------------------------------
const BHH1: f64 = 0.244094488188976377952755905512e+00;
const BHH2: f64 = 0.733846688281611857341361741547e+00;
const BHH3: f64 = 0.220588235294117647058823529412e-01;

// ---- 5th-order error weights -----------------------------------------------------------------
const ER1: f64 = 0.1312004499419488073250102996e-01;
const ER6: f64 = -0.1225156446376204440720569753e+01;
const ER7: f64 = -0.4957589496572501915214079952e+00;
const ER8: f64 = 0.1664377182454986536961530415e+01;
const ER9: f64 = -0.3503288487499736816886487290e+00;
const ER10: f64 = 0.3341791187130174790297318841e+00;
const ER11: f64 = 0.8192320648511571246570742613e-01;
const ER12: f64 = -0.2235530786388629525884427845e-01;

// ---- Runge–Kutta matrix a_ij -----------------------------------------------------------------
const A21: f64 = 5.26001519587677318785587544488e-2;
const A31: f64 = 1.97250569845378994544595329183e-2;
const A32: f64 = 5.91751709536136983633785987549e-2;
const A41: f64 = 2.95875854768068491816892993775e-2;
const A43: f64 = 8.87627564304205475450678981324e-2;
const A51: f64 = 2.41365134159266685502369798665e-1;
const A53: f64 = -8.84549479328286085344864962717e-1;
const A54: f64 = 9.24834003261792003115737966543e-1;
const A61: f64 = 3.7037037037037037037037037037e-2;
const A64: f64 = 1.70828608729473871279604482173e-1;
const A65: f64 = 1.25467687566822425016691814123e-1;
const A71: f64 = 3.7109375e-2;
const A74: f64 = 1.70252211019544039314978060272e-1;
const A75: f64 = 6.02165389804559606850219397283e-2;
const A76: f64 = -1.7578125e-2;
const A81: f64 = 3.70920001185047927108779319836e-2;
const A84: f64 = 1.70383925712239993810214054705e-1;
const A85: f64 = 1.07262030446373284651809199168e-1;
const A86: f64 = -1.53194377486244017527936158236e-2;
const A87: f64 = 8.27378916381402288758473766002e-3;
const A91: f64 = 6.24110958716075717114429577812e-1;
const A94: f64 = -3.36089262944694129406857109825e0;
const A95: f64 = -8.68219346841726006818189891453e-1;
const A96: f64 = 2.75920996994467083049415600797e1;
const A97: f64 = 2.01540675504778934086186788979e1;
const A98: f64 = -4.34898841810699588477366255144e1;
const A101: f64 = 4.77662536438264365890433908527e-1;
const A104: f64 = -2.48811461997166764192642586468e0;
const A105: f64 = -5.90290826836842996371446475743e-1;
const A106: f64 = 2.12300514481811942347288949897e1;
const A107: f64 = 1.52792336328824235832596922938e1;
const A108: f64 = -3.32882109689848629194453265587e1;
const A109: f64 = -2.03312017085086261358222928593e-2;
const A111: f64 = -9.3714243008598732571704021658e-1;
const A114: f64 = 5.18637242884406370830023853209e0;
const A115: f64 = 1.09143734899672957818500254654e0;
const A116: f64 = -8.14978701074692612513997267357e0;
const A117: f64 = -1.85200656599969598641566180701e1;
const A118: f64 = 2.27394870993505042818970056734e1;
const A119: f64 = 2.49360555267965238987089396762e0;
const A1110: f64 = -3.0467644718982195003823669022e0;
const A121: f64 = 2.27331014751653820792359768449e0;
const A124: f64 = -1.05344954667372501984066689879e1;
const A125: f64 = -2.00087205822486249909675718444e0;
const A126: f64 = -1.79589318631187989172765950534e1;
const A127: f64 = 2.79488845294199600508499808837e1;
const A128: f64 = -2.85899827713502369474065508674e0;
const A129: f64 = -8.87285693353062954433549289258e0;
const A1210: f64 = 1.23605671757943030647266201528e1;
const A1211: f64 = 6.43392746015763530355970484046e-1;

// ---- Extra stages for dense output -----------------------------------------------------------
const A141: f64 = 5.61675022830479523392909219681e-2;
const A147: f64 = 2.53500210216624811088794765333e-1;
const A148: f64 = -2.46239037470802489917441475441e-1;
const A149: f64 = -1.24191423263816360469010140626e-1;
const A1410: f64 = 1.5329179827876569731206322685e-1;
const A1411: f64 = 8.20105229563468988491666602057e-3;
const A1412: f64 = 7.56789766054569976138603589584e-3;
const A1413: f64 = -8.298e-3;
const A151: f64 = 3.18346481635021405060768473261e-2;
const A156: f64 = 2.83009096723667755288322961402e-2;
const A157: f64 = 5.35419883074385676223797384372e-2;
const A158: f64 = -5.49237485713909884646569340306e-2;
const A1511: f64 = -1.08347328697249322858509316994e-4;
const A1512: f64 = 3.82571090835658412954920192323e-4;
const A1513: f64 = -3.40465008687404560802977114492e-4;
const A1514: f64 = 1.41312443674632500278074618366e-1;
const A161: f64 = -4.28896301583791923408573538692e-1;
const A166: f64 = -4.69762141536116384314449447206e0;
const A167: f64 = 7.68342119606259904184240953878e0;
const A168: f64 = 4.06898981839711007970213554331e0;
const A169: f64 = 3.56727187455281109270669543021e-1;
const A1613: f64 = -1.39902416515901462129418009734e-3;
const A1614: f64 = 2.9475147891527723389556272149e0;
const A1615: f64 = -9.15095847217987001081870187138e0;

// ---- Dense-output weights d_ij (rows 4..7; columns are stages 1, 6..16) ----------------------
/// Dense-output coefficients; `D[r][k]` multiplies stage `DSTAGE[k]`.
const DSTAGE: [usize; 12] = [1, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16];
const D: [[f64; 12]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// Step-size controller constants (Hairer's defaults: safety 0.9, factor in [1/3, 6]).
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.333;
const FAC_MAX: f64 = 6.0;

/// `y + h·Σ cᵢ kᵢ` for a fixed list of (coefficient, stage) pairs, expanded inline so that
/// the component loop vectorises.
macro_rules! combine {
    ($out:expr; $y:expr, $h:expr; ($c0:expr, $k0:expr) $(, ($c:expr, $k:expr))* $(,)?) => {{
        // Written into the stepper's scratch vector: a fresh array per stage cost a zero-fill.
        let out: &mut [f64; N] = $out;
        let y = $y;
        let h = $h;
        for i in 0..N {
            out[i] = y[i] + h * ($c0 * $k0[i] $(+ $c * $k[i])*);
        }
        &*out
    }};
}

/// The 7th-order continuous extension of one accepted step (Hairer's `CONTD8`):
/// with s = (t − t₀)/h and s₁ = 1 − s,
/// y(t) = r₁ + s(r₂ + s₁(r₃ + s(r₄ + s₁(r₅ + s(r₆ + s₁(r₇ + s r₈)))))).
#[derive(Clone, Copy, Debug)]
pub struct DenseStep<const N: usize> {
    t0: f64,
    h: f64,
    r: [[f64; N]; 8],
}

impl<const N: usize> DenseStep<N> {
    /// Writes the coefficients r₁..r₈ of the step (t, t + h) from y(t), y(t + h), the FSAL
    /// derivative k13 and the stages `ks` (in the order of [`DSTAGE`]; `ks[0]` is k1). Row by
    /// row, so that each loop runs over the components and vectorises.
    #[inline(always)]
    fn fill(
        &mut self,
        t: f64,
        h: f64,
        y: &[f64; N],
        y_new: &[f64; N],
        k13: &[f64; N],
        ks: &[&[f64; N]; 12],
    ) {
        let r = &mut self.r;
        for i in 0..N {
            let ydiff = y_new[i] - y[i];
            let bspl = h * ks[0][i] - ydiff;
            r[0][i] = y[i];
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - h * k13[i] - bspl;
        }
        for (row, d) in D.iter().enumerate() {
            let out = &mut r[4 + row];
            for i in 0..N {
                let mut s = d[0] * ks[0][i];
                for c in 1..12 {
                    s += d[c] * ks[c][i];
                }
                out[i] = h * s;
            }
        }
        self.t0 = t;
        self.h = h;
    }

    /// Start of the step.
    pub fn t_start(&self) -> f64 {
        self.t0
    }
    /// End of the step.
    pub fn t_end(&self) -> f64 {
        self.t0 + self.h
    }
    /// The interpolated state at `t` (meant for t within the step; extrapolates otherwise).
    #[inline(always)] // into the 3-D scan's AVX2 build (crate::simd)
    pub fn eval(&self, t: f64) -> [f64; N] {
        let s = if self.h != 0.0 {
            (t - self.t0) / self.h
        } else {
            0.0
        };
        let s1 = 1.0 - s;
        let r = &self.r;
        let mut out = [0.0; N];
        for i in 0..N {
            let conpar = r[4][i] + s * (r[5][i] + s1 * (r[6][i] + s * r[7][i]));
            out[i] = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * conpar)));
        }
        out
    }
}

/// An adaptive DOP853 stepper over `[t0, t_end]` (either direction) for y' = f(t, y),
/// y ∈ ℝᴺ. Each call to [`Dop853::step`] performs one accepted step (retrying rejected ones)
/// and never steps past `t_end`; the step budget counts every attempted step.
#[derive(Clone, Debug)]
pub struct Dop853<const N: usize> {
    opts: OdeOptions,
    t: f64,
    y: [f64; N],
    /// The stages of the current step; `k[0]` is the derivative at (t, y) (first same as last:
    /// the previous step's final evaluation). Kept here so that a step neither zero-fills nor
    /// copies 12 state vectors.
    k: [[f64; N]; 12],
    /// The argument of the stage being evaluated.
    scratch: [f64; N],
    /// The solution at the end of the step being attempted.
    y_next: [f64; N],
    t_end: f64,
    dir: f64,
    h: f64,
    reject: bool,
    stats: OdeStats,
    /// The continuous extension of the last accepted step, written in place (valid when
    /// `has_dense`).
    dense: DenseStep<N>,
    has_dense: bool,
    want_dense: bool,
}

impl<const N: usize> Dop853<N> {
    /// Prepares integration of y' = f(t, y), y(t0) = y0 up to `t_end`. With `dense`, every
    /// accepted step also builds its continuous extension (3 extra evaluations per step).
    ///
    /// Errors: non-finite t0, t_end, y0, invalid tolerances, or a non-finite f(t0, y0).
    #[inline(always)] // so that a caller compiled for wider vectors (crate::simd) gets it all
    pub fn new<F>(
        f: &mut F,
        t0: f64,
        y0: [f64; N],
        t_end: f64,
        opts: &OdeOptions,
        dense: bool,
    ) -> Result<Self, OdeError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let opts = opts.sanitized();
        opts.validate()?;
        if !t0.is_finite() || !t_end.is_finite() {
            return Err(OdeError::InvalidInput("non-finite time bounds".into()));
        }
        if y0.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t: t0 });
        }
        let mut k1 = [0.0; N];
        f(t0, &y0, &mut k1);
        let mut stats = OdeStats::default();
        stats.evaluations += 1;
        if k1.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t: t0 });
        }
        let dir = if t_end >= t0 { 1.0 } else { -1.0 };
        let mut k = [[0.0; N]; 12];
        k[0] = k1;
        let mut s = Self {
            opts,
            t: t0,
            y: y0,
            k,
            scratch: [0.0; N],
            y_next: [0.0; N],
            t_end,
            dir,
            h: 0.0,
            reject: false,
            stats,
            dense: DenseStep {
                t0,
                h: 0.0,
                r: [[0.0; N]; 8],
            },
            has_dense: false,
            want_dense: dense,
        };
        s.h = match opts.initial_step {
            Some(h) if h.is_finite() && h > 0.0 => h,
            _ => s.initial_step(f),
        };
        Ok(s)
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Current state.
    pub fn y(&self) -> &[f64; N] {
        &self.y
    }
    /// Counters so far.
    pub fn stats(&self) -> OdeStats {
        self.stats
    }
    /// True once t has reached `t_end`.
    pub fn finished(&self) -> bool {
        self.t == self.t_end
    }
    /// Continuous extension of the last accepted step (None before the first step or
    /// when the stepper was created without dense output).
    pub fn dense(&self) -> Option<&DenseStep<N>> {
        self.has_dense.then_some(&self.dense)
    }

    /// Hairer's starting-step heuristic (HNW I, §II.4): h such that an explicit Euler step
    /// would have local error ≈ 0.01 in the weighted norm, corrected by a second evaluation.
    fn initial_step<F>(&mut self, f: &mut F) -> f64
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let span = (self.t_end - self.t).abs();
        if span == 0.0 {
            return 0.0;
        }
        let hmax = self.opts.max_step.min(span);
        let ne = self.opts.error_components.min(N).max(1);
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for i in 0..ne {
            let sk = self.opts.weight(self.y[i], self.y[i]);
            dnf += (self.k[0][i] / sk).powi(2);
            dny += (self.y[i] / sk).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        if !h.is_finite() || h <= 0.0 {
            h = 1e-6;
        }
        h = h.min(hmax);
        let y1: [f64; N] = std::array::from_fn(|i| self.y[i] + self.dir * h * self.k[0][i]);
        let mut f1 = [0.0; N];
        f(self.t + self.dir * h, &y1, &mut f1);
        self.stats.evaluations += 1;
        let mut der2 = 0.0;
        for i in 0..ne {
            let sk = self.opts.weight(self.y[i], self.y[i]);
            der2 += ((f1[i] - self.k[0][i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 || !der12.is_finite() {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(1.0 / 8.0)
        };
        let out = (100.0 * h).min(h1).min(hmax);
        if out.is_finite() && out > 0.0 {
            out
        } else {
            (span * 1e-6).max(f64::MIN_POSITIVE)
        }
    }

    /// Stages k1..k12 of the step of size `h` from (t, y) (Hairer's DOP853 tableau written out:
    /// a coefficient table; k1 is the stored FSAL derivative), the last evaluated at
    /// `t_new` = t + h exactly.
    #[inline(always)]
    fn stages<F>(&mut self, f: &mut F, t: f64, h: f64, t_new: f64)
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let Self { y, k, scratch, .. } = self;
        let y = &*y;
        f(t + C2 * h, combine!(scratch; y, h; (A21, &k[0])), &mut k[1]);
        f(
            t + C3 * h,
            combine!(scratch; y, h; (A31, &k[0]), (A32, &k[1])),
            &mut k[2],
        );
        f(
            t + C4 * h,
            combine!(scratch; y, h; (A41, &k[0]), (A43, &k[2])),
            &mut k[3],
        );
        f(
            t + C5 * h,
            combine!(scratch; y, h; (A51, &k[0]), (A53, &k[2]), (A54, &k[3])),
            &mut k[4],
        );
        f(
            t + C6 * h,
            combine!(scratch; y, h; (A61, &k[0]), (A64, &k[3]), (A65, &k[4])),
            &mut k[5],
        );
        f(
            t + C7 * h,
            combine!(scratch; y, h; (A71, &k[0]), (A74, &k[3]), (A75, &k[4]), (A76, &k[5])),
            &mut k[6],
        );
        f(
            t + C8 * h,
            combine!(scratch; y, h; (A81, &k[0]), (A84, &k[3]), (A85, &k[4]), (A86, &k[5]), (A87, &k[6])),
            &mut k[7],
        );
        f(
            t + C9 * h,
            combine!(scratch; y, h;
                (A91, &k[0]),
                (A94, &k[3]),
                (A95, &k[4]),
                (A96, &k[5]),
                (A97, &k[6]),
                (A98, &k[7]),
            ),
            &mut k[8],
        );
        f(
            t + C10 * h,
            combine!(scratch; y, h;
                (A101, &k[0]),
                (A104, &k[3]),
                (A105, &k[4]),
                (A106, &k[5]),
                (A107, &k[6]),
                (A108, &k[7]),
                (A109, &k[8]),
            ),
            &mut k[9],
        );
        f(
            t + C11 * h,
            combine!(scratch; y, h;
                (A111, &k[0]),
                (A114, &k[3]),
                (A115, &k[4]),
                (A116, &k[5]),
                (A117, &k[6]),
                (A118, &k[7]),
                (A119, &k[8]),
                (A1110, &k[9]),
            ),
            &mut k[10],
        );
        f(
            t_new,
            combine!(scratch; y, h;
                (A121, &k[0]),
                (A124, &k[3]),
                (A125, &k[4]),
                (A126, &k[5]),
                (A127, &k[6]),
                (A128, &k[7]),
                (A129, &k[8]),
                (A1210, &k[9]),
                (A1211, &k[10]),
            ),
            &mut k[11],
        );
    }

    /// The 8th-order solution of the step and its scaled error norm (Hairer's combination of
    /// the 5th- and 3rd-order estimates: err = |h| err5 / √(n (err5² + 0.01 err3²))).
    #[inline(always)]
    fn solution_and_error(&mut self, h: f64, habs: f64) -> f64 {
        let Self {
            y,
            k,
            scratch,
            y_next,
            opts,
            ..
        } = self;
        let [k1, _, _, _, _, k6, k7, k8, k9, k10, k11, k12] = &*k;
        // Σ bᵢkᵢ is kept in `scratch` for the error estimate; both loops vectorise.
        for i in 0..N {
            scratch[i] = B1 * k1[i]
                + B6 * k6[i]
                + B7 * k7[i]
                + B8 * k8[i]
                + B9 * k9[i]
                + B10 * k10[i]
                + B11 * k11[i]
                + B12 * k12[i];
            y_next[i] = y[i] + h * scratch[i];
        }
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        let ne = opts.error_components.min(N).max(1);
        for i in 0..ne {
            let inv = 1.0 / opts.weight(y[i], y_next[i]);
            let e3 = scratch[i] - BHH1 * k1[i] - BHH2 * k9[i] - BHH3 * k12[i];
            let e5 = ER1 * k1[i]
                + ER6 * k6[i]
                + ER7 * k7[i]
                + ER8 * k8[i]
                + ER9 * k9[i]
                + ER10 * k10[i]
                + ER11 * k11[i]
                + ER12 * k12[i];
            err3 += (e3 * inv).powi(2);
            err5 += (e5 * inv).powi(2);
        }
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        habs * err5 * (1.0 / (ne as f64 * deno)).sqrt()
    }

    /// The 7th-order continuous extension of an accepted step (Hairer's `CONTD8`): three more
    /// stages k14..k16 and the coefficients r₁..r₈ of [`DenseStep`].
    #[inline(always)]
    fn dense_output<F>(&mut self, f: &mut F, t: f64, h: f64, k13: &[f64; N])
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        let Self {
            y,
            k,
            scratch,
            y_next,
            dense,
            ..
        } = self;
        let (y, k, y_new) = (&*y, &*k, &*y_next);
        let [k1, _, _, _, _, k6, k7, k8, k9, k10, k11, k12] = k;
        let mut k14 = [0.0; N];
        let mut k15 = [0.0; N];
        let mut k16 = [0.0; N];
        f(
            t + C14 * h,
            combine!(scratch; y, h;
                (A141, k1),
                (A147, &k7),
                (A148, &k8),
                (A149, &k9),
                (A1410, &k10),
                (A1411, &k11),
                (A1412, &k12),
                (A1413, k13),
            ),
            &mut k14,
        );
        f(
            t + C15 * h,
            combine!(scratch; y, h;
                (A151, k1),
                (A156, &k6),
                (A157, &k7),
                (A158, &k8),
                (A1511, &k11),
                (A1512, &k12),
                (A1513, k13),
                (A1514, &k14),
            ),
            &mut k15,
        );
        f(
            t + C16 * h,
            combine!(scratch; y, h;
                (A161, k1),
                (A166, &k6),
                (A167, &k7),
                (A168, &k8),
                (A169, &k9),
                (A1613, k13),
                (A1614, &k14),
                (A1615, &k15),
            ),
            &mut k16,
        );
        let ks: [&[f64; N]; 12] = [k1, k6, k7, k8, k9, k10, k11, k12, k13, &k14, &k15, &k16];
        debug_assert_eq!(DSTAGE.len(), ks.len());
        dense.fill(t, h, y, y_new, k13, &ks);
    }

    /// Performs one accepted step towards `t_end` (a no-op once there).
    ///
    /// Errors: [`OdeError::StepBudget`] when `max_steps` attempts are used up,
    /// [`OdeError::StepSizeUnderflow`] when h falls below the resolution of t (e.g. a state that
    /// keeps turning non-finite), [`OdeError::Deadline`] when the deadline in force passes
    /// (each attempt is charged to [`crate::deadline`]).
    #[inline(always)] // so that a caller compiled for wider vectors (crate::simd) gets it all
    pub fn step<F>(&mut self, f: &mut F) -> Result<(), OdeError>
    where
        F: FnMut(f64, &[f64; N], &mut [f64; N]),
    {
        if self.finished() {
            return Ok(());
        }
        loop {
            if self.stats.attempts >= self.opts.max_steps {
                return Err(OdeError::StepBudget {
                    steps: self.stats.attempts,
                    t: self.t,
                });
            }
            self.stats.attempts += 1;
            if crate::deadline::charge(crate::deadline::units::DOP853_STEP) {
                return Err(OdeError::Deadline { t: self.t });
            }
            let remaining = (self.t_end - self.t).abs();
            let mut habs = self.h.abs().min(self.opts.max_step);
            let last = habs >= remaining * (1.0 - 1e-12);
            if last {
                habs = remaining;
            }
            if habs <= 16.0 * f64::EPSILON * self.t.abs().max(f64::MIN_POSITIVE) {
                return Err(OdeError::StepSizeUnderflow { t: self.t, h: habs });
            }
            let h = self.dir * habs;
            let t = self.t;
            let t_new = if last { self.t_end } else { t + h };
            self.stages(f, t, h, t_new);
            self.stats.evaluations += 11;
            let err = self.solution_and_error(h, habs);
            if !err.is_finite() || self.y_next.iter().any(|v| !v.is_finite()) {
                // Treat as a hard rejection: shrink and retry (bounded by the budget).
                self.stats.rejected += 1;
                self.h = habs * 0.25;
                self.reject = true;
                continue;
            }
            if err <= 1.0 {
                let mut k13 = [0.0; N];
                f(t_new, &self.y_next, &mut k13);
                self.stats.evaluations += 1;
                if k13.iter().any(|v| !v.is_finite()) {
                    self.stats.rejected += 1;
                    self.h = habs * 0.25;
                    self.reject = true;
                    continue;
                }
                if self.want_dense {
                    self.dense_output(f, t, h, &k13);
                    self.has_dense = true;
                    self.stats.evaluations += 3;
                }
                // Accept.
                let fac = if err == 0.0 {
                    FAC_MAX
                } else {
                    (SAFETY * err.powf(-1.0 / 8.0)).clamp(FAC_MIN, FAC_MAX)
                };
                let fac = if self.reject { fac.min(1.0) } else { fac };
                self.reject = false;
                self.h = habs * fac;
                self.t = t_new;
                self.y = self.y_next;
                self.k[0] = k13;
                self.stats.accepted += 1;
                return Ok(());
            } else {
                let fac = (SAFETY * err.powf(-1.0 / 8.0)).max(FAC_MIN);
                self.h = habs * fac;
                self.reject = true;
                self.stats.rejected += 1;
            }
        }
    }
}

/// Integrates y' = f(t, y), y(t0) = y0 to `t1` with DOP853 and returns y(t1).
#[inline(always)] // so that a caller compiled for wider vectors (crate::simd) gets it all
pub fn solve<const N: usize, F>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    opts: &OdeOptions,
) -> Result<([f64; N], OdeStats), OdeError>
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
{
    let mut st = Dop853::new(&mut f, t0, y0, t1, opts, false)?;
    while !st.finished() {
        st.step(&mut f)?;
    }
    Ok((st.y, st.stats))
}

/// Integrates with DOP853 and reports the solution at each requested time of `ts` through
/// `observer(index, t, y(t))`, using the 7th-order dense output (times equal to a step end get
/// the step's 8th-order value). `ts` must be monotone in the direction of integration and lie on
/// the same side of `t0`; integration stops at the last requested time, or early when the
/// observer returns `ControlFlow::Break`.
#[inline(always)] // so that a caller compiled for wider vectors (crate::simd) gets it all
pub fn solve_dense<const N: usize, F, O>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    ts: &[f64],
    opts: &OdeOptions,
    mut observer: O,
) -> Result<OdeStats, OdeError>
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
    O: FnMut(usize, f64, &[f64; N]) -> ControlFlow<()>,
{
    let Some(&t_last) = ts.last() else {
        return Ok(OdeStats::default());
    };
    if ts.iter().any(|t| !t.is_finite()) {
        return Err(OdeError::InvalidInput("non-finite output time".into()));
    }
    let dir = if t_last >= t0 { 1.0 } else { -1.0 };
    let mut prev = t0;
    for &t in ts {
        if (t - prev) * dir < 0.0 {
            return Err(OdeError::InvalidInput(
                "output times must be monotone in the direction of integration, starting at t0"
                    .into(),
            ));
        }
        prev = t;
    }
    let mut st = Dop853::new(&mut f, t0, y0, t_last, opts, true)?;
    let mut idx = 0;
    while idx < ts.len() && ts[idx] == t0 {
        if observer(idx, t0, &y0).is_break() {
            return Ok(st.stats);
        }
        idx += 1;
    }
    while idx < ts.len() {
        st.step(&mut f)?;
        let t_now = st.t;
        while idx < ts.len() && (ts[idx] - t_now) * dir <= 0.0 {
            let t = ts[idx];
            let y = if t == t_now {
                st.y
            } else {
                match st.dense() {
                    Some(d) => d.eval(t),
                    None => st.y,
                }
            };
            if observer(idx, t, &y).is_break() {
                return Ok(st.stats);
            }
            idx += 1;
        }
    }
    Ok(st.stats)
}
