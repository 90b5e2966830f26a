//! What a scan samples and what it finds: [`Probe`] (one evaluation of g), [`Scan`], and the
//! verdict they give.

use crate::StabilityReport;

/// Smallest t entering the margin ([`crate::STABILITY_MARGIN_T_MIN`]).
pub(crate) const T_MARGIN: f64 = crate::STABILITY_MARGIN_T_MIN;

/// What a scan of g found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scan {
    /// First sign change (det ≤ 0).
    pub(crate) first: Option<f64>,
    /// min g over t ≥ T_MARGIN (or the negative value at a sign change below it).
    pub(crate) margin: f64,
    /// Where the margin was found.
    pub(crate) t_margin: f64,
}

/// One evaluation of g for [`scan`]: its value (NaN: no sign, the sample is dropped) and its
/// slope g′(t), NaN where the source gives none (the series, the short series and the
/// double-double closed form).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Probe {
    pub(crate) v: f64,
    pub(crate) d: f64,
}

/// A value-only g as a [`scan`] probe (no slope).
pub(crate) fn value_only(g: impl Fn(f64) -> f64) -> impl Fn(f64) -> Probe {
    move |t| Probe {
        v: g(t),
        d: f64::NAN,
    }
}

/// Sample budget of one scan (coarse grid, T_MARGIN, three samples around t* and the extra
/// ones).
pub(crate) const MAX_SAMPLES: usize = 112;

/// Most extra sample times a scan takes (the planar closed form's dip times, at most 8).
pub(crate) const MAX_EXTRA_SAMPLES: usize = 8;

/// The verdict from a scan and the error bound of g where the margin was found: certain where
/// |margin| exceeds the bound (stable without a sign change, unstable with one), uncertain
/// otherwise (no conjugate point reported then).
pub(crate) fn verdict(scan: Scan, g_error: f64) -> StabilityReport {
    let clear = scan.margin.abs() > g_error;
    let (stable, uncertain) = match scan.first {
        None => (clear, !clear),
        Some(_) => (false, !clear),
    };
    StabilityReport {
        stable,
        margin: scan.margin,
        first_conjugate_t: if uncertain { None } else { scan.first },
        uncertain,
    }
}

/// The report of a rod whose det J vanishes identically (straight along its force: J's
/// displacement row is zero): the test "det J > 0 on (0, 1]" neither passes nor fails; the rod
/// is a singular point of the a-chart. Unstable, uncertain, margin 0.
pub(crate) fn undecided() -> StabilityReport {
    StabilityReport {
        stable: false,
        margin: 0.0,
        first_conjugate_t: None,
        uncertain: true,
    }
}
