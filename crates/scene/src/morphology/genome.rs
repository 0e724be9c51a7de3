//! A body's genome, as evolution holds it: the particle/spring graph itself
//! (Framsticks f0-like), with each muscle's oscillator genes on its spring
//! (and, for a `neural` body, the weights of the touch sensors at its two
//! ends).
//! A lattice genome ([`super::lattice`]) develops into one of these.
//!
//! Evolution's runs hold genomes as `Vec<f64>` (so that checkpoints, logs
//! and the ask/tell interface serve bodies unchanged); [`Body::to_genes`]
//! and [`Body::from_genes`] are the layout, and `from_genes` refuses any
//! vector that is not one (a count that is not a whole number, an index
//! past the end), naming what is wrong.

use animats_engine::DVec3;

/// The first gene of a graph genome driven by oscillators.
pub const GRAPH_TAG: f64 = 1.0;
/// The first gene of a graph genome whose muscles also feel touch
/// (`controller = "neural"`).
pub const NEURAL_TAG: f64 = 3.0;
/// The first gene of a graph genome whose muscles each carry a duty
/// (`waveform = "skewed"`).
pub const SKEWED_TAG: f64 = 5.0;

/// A particle of the body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// Where it is built, m, before the body is placed.
    pub position: DVec3,
    /// kg.
    pub mass: f64,
    /// m.
    pub radius: f64,
}

/// A muscle's genes. Driven by an oscillator its level is
/// `offset + amplitude sin(2π f t + phase)` (in a `skewed` body, that wave
/// skewed to rise for the share `duty` of a cycle: the oscillator's
/// `duty`); in a `neural` body it is
/// `σ(4 (offset − ½) + 4 amplitude sin(2π f t + phase) + 2 touch[0] t_a +
/// 2 touch[1] t_b)`, with `t_a`, `t_b` 1 while the spring's ends touch the
/// floor, else 0, and σ the logistic function (near ½ the same slope).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Muscle {
    /// In [0, 0.5].
    pub amplitude: f64,
    /// rad, in [−π, π].
    pub phase: f64,
    /// In [0, 1].
    pub offset: f64,
    /// The weights of the touch sensors at the spring's ends `a` and `b`,
    /// each in [`super::TOUCH`] (a `neural` body's; 0 otherwise).
    pub touch: [f64; 2],
    /// The share of a cycle the level rises, in [`super::DUTY`] (a
    /// `skewed` body's; ½, the sine, otherwise).
    pub duty: f64,
}

/// A spring between two particles; a muscle if it carries muscle genes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// One end (an index into [`Body::nodes`]).
    pub a: usize,
    /// The other end.
    pub b: usize,
    /// N/m.
    pub stiffness: f64,
    /// The muscle's genes, if it is one.
    pub muscle: Option<Muscle>,
}

/// A body and its brain: particles, springs (some of them muscles) and the
/// muscles' shared frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// The particles.
    pub nodes: Vec<Node>,
    /// The springs.
    pub edges: Vec<Edge>,
    /// Hz, shared by every muscle.
    pub frequency: f64,
    /// Its muscles feel touch (`controller = "neural"`): the genome carries
    /// every muscle's `touch` weights.
    pub neural: bool,
    /// Its muscles' waves are skewed (`waveform = "skewed"`): the genome
    /// carries every muscle's `duty`.
    pub skewed: bool,
}

/// Genes a node takes.
const NODE_GENES: usize = 5;

/// A graph genome's first gene and the genes each edge takes: 7, two more
/// touch weights in a `neural` body, a duty more in a `skewed` one.
fn layout(neural: bool, skewed: bool) -> (f64, usize) {
    if neural {
        (NEURAL_TAG, 9)
    } else if skewed {
        (SKEWED_TAG, 8)
    } else {
        (GRAPH_TAG, 7)
    }
}

impl Body {
    /// Muscles in the body.
    pub fn muscles(&self) -> usize {
        self.edges.iter().filter(|e| e.muscle.is_some()).count()
    }

    /// kg.
    pub fn mass(&self) -> f64 {
        self.nodes.iter().map(|n| n.mass).sum()
    }

    /// The genes: `[1, particles, springs, frequency]`, then each particle's
    /// `x, y, z, mass, radius`, then each spring's `a, b, stiffness, muscle
    /// (0 or 1), amplitude, phase, offset`. A `neural` body starts with 3
    /// and each spring adds `touch_a, touch_b`; a `skewed` body starts
    /// with 5 and each spring adds `duty`.
    pub fn to_genes(&self) -> Vec<f64> {
        let (tag, per_edge) = layout(self.neural, self.skewed);
        let mut g =
            Vec::with_capacity(4 + NODE_GENES * self.nodes.len() + per_edge * self.edges.len());
        g.extend([
            tag,
            self.nodes.len() as f64,
            self.edges.len() as f64,
            self.frequency,
        ]);
        for n in &self.nodes {
            g.extend([n.position.x, n.position.y, n.position.z, n.mass, n.radius]);
        }
        for e in &self.edges {
            let m = e.muscle.unwrap_or(Muscle {
                amplitude: 0.0,
                phase: 0.0,
                offset: 0.5,
                touch: [0.0; 2],
                duty: 0.5,
            });
            g.extend([
                e.a as f64,
                e.b as f64,
                e.stiffness,
                if e.muscle.is_some() { 1.0 } else { 0.0 },
                m.amplitude,
                m.phase,
                m.offset,
            ]);
            if self.neural {
                g.extend(m.touch);
            }
            if self.skewed {
                g.push(m.duty);
            }
        }
        g
    }

    /// Reads [`Body::to_genes`]'s layout back; any other vector is refused,
    /// saying why.
    pub fn from_genes(g: &[f64]) -> Result<Body, String> {
        if let Some(i) = g.iter().position(|x| !x.is_finite()) {
            return Err(format!("gene {i} is not finite: {}", g[i]));
        }
        if g.len() < 4 || (g[0] != GRAPH_TAG && g[0] != NEURAL_TAG && g[0] != SKEWED_TAG) {
            return Err(
                "not a body genome: it must start [1, particles, springs, frequency] (3 for a neural body, 5 for a skewed one)".into(),
            );
        }
        let (neural, skewed) = (g[0] == NEURAL_TAG, g[0] == SKEWED_TAG);
        let (_, per_edge) = layout(neural, skewed);
        let count = |x: f64, what: &str| -> Result<usize, String> {
            if x >= 0.0 && x.fract() == 0.0 && x <= 1e6 {
                Ok(x as usize)
            } else {
                Err(format!("{what}: {x} is not a count"))
            }
        };
        let n = count(g[1], "particles")?;
        let m = count(g[2], "springs")?;
        let need = 4 + NODE_GENES * n + per_edge * m;
        if g.len() != need {
            return Err(format!(
                "a body of {n} particles and {m} springs takes {need} genes, not {}",
                g.len()
            ));
        }
        let nodes = g[4..4 + NODE_GENES * n]
            .chunks_exact(NODE_GENES)
            .map(|c| Node {
                position: DVec3::new(c[0], c[1], c[2]),
                mass: c[3],
                radius: c[4],
            })
            .collect();
        let edges = g[4 + NODE_GENES * n..]
            .chunks_exact(per_edge)
            .enumerate()
            .map(|(j, c)| {
                let a = count(c[0], &format!("spring {j}'s first end"))?;
                let b = count(c[1], &format!("spring {j}'s second end"))?;
                if a >= n || b >= n {
                    return Err(format!("spring {j} joins particle {a} and {b} of {n}"));
                }
                let muscle = match c[3] {
                    0.0 => None,
                    1.0 => Some(Muscle {
                        amplitude: c[4],
                        phase: c[5],
                        offset: c[6],
                        touch: if neural { [c[7], c[8]] } else { [0.0; 2] },
                        duty: if skewed { c[7] } else { 0.5 },
                    }),
                    x => return Err(format!("spring {j}: muscle flag {x} is neither 0 nor 1")),
                };
                Ok(Edge {
                    a,
                    b,
                    stiffness: c[2],
                    muscle,
                })
            })
            .collect::<Result<_, String>>()?;
        Ok(Body {
            nodes,
            edges,
            frequency: g[3],
            neural,
            skewed,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two() -> Body {
        Body {
            nodes: vec![
                Node {
                    position: DVec3::new(0.0, 0.1, 0.0),
                    mass: 0.1,
                    radius: 0.02,
                },
                Node {
                    position: DVec3::new(0.1, 0.1, 0.0),
                    mass: 0.2,
                    radius: 0.03,
                },
            ],
            edges: vec![Edge {
                a: 0,
                b: 1,
                stiffness: 300.0,
                muscle: Some(Muscle {
                    amplitude: 0.2,
                    phase: -1.0,
                    offset: 0.4,
                    touch: [0.0; 2],
                    duty: 0.5,
                }),
            }],
            frequency: 1.5,
            neural: false,
            skewed: false,
        }
    }

    #[test]
    fn genes_round_trip_and_malformed_vectors_are_refused() {
        let b = two();
        let g = b.to_genes();
        assert_eq!(g.len(), 4 + 10 + 7);
        assert_eq!(Body::from_genes(&g).unwrap(), b);
        let mut short = g.clone();
        short.pop();
        assert!(Body::from_genes(&short)
            .unwrap_err()
            .contains("takes 21 genes"));
        let mut far = g.clone();
        far[15] = 2.0; // the spring's second end
        assert!(Body::from_genes(&far)
            .unwrap_err()
            .contains("joins particle 0 and 2"));
        let mut half = g.clone();
        half[1] = 1.5;
        assert!(Body::from_genes(&half).unwrap_err().contains("not a count"));
        let mut nan = g;
        nan[5] = f64::NAN;
        assert!(Body::from_genes(&nan).unwrap_err().contains("not finite"));
    }

    #[test]
    fn a_neural_body_carries_two_touch_weights_per_spring() {
        let mut b = two();
        b.neural = true;
        if let Some(mu) = b.edges[0].muscle.as_mut() {
            mu.touch = [0.7, -0.3];
        }
        let g = b.to_genes();
        assert_eq!(g[0], NEURAL_TAG);
        assert_eq!(g.len(), 4 + 10 + 9);
        assert_eq!(Body::from_genes(&g).unwrap(), b);
        // The same genes read as an oscillator body's are the wrong length.
        let mut as_graph = g;
        as_graph[0] = GRAPH_TAG;
        assert!(Body::from_genes(&as_graph)
            .unwrap_err()
            .contains("takes 21 genes"));
    }

    #[test]
    fn a_skewed_body_carries_a_duty_per_spring() {
        let mut b = two();
        b.skewed = true;
        if let Some(mu) = b.edges[0].muscle.as_mut() {
            mu.duty = 0.2;
        }
        let g = b.to_genes();
        assert_eq!(g[0], SKEWED_TAG);
        assert_eq!(g.len(), 4 + 10 + 8);
        assert_eq!(g[21], 0.2);
        assert_eq!(Body::from_genes(&g).unwrap(), b);
        let mut as_graph = g;
        as_graph[0] = GRAPH_TAG;
        assert!(Body::from_genes(&as_graph)
            .unwrap_err()
            .contains("takes 21 genes"));
    }
}
