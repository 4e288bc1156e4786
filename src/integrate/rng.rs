//! The one seeded random-number generator: SplitMix64 (Steele, Lea & Flood 2014, the
//! `java.util.SplittableRandom` generator): a Weyl sequence of the golden-ratio increment
//! through the finaliser [`mix64`]. The Monte Carlo integrands seed one stream per path from a
//! hash of (key, cell, sample), so a path's bits depend on nothing but those three numbers: not
//! on the thread, the shard or the order in which paths run; benchmarks and seeded cases
//! take a stream from a seed.

/// The Weyl increment, 2^64/φ.
pub const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64's output finaliser (a bijection of u64 with full avalanche).
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A SplitMix64 stream; the state is the seed until the first draw.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The stream of path `sample` of cell `cell` under key `key`.
    pub fn for_path(key: u64, cell: u64, sample: u64) -> Self {
        SplitMix64(mix64(mix64(mix64(key ^ GOLDEN).wrapping_add(cell)).wrapping_add(sample.wrapping_mul(GOLDEN))))
    }

    /// A uniform number in [0, 1) with 53 random bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(GOLDEN);
        (mix64(self.0) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generator is SplitMix64 value for value: from state 0 its first four outputs are the
    /// reference ones of Vigna's splitmix64.c (https://prng.di.unimi.it/splitmix64.c), and a
    /// draw is an output's top 53 bits over 2^53.
    #[test]
    fn the_stream_is_splitmix64() {
        let published: [u64; 4] = [0xe220_a839_7b1d_cdaf, 0x6e78_9e6a_a1b9_65f4, 0x06c4_5d18_8009_454f, 0xf88b_b8a8_724c_81ec];
        let mut r = SplitMix64(0);
        for (k, &want) in published.iter().enumerate() {
            assert_eq!(mix64(GOLDEN.wrapping_mul(k as u64 + 1)), want, "output {k}");
            assert_eq!(r.next_f64(), (want >> 11) as f64 / 9_007_199_254_740_992.0, "draw {k}");
        }
    }
}
