//! A tiny deterministic generator for reproducible benchmark and test samples, so that the
//! crate needs no RNG dependency.

/// SplitMix64 (Steele, Lea & Flood 2014): 64-bit state, full period, good enough to draw
/// benchmark inputs; not for cryptography.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed` (equal seeds give equal sequences).
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) (53 random bits).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// ±10^u with u uniform in [lo, hi) and a random sign: the log-scale magnitudes the tests
    /// and benchmarks draw parameters with.
    pub fn signed_pow10(&mut self, lo: f64, hi: f64) -> f64 {
        let v = 10f64.powf(self.range(lo, hi));
        if self.uniform() < 0.5 {
            -v
        } else {
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproducible_and_in_range() {
        let (mut a, mut b) = (SplitMix64::new(3), SplitMix64::new(3));
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let x = a.range(-2.0, 5.0);
            assert_eq!(x, b.range(-2.0, 5.0));
            assert!((-2.0..5.0).contains(&x));
            sum += x;
        }
        // Mean of U(−2, 5) is 1.5; 10,000 draws put it within ±0.06 (3σ).
        assert!((sum / 10_000.0 - 1.5).abs() < 0.06, "{}", sum / 10_000.0);
    }
}
