//! The one seeded random-stream type of animats: PCG64-MCG streams, each
//! named by what it is for, so results depend only on the seed and never on
//! the order things run in, the number of threads or where a run resumed.
//!
//! - [`Random::for_entry`]: placing and spawning the things of a scene entry
//!   (rocks, bubbles), from the scene's seed and the entry's index;
//! - [`Random::for_evaluation`]: one evolution candidate, from the run's
//!   seed, its lane and its generation (a checkpoint needs no generator
//!   state).

use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// SplitMix64's finaliser: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A named random stream.
#[derive(Clone, Debug)]
pub struct Random(Pcg64Mcg);

impl Random {
    /// The stream of entry `index` of a scene seeded with `seed`.
    pub fn for_entry(seed: u64, index: u64) -> Random {
        // SplitMix of seed ^ index·φ (the key the scenes have always used).
        let z = seed ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        Random(Pcg64Mcg::seed_from_u64(mix(
            z.wrapping_sub(0x9e37_79b9_7f4a_7c15)
        )))
    }

    /// The stream of `lane` at `generation` of an evolution seeded with `seed`.
    pub fn for_evaluation(seed: u64, lane: usize, generation: u64) -> Random {
        let key = mix(mix(mix(seed) ^ lane as u64) ^ generation);
        Random(Pcg64Mcg::seed_from_u64(key))
    }

    /// The stream of child `child` of `lane` at `generation`: each
    /// offspring of a generation made from its own stream, so that they can
    /// be made on any thread in any order.
    pub fn for_child(seed: u64, lane: usize, generation: u64, child: u64) -> Random {
        let key = mix(mix(mix(mix(seed) ^ lane as u64) ^ generation)
            ^ child.wrapping_add(0x5851_f42d_4c95_7f2d));
        Random(Pcg64Mcg::seed_from_u64(key))
    }

    /// Uniform in [0, 1), with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}
