//! Runtime choice of a build of the hot loops for the CPU's wider vector unit.
//!
//! The crate is compiled for the x86-64 baseline (SSE2: two f64 per vector operation), so that
//! one binary runs everywhere. The 3-D integrations are loops over 44-value states and six J
//! columns; on a CPU with AVX2 the same loops compiled for it run four values per operation
//! and need about a third fewer instructions (callgrind, `profile tipj3d|evaluate3d`). Their
//! callers keep two copies of the integration (`spatial::reduced::integrate`,
//! `spatial::stability`): one in a function with `#[target_feature(enable = "avx2")]`, whose
//! closures inherit the feature and into which the integrator is inlined, and one as built; they
//! pick one with [`pick_build!`].
//!
//! The results are bit-identical either way: Rust never contracts a·b + c into an FMA nor
//! reorders floating-point operations, so wider vectors perform the same IEEE operations in the
//! same order (checked by `spatial::tests::avx2_build_is_bit_identical`).

/// True when the CPU has AVX2 (`is_x86_feature_detected!` caches the answer).
#[inline(always)]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `pick_build!(avx2_fn, baseline_fn, args...)`: calls `avx2_fn(args...)` — a function
/// compiled with `#[target_feature(enable = "avx2")]` — where the CPU has AVX2, else
/// `baseline_fn(args...)`. The one place where the AVX2 build is entered.
macro_rules! pick_build {
    ($avx2:expr, $baseline:expr, $($arg:expr),* $(,)?) => {{
        #[cfg(target_arch = "x86_64")]
        let out = if $crate::simd::has_avx2() {
            // SAFETY: the callee needs AVX2 only, and this CPU has it (checked just above).
            unsafe { $avx2($($arg),*) }
        } else {
            $baseline($($arg),*)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let out = $baseline($($arg),*);
        out
    }};
}
pub(crate) use pick_build;
