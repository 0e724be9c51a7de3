//! Seeded randomness for placing and spawning things: PCG64-MCG streams
//! derived from a scene's seed and an entry's index, so the same scene file
//! gives the same world.

use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A named random stream.
#[derive(Clone, Debug)]
pub struct Random(Pcg64Mcg);

impl Random {
    /// The stream of entry `index` of a scene seeded with `seed`.
    pub fn new(seed: u64, index: u64) -> Random {
        let mut z = seed ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        Random(Pcg64Mcg::seed_from_u64(z ^ (z >> 31)))
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}
