//! `encoding = "lattice"`: a grid of cubic cells, each painted with a
//! material (EvoGym's voxel robots, in 3-D). A cell is its eight corners
//! (shared with its neighbours), its twelve edges and its faces' twelve
//! diagonals, all springs; a muscle cell's four edges along its axis are
//! muscles, driven by the cell's oscillator genes.
//!
//! Genome: `[2, nx, ny, nz, frequency]`, a material code per cell (x
//! fastest, then y, then z), then each cell's `amplitude, phase, offset`
//! (used while it is a muscle). A `neural` lattice's genome starts with 4
//! instead and each cell carries two more genes, the touch weights of its
//! muscles (each muscle feels the touch sensors at its own two ends, as a
//! graph body's muscle does). It develops into a [`Body`]: every check and
//! the rest of development are the graph's.

use super::genome::{Body, Edge, Muscle, Node};
use super::{Morphology, MorphologyEntry, MAX_CELLS};
use crate::build::At;
use crate::error::SceneError;
use animats_engine::DVec3;
use std::collections::BTreeMap;

/// The first gene of a lattice genome.
pub const LATTICE_TAG: f64 = 2.0;
/// The first gene of a `neural` lattice's genome.
pub const NEURAL_LATTICE_TAG: f64 = 4.0;

/// A cell's material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Material {
    /// No cell.
    Empty,
    /// Springs at the low end of the stiffness range.
    Soft,
    /// Springs at the high end.
    Rigid,
    /// Its edges along x are muscles.
    MuscleX,
    /// Along y.
    MuscleY,
    /// Along z.
    MuscleZ,
}

impl Material {
    /// Every material, by code.
    pub const ALL: [Material; 6] = [
        Material::Empty,
        Material::Soft,
        Material::Rigid,
        Material::MuscleX,
        Material::MuscleY,
        Material::MuscleZ,
    ];

    /// Its code in the genome.
    pub fn code(self) -> f64 {
        Material::ALL.iter().position(|m| *m == self).unwrap_or(0) as f64
    }

    fn from_code(x: f64) -> Option<Material> {
        if x >= 0.0 && x.fract() == 0.0 {
            Material::ALL.get(x as usize).copied()
        } else {
            None
        }
    }

    /// The axis its muscles lie along, if it is a muscle.
    fn axis(self) -> Option<usize> {
        match self {
            Material::MuscleX => Some(0),
            Material::MuscleY => Some(1),
            Material::MuscleZ => Some(2),
            _ => None,
        }
    }
}

/// `cells`, `cell` and `structure`, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// Cells along x, y, z.
    pub cells: [usize; 3],
    /// m.
    pub cell: f64,
    /// The starting body's materials (from `structure`), if given.
    pub start: Option<Vec<Material>>,
}

impl Shape {
    /// Cells in all.
    pub fn len(&self) -> usize {
        self.cells.iter().product()
    }

    /// True for a lattice of no cells (never, once checked).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub(crate) fn from_entry(at: &At, e: &MorphologyEntry) -> Result<Shape, SceneError> {
        let cells = e.cells.unwrap_or([5, 5, 2]);
        let n = cells
            .iter()
            .try_fold(1usize, |n, &c| n.checked_mul(c))
            .unwrap_or(usize::MAX);
        if cells.contains(&0) || n > MAX_CELLS {
            return Err(at.err(
                "cells",
                format!("{cells:?}: a lattice needs 1 to {MAX_CELLS} cells, at least one along each axis"),
            ));
        }
        let cell = at.positive("cell", e.cell.unwrap_or(0.08))?;
        let start = match &e.structure {
            None => None,
            Some(rows) => Some(evogym(at, rows, cells)?),
        };
        Ok(Shape { cells, cell, start })
    }

    fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.cells[0] * (y + self.cells[1] * z)
    }
}

/// An EvoGym structure (rows top to bottom; 0 empty, 1 rigid, 2 soft, 3
/// horizontal and 4 vertical muscle) extruded through every z layer.
fn evogym(at: &At, rows: &[Vec<i64>], cells: [usize; 3]) -> Result<Vec<Material>, SceneError> {
    if rows.len() != cells[1] || rows.iter().any(|r| r.len() != cells[0]) {
        return Err(at.err(
            "structure",
            format!(
                "must be {} rows of {} cells (cells = {cells:?}), got {} rows",
                cells[1],
                cells[0],
                rows.len()
            ),
        ));
    }
    let mut out = vec![Material::Empty; cells.iter().product()];
    for (r, row) in rows.iter().enumerate() {
        let y = cells[1] - 1 - r;
        for (x, &v) in row.iter().enumerate() {
            let m = match v {
                0 => Material::Empty,
                1 => Material::Rigid,
                2 => Material::Soft,
                3 => Material::MuscleX,
                4 => Material::MuscleY,
                _ => {
                    return Err(at.err(
                        "structure",
                        format!("row {r}, column {x}: {v} is not a material (0 empty, 1 rigid, 2 soft, 3 horizontal, 4 vertical muscle)"),
                    ))
                }
            };
            for z in 0..cells[2] {
                out[x + cells[0] * (y + cells[1] * z)] = m;
            }
        }
    }
    Ok(out)
}

/// A lattice genome, decoded.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice {
    /// Each cell's material.
    pub materials: Vec<Material>,
    /// Each cell's muscle genes.
    pub muscles: Vec<Muscle>,
    /// Hz.
    pub frequency: f64,
    /// Its muscles feel touch (`controller = "neural"`): each cell's genes
    /// carry two touch weights.
    pub neural: bool,
}

impl Lattice {
    /// The genes (see the module).
    pub fn to_genes(&self, shape: &Shape) -> Vec<f64> {
        let mut g = vec![
            if self.neural {
                NEURAL_LATTICE_TAG
            } else {
                LATTICE_TAG
            },
            shape.cells[0] as f64,
            shape.cells[1] as f64,
            shape.cells[2] as f64,
            self.frequency,
        ];
        g.extend(self.materials.iter().map(|m| m.code()));
        for m in &self.muscles {
            g.extend([m.amplitude, m.phase, m.offset]);
            if self.neural {
                g.extend(m.touch);
            }
        }
        g
    }

    /// Reads the genes of a lattice of `shape`; anything else is refused.
    pub fn from_genes(g: &[f64], shape: &Shape) -> Result<Lattice, String> {
        if let Some(i) = g.iter().position(|x| !x.is_finite()) {
            return Err(format!("gene {i} is not finite: {}", g[i]));
        }
        let n = shape.len();
        let neural = g.first() == Some(&NEURAL_LATTICE_TAG);
        let per_cell = if neural { 5 } else { 3 };
        let head = [
            if neural {
                NEURAL_LATTICE_TAG
            } else {
                LATTICE_TAG
            },
            shape.cells[0] as f64,
            shape.cells[1] as f64,
            shape.cells[2] as f64,
        ];
        if g.len() != 5 + (1 + per_cell) * n || g[..4.min(g.len())] != head {
            return Err(format!(
                "not a lattice genome of {:?} cells: it must start {head:?} and hold {} genes",
                shape.cells,
                5 + (1 + per_cell) * n
            ));
        }
        let materials = g[5..5 + n]
            .iter()
            .enumerate()
            .map(|(i, &x)| Material::from_code(x).ok_or(format!("cell {i}: {x} is not a material")))
            .collect::<Result<_, _>>()?;
        let muscles = g[5 + n..]
            .chunks_exact(per_cell)
            .map(|c| Muscle {
                amplitude: c[0],
                phase: c[1],
                offset: c[2],
                touch: if neural { [c[3], c[4]] } else { [0.0; 2] },
                duty: 0.5,
            })
            .collect();
        Ok(Lattice {
            materials,
            muscles,
            frequency: g[4],
            neural,
        })
    }

    /// The body the lattice grows into: a particle at every corner of a
    /// painted cell, springs along every edge and face diagonal (the
    /// stiffer material wins an edge two cells share, and a muscle wins
    /// over a plain spring), each corner weighing an eighth of each cell it
    /// belongs to, a cell weighing the mass budget over the lattice's cells.
    pub fn develop(&self, shape: &Shape, m: &Morphology) -> Body {
        let cell_mass = m.total_mass / shape.len() as f64;
        let radius = (shape.cell / 4.0).clamp(m.radius.0, m.radius.1);
        let mut corners: BTreeMap<[usize; 3], usize> = BTreeMap::new();
        let mut nodes: Vec<Node> = Vec::new();
        let mut edges: BTreeMap<(usize, usize), Edge> = BTreeMap::new();
        let [nx, ny, nz] = shape.cells;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let c = shape.index(x, y, z);
                    let material = self.materials[c];
                    if material == Material::Empty {
                        continue;
                    }
                    let mut ids = [0usize; 8];
                    for (k, id) in ids.iter_mut().enumerate() {
                        let at = [x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1)];
                        let next = nodes.len();
                        *id = *corners.entry(at).or_insert(next);
                        if *id == next {
                            nodes.push(Node {
                                position: DVec3::new(at[0] as f64, at[1] as f64, at[2] as f64)
                                    * shape.cell,
                                mass: 0.0,
                                radius,
                            });
                        }
                        nodes[*id].mass += cell_mass / 8.0;
                    }
                    cell_springs(&ids, material, self.muscles[c], m, &mut edges);
                }
            }
        }
        Body {
            nodes,
            edges: edges.into_values().collect(),
            frequency: self.frequency,
            neural: self.neural,
            skewed: false,
        }
    }
}

/// Adds a cell's springs: corner `k`'s offset is `(k & 1, k >> 1 & 1, k >> 2 & 1)`;
/// two corners share an edge when they differ in one bit, a face diagonal
/// when in two.
fn cell_springs(
    ids: &[usize; 8],
    material: Material,
    genes: Muscle,
    m: &Morphology,
    edges: &mut BTreeMap<(usize, usize), Edge>,
) {
    let stiffness = match material {
        Material::Soft => m.stiffness.0,
        _ => m.stiffness.1,
    };
    for i in 0..8usize {
        for j in i + 1..8 {
            let differ = (i ^ j).count_ones();
            if differ == 3 {
                continue;
            }
            let along = (i ^ j).trailing_zeros() as usize;
            let muscle = (differ == 1 && material.axis() == Some(along)).then_some(genes);
            let (a, b) = (ids[i].min(ids[j]), ids[i].max(ids[j]));
            let new = Edge {
                a,
                b,
                stiffness,
                muscle,
            };
            edges
                .entry((a, b))
                .and_modify(|e| {
                    e.stiffness = e.stiffness.max(stiffness);
                    if e.muscle.is_none() {
                        e.muscle = muscle;
                    }
                })
                .or_insert(new);
        }
    }
}
