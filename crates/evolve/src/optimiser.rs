//! The optimiser interface: ask for a candidate, tell its fitness. Hill
//! climbing (the thesis's scheme) implements it; other strategies (a GA,
//! CMA-ES) plug into the same evaluation code.

use animats_creatures::random::Random;

/// An ask/tell optimiser over real parameter vectors, maximising fitness.
pub trait Optimiser {
    /// The next candidate to evaluate, drawn with `rng`.
    fn ask(&mut self, rng: &mut Random) -> Vec<f64>;
    /// The fitness of the last candidate; returns true if it became the best.
    fn tell(&mut self, candidate: &[f64], fitness: f64) -> bool;
    /// The best candidate so far and its fitness.
    fn best(&self) -> (&[f64], f64);
}
