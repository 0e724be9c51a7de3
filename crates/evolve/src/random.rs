//! Random streams. Every evaluation draws from its own stream, derived from
//! the run's seed, the lane and the generation, so results do not depend on
//! the order lanes are run in, the number of threads, or where a run was
//! stopped and resumed: a checkpoint needs no generator state.

use rand_core::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// SplitMix64's finaliser: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A named generator for one (seed, lane, generation).
pub struct Stream(Pcg64Mcg);

impl Stream {
    /// The stream of `lane` at `generation` of the run seeded with `seed`.
    pub fn new(seed: u64, lane: usize, generation: u64) -> Stream {
        let key = mix(mix(mix(seed) ^ lane as u64) ^ generation);
        Stream(Pcg64Mcg::seed_from_u64(key))
    }

    /// A uniform number in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
