//! The ground's shape: the flat floor y = 0 (thesis §3.1.3.1), a slope, a
//! flight of steps, or a heightfield.
//!
//! The floor's collision event and contact force ask the terrain one
//! question, [`Terrain::probe`]: the signed distance from a sphere's centre
//! to the surface (negative below it) and the surface's outward normal at
//! the nearest point. A sphere collides when that distance is less than its
//! radius, and is moved out and reflected along that normal; it rests and
//! rubs in the plane perpendicular to it. For the flat floor the distance is
//! `y` and the normal `+y`, exactly the thesis's floor; every other terrain
//! gives the exact distance to its surface (a plane; the treads and risers
//! of the steps, their edges rounded by the distance; the triangles of the
//! heightfield), so a sphere rolling over an edge meets it at the point of
//! contact, not at a face's extension.

use crate::error::ModelError;
use glam::{DVec2, DVec3};

/// The ground's shape.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Terrain {
    /// The plane y = 0.
    #[default]
    Flat,
    /// A plane through the origin, rising along a direction.
    Slope(Slope),
    /// Flat ground, then a flight of steps along a direction, then flat.
    Steps(Steps),
    /// Heights on a square grid, joined by two triangles per cell.
    Heightfield(Heightfield),
}

/// A plane through the origin rising at `angle` along `uphill`.
#[derive(Clone, Debug, PartialEq)]
pub struct Slope {
    /// rad, in [0, π/2).
    pub angle: f64,
    /// Unit horizontal direction the ground rises along.
    pub uphill: DVec3,
}

/// Flat ground (y = 0) up to `start` along `direction`, then `count` steps
/// each `height` higher (lower, if negative) and `depth` deep, then flat.
#[derive(Clone, Debug, PartialEq)]
pub struct Steps {
    /// Unit horizontal direction the steps go along.
    pub direction: DVec3,
    /// Where the first riser stands, m along `direction` from the origin.
    pub start: f64,
    /// Rise of each step, m (negative: steps down).
    pub height: f64,
    /// Tread of each step, m (> 0).
    pub depth: f64,
    /// Number of steps.
    pub count: u32,
}

/// Heights on a grid: vertex (i, j) at x = `origin.x + i·cell`, z =
/// `origin.y + j·cell`, height `heights[j·nx + i]`; each cell is split
/// into two triangles along its diagonal from (i, j) to (i + 1, j + 1).
/// Beyond the grid the edge's heights go on (the vertex indices are
/// clamped), so the ground has no cliff at its border.
#[derive(Clone, Debug, PartialEq)]
pub struct Heightfield {
    /// x and z of vertex (0, 0), m.
    pub origin: DVec2,
    /// Grid spacing, m (> 0).
    pub cell: f64,
    /// Vertices along x.
    pub nx: usize,
    /// Vertices along z.
    pub nz: usize,
    /// nx·nz heights, row by row along x, m.
    pub heights: Vec<f64>,
    /// The steepest triangle's gradient (set by [`Heightfield::new`]).
    steepest: f64,
}

/// Up.
const UP: DVec3 = DVec3::Y;

impl Terrain {
    /// Whether this is the plane y = 0.
    pub fn is_flat(&self) -> bool {
        matches!(self, Terrain::Flat)
    }

    /// Checks the shape's numbers.
    pub fn validate(&self) -> Result<(), ModelError> {
        let finite = |field: &str, x: f64| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(ModelError::new(field, format!("must be finite, got {x}")))
            }
        };
        let horizontal = |field: &str, d: DVec3| {
            if !d.is_finite() || d.y != 0.0 || (d.length() - 1.0).abs() > 1e-9 {
                return Err(ModelError::new(
                    field,
                    format!("must be a horizontal unit vector (y = 0), got {d}"),
                ));
            }
            Ok(())
        };
        match self {
            Terrain::Flat => Ok(()),
            Terrain::Slope(s) => {
                horizontal("direction", s.uphill)?;
                // (A microradian short of vertical: the height's slope,
                // tan θ, stays finite and its normal computable.)
                let steepest = std::f64::consts::FRAC_PI_2 - 1e-6;
                if !(0.0..steepest).contains(&s.angle) {
                    return Err(ModelError::new(
                        "angle",
                        format!(
                            "must be at least 0° and under {:.5}° (90° less a microradian), got {}°",
                            steepest.to_degrees(),
                            s.angle.to_degrees()
                        ),
                    ));
                }
                Ok(())
            }
            Terrain::Steps(s) => {
                horizontal("direction", s.direction)?;
                finite("start", s.start)?;
                finite("height", s.height)?;
                if !(s.depth > 0.0 && s.depth.is_finite()) {
                    return Err(ModelError::new(
                        "depth",
                        format!("must be > 0, got {}", s.depth),
                    ));
                }
                Ok(())
            }
            Terrain::Heightfield(h) => {
                if !(h.cell > 0.0 && h.cell.is_finite()) {
                    return Err(ModelError::new(
                        "cell",
                        format!("must be > 0, got {}", h.cell),
                    ));
                }
                finite("origin", h.origin.x + h.origin.y)?;
                if h.nx < 2 || h.nz < 2 || h.heights.len() != h.nx * h.nz {
                    return Err(ModelError::new(
                        "heights",
                        format!(
                            "needs at least 2 × 2 heights, {} × {} = {} of them; got {}",
                            h.nx,
                            h.nz,
                            h.nx * h.nz,
                            h.heights.len()
                        ),
                    ));
                }
                if let Some(k) = h.heights.iter().position(|y| !y.is_finite()) {
                    return Err(ModelError::new(
                        "heights",
                        format!("height {k} is {}", h.heights[k]),
                    ));
                }
                Ok(())
            }
        }
    }

    /// The ground's height under (x, z), m.
    pub fn height(&self, x: f64, z: f64) -> f64 {
        match self {
            Terrain::Flat => 0.0,
            Terrain::Slope(s) => crate::math::tan(s.angle) * (s.uphill.x * x + s.uphill.z * z),
            Terrain::Steps(s) => s.profile(s.direction.x * x + s.direction.z * z),
            Terrain::Heightfield(h) => h.height(x, z),
        }
    }

    /// The signed distance from `p` to the surface (negative below it), m,
    /// and the surface's outward unit normal at the nearest point; `None`
    /// when `p` is certainly more than `reach` above the surface.
    #[inline]
    pub fn probe(&self, p: DVec3, reach: f64) -> Option<(f64, DVec3)> {
        match self {
            Terrain::Flat => (p.y <= reach).then_some((p.y, UP)),
            Terrain::Slope(s) => {
                let n = s.normal();
                let d = p.dot(n);
                (d <= reach).then_some((d, n))
            }
            Terrain::Steps(s) => s.probe(p, reach),
            Terrain::Heightfield(h) => h.probe(p, reach),
        }
    }
}

impl Slope {
    /// The surface's outward unit normal.
    #[inline]
    pub fn normal(&self) -> DVec3 {
        let (sin, cos) = crate::math::sincos(self.angle);
        UP * cos - self.uphill * sin
    }
}

/// How far (in cells) a cell's index may lie from the field's origin
/// before it is held there (`Heightfield::cell_of`): 2⁶², so that the
/// cells searched around it (at most 8 further) stay within an `i64`.
const FAR_CELLS: f64 = (1u64 << 62) as f64;

/// The cells around a probe `vertical` m above (or below) a field of
/// `cell` m to search for its nearest point: as many as that distance
/// spans, plus one, at most 8 (compared before the cast: a blown-up
/// distance saturated `as i64` and the `+ 1` overflowed).
fn span_for(vertical: f64, cell: f64) -> i64 {
    let cells = (vertical.abs() / cell).ceil();
    if cells >= 7.0 {
        8
    } else {
        cells as i64 + 1
    }
}

impl Steps {
    /// Which tread lies under `s` (0 before the first riser, `count` on top).
    fn tread(&self, s: f64) -> i64 {
        if s < self.start {
            return 0;
        }
        // (Compared before the cast: far along, `as i64` saturates and the
        // `+ 1` overflowed.)
        let t = ((s - self.start) / self.depth).floor();
        if t >= f64::from(self.count) {
            i64::from(self.count)
        } else {
            (t as i64 + 1).min(i64::from(self.count))
        }
    }

    /// The height of the ground `s` m along the direction.
    pub fn profile(&self, s: f64) -> f64 {
        self.tread(s) as f64 * self.height
    }

    /// Riser `j`'s place along the direction (1 ≤ j ≤ count).
    fn riser(&self, j: i64) -> f64 {
        self.start + (j - 1) as f64 * self.depth
    }

    fn probe(&self, p: DVec3, reach: f64) -> Option<(f64, DVec3)> {
        let d = self.direction;
        let q = DVec2::new(p.x * d.x + p.z * d.z, p.y);
        let k = self.tread(q.x);
        let below = q.y < self.profile(q.x);
        // Every tread and riser within two of the one under the centre: the
        // nearest for any sphere less than a tread deep.
        let n = i64::from(self.count);
        let (mut best, mut nearest) = (f64::INFINITY, q);
        let mut consider = |c: DVec2| {
            let d2 = (q - c).length_squared();
            if d2 < best {
                (best, nearest) = (d2, c);
            }
        };
        for j in (k - 2).max(0)..=(k + 2).min(n) {
            // Tread j, from its riser (none before the first) to the next.
            let y = j as f64 * self.height;
            let from = if j == 0 {
                f64::NEG_INFINITY
            } else {
                self.riser(j)
            };
            let to = if j == n {
                f64::INFINITY
            } else {
                self.riser(j + 1)
            };
            consider(DVec2::new(q.x.clamp(from, to), y));
            if j >= 1 {
                // Riser j, from tread j - 1 to tread j.
                let (y0, y1) = ((j - 1) as f64 * self.height, y);
                consider(DVec2::new(self.riser(j), q.y.clamp(y0.min(y1), y0.max(y1))));
            }
        }
        let distance = best.sqrt();
        if !below && distance > reach {
            return None;
        }
        let away = q - nearest;
        let normal2 = if distance > 1e-12 {
            if below {
                -away / distance
            } else {
                away / distance
            }
        } else if (nearest.x - self.riser(k.max(1))).abs() < 1e-12 && k >= 1 {
            // On a riser's face: it faces down the flight.
            DVec2::new(-self.height.signum(), 0.0)
        } else {
            DVec2::Y
        };
        let normal = d * normal2.x + UP * normal2.y;
        Some((if below { -distance } else { distance }, normal))
    }
}

impl Heightfield {
    /// A heightfield; see the type's documentation for the layout.
    pub fn new(origin: DVec2, cell: f64, nx: usize, nz: usize, heights: Vec<f64>) -> Self {
        let mut h = Heightfield {
            origin,
            cell,
            nx,
            nz,
            heights,
            steepest: 0.0,
        };
        if h.heights.len() == nx * nz && nx >= 2 && nz >= 2 {
            let mut steepest = 0.0f64;
            for j in 0..nz as i64 - 1 {
                for i in 0..nx as i64 - 1 {
                    for t in h.triangles(i, j) {
                        let n = (t[1] - t[0]).cross(t[2] - t[0]);
                        steepest = steepest.max(DVec2::new(n.x, n.z).length() / n.y.abs());
                    }
                }
            }
            h.steepest = steepest;
        }
        h
    }

    /// The cosine of the steepest triangle's slope.
    #[inline]
    pub fn steepest_cos(&self) -> f64 {
        1.0 / (1.0 + self.steepest * self.steepest).sqrt()
    }

    /// Vertex (i, j), its indices clamped to the grid.
    fn vertex(&self, i: i64, j: i64) -> DVec3 {
        let (ci, cj) = (
            i.clamp(0, self.nx as i64 - 1) as usize,
            j.clamp(0, self.nz as i64 - 1) as usize,
        );
        DVec3::new(
            self.origin.x + i as f64 * self.cell,
            self.heights[cj * self.nx + ci],
            self.origin.y + j as f64 * self.cell,
        )
    }

    /// Cell (i, j)'s two triangles, counter-clockwise seen from above.
    fn triangles(&self, i: i64, j: i64) -> [[DVec3; 3]; 2] {
        let (a, b) = (self.vertex(i, j), self.vertex(i + 1, j));
        let (c, d) = (self.vertex(i + 1, j + 1), self.vertex(i, j + 1));
        [[a, c, b], [a, d, c]]
    }

    /// The cell under (x, z) and where in it, in cells.
    fn cell_of(&self, x: f64, z: f64) -> (i64, i64, f64, f64) {
        let (u, v) = (
            (x - self.origin.x) / self.cell,
            (z - self.origin.y) / self.cell,
        );
        let (i, j) = (u.floor(), v.floor());
        // The index held within ±2⁶² cells: a blown-up particle's
        // saturated `as i64` and the next cell's index overflowed (the
        // search reaches 8 cells past it).
        let index = |k: f64| k.clamp(-FAR_CELLS, FAR_CELLS) as i64;
        (index(i), index(j), u - i, v - j)
    }

    /// The surface's height under (x, z), m.
    pub fn height(&self, x: f64, z: f64) -> f64 {
        let (i, j, fu, fv) = self.cell_of(x, z);
        let (a, b) = (self.vertex(i, j).y, self.vertex(i + 1, j).y);
        let (c, d) = (self.vertex(i + 1, j + 1).y, self.vertex(i, j + 1).y);
        if fu >= fv {
            // Triangle a, b, c.
            a + fu * (b - a) + fv * (c - b)
        } else {
            // Triangle a, c, d.
            a + fv * (d - a) + fu * (c - d)
        }
    }

    fn probe(&self, p: DVec3, reach: f64) -> Option<(f64, DVec3)> {
        let vertical = p.y - self.height(p.x, p.z);
        // Above a surface no steeper than `steepest`, the distance is at
        // least the height over it times the cosine of that slope; below
        // it, the signed distance is at least `vertical` (a negative reach).
        let least = if vertical >= 0.0 {
            vertical * self.steepest_cos()
        } else {
            vertical
        };
        if least > reach {
            return None;
        }
        // The nearest point is no farther than the point straight below (or
        // above), so it lies within |vertical| of (x, z) across.
        // (Capped: past 8 cells the nearest of those searched is taken.)
        let span = span_for(vertical, self.cell);
        let (i0, j0, _, _) = self.cell_of(p.x, p.z);
        let (best, nearest, face) = self.nearest_within(p, i0, j0, span, true);
        let below = vertical < 0.0;
        let distance = best.sqrt();
        let normal = if distance > 1e-12 {
            let away = (p - nearest) / distance;
            if below {
                -away
            } else {
                away
            }
        } else {
            face
        };
        Some((if below { -distance } else { distance }, normal))
    }

    /// The nearest point to `p` on the triangles of cells `i0 ± span`, `j0
    /// ± span`: its squared distance, the point, and its triangle's unit
    /// normal. The cells are visited row by row (`j`, then `i`, each
    /// rising), each cell's two triangles in turn, and a triangle replaces
    /// the nearest so far only when strictly nearer: the first of equally
    /// near ones is kept.
    ///
    /// With `prune`, a cell whose footprint lies farther across from `p`
    /// than the nearest point found so far (at first, on the centre cell's
    /// triangles) is passed over. No triangle it holds could be as near,
    /// so the nearest is the same triangle, and the same bits, as with
    /// every cell visited (`tests::pruning_changes_no_bit`): the margin, a
    /// billionth of the distance and a millionth of the cell and of `p`'s
    /// coordinates, is far above the rounding of a triangle's nearest
    /// point. Resting on the ground, a sphere's search falls from the
    /// 5 × 5 cells around it to the one or few it overhangs.
    fn nearest_within(
        &self,
        p: DVec3,
        i0: i64,
        j0: i64,
        span: i64,
        prune: bool,
    ) -> (f64, DVec3, DVec3) {
        let tolerance = 1e-6 * (self.cell + p.x.abs() + p.z.abs());
        let radius = |d2: f64| {
            if prune && d2.is_finite() {
                d2.sqrt() * (1.0 + 1e-9) + tolerance
            } else {
                f64::INFINITY
            }
        };
        let mut r = radius(
            self.triangles(i0, j0)
                .map(|t| (p - nearest_on_triangle(p, t)).length_squared())
                .into_iter()
                .fold(f64::INFINITY, f64::min),
        );
        // How far across `c` lies from the footprint [from, from + cell).
        let gap = |c: f64, from: f64, to: f64| (from - c).max(c - to).max(0.0);
        let (mut best, mut nearest, mut face) = (f64::INFINITY, p, UP);
        for j in j0 - span..=j0 + span {
            let z0 = self.origin.y + j as f64 * self.cell;
            let dz = gap(p.z, z0, self.origin.y + (j + 1) as f64 * self.cell);
            if dz > r {
                if z0 > p.z {
                    break; // every later row lies farther still
                }
                continue;
            }
            for i in i0 - span..=i0 + span {
                let x0 = self.origin.x + i as f64 * self.cell;
                let dx = gap(p.x, x0, self.origin.x + (i + 1) as f64 * self.cell);
                if dx * dx + dz * dz > r * r {
                    if x0 > p.x {
                        break;
                    }
                    continue;
                }
                for t in self.triangles(i, j) {
                    let c = nearest_on_triangle(p, t);
                    let d2 = (p - c).length_squared();
                    if d2 < best {
                        (best, nearest) = (d2, c);
                        face = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                        r = r.min(radius(d2));
                    }
                }
            }
        }
        (best, nearest, face)
    }
}

/// The nearest point to `p` on triangle `t` (Ericson, *Real-Time Collision
/// Detection*, §5.1.5).
fn nearest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_heightfields_height_interpolates_its_triangles() {
        // A tilted plane sampled on a grid is the same plane.
        let (nx, nz) = (4, 3);
        let plane = |x: f64, z: f64| 0.2 * x - 0.1 * z + 0.05;
        let mut heights = Vec::new();
        for j in 0..nz {
            for i in 0..nx {
                heights.push(plane(0.5 * i as f64 - 1.0, 0.5 * j as f64 + 0.25));
            }
        }
        let h = Heightfield::new(DVec2::new(-1.0, 0.25), 0.5, nx, nz, heights);
        for (x, z) in [(-0.9, 0.3), (0.2, 0.7), (0.49, 1.2), (-0.25, 0.26)] {
            assert!((h.height(x, z) - plane(x, z)).abs() < 1e-12, "{x}, {z}");
            // Straight above it, the distance is the height times cos θ.
            let n = DVec3::new(-0.2, 1.0, 0.1).normalize();
            let p = DVec3::new(x, plane(x, z) + 0.01, z);
            let (d, normal) = h.probe(p, 1.0).unwrap();
            assert!((d - 0.01 * n.y).abs() < 1e-12, "{d}");
            assert!((normal - n).length() < 1e-9, "{normal}");
        }
        // A point high above is refused cheaply.
        assert!(h.probe(DVec3::new(0.0, 5.0, 0.5), 0.1).is_none());
    }

    /// The pruned search of `Heightfield::probe` against every cell of
    /// the span, on random grids from flat to cliffs of 10⁴ cells a cell,
    /// some with heights on a coarse lattice (equal heights: ties between
    /// triangles), and points from on the surface to twenty cells off it,
    /// some exactly over vertices and grid lines: the same squared
    /// distance, nearest point and face, bit for bit.
    #[test]
    fn pruning_changes_no_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut probes, mut pruned_away) = (0, 0);
        for field in 0..60 {
            let cell = [0.1, 0.5, 0.013, 2.0][field % 4];
            let relief = cell * [0.0, 0.15, 1.0, 10.0, 1e4][field / 4 % 5];
            let lattice = field / 20 == 1;
            let (nx, nz) = (
                2 + (uniform() * 12.0) as usize,
                2 + (uniform() * 12.0) as usize,
            );
            let heights = (0..nx * nz)
                .map(|_| {
                    let y = relief * (uniform() - 0.5);
                    if lattice {
                        (y / (0.25 * relief + 1e-300)).round() * 0.25 * relief
                    } else {
                        y
                    }
                })
                .collect();
            let origin = DVec2::new(uniform() * 4.0 - 2.0, uniform() * 4.0 - 2.0);
            let h = Heightfield::new(origin, cell, nx, nz, heights);
            for k in 0..4000 {
                let (mut x, mut z) = (
                    origin.x + cell * (uniform() * (nx as f64 + 4.0) - 2.0),
                    origin.y + cell * (uniform() * (nz as f64 + 4.0) - 2.0),
                );
                if k % 5 == 0 {
                    x = origin.x + cell * ((x - origin.x) / cell).round();
                }
                if k % 7 == 0 {
                    z = origin.y + cell * ((z - origin.y) / cell).round();
                }
                // Up to twenty cells off, or anywhere within the relief (by
                // the cliffs of the steepest fields, nearly level with them).
                let scale = [
                    0.0,
                    1e-3 * cell,
                    0.1 * cell,
                    0.5 * cell,
                    2.0 * cell,
                    20.0 * cell,
                    relief,
                ][k % 7];
                let p = DVec3::new(x, h.height(x, z) + scale * (2.0 * uniform() - 1.0), z);
                let vertical = p.y - h.height(p.x, p.z);
                let span = span_for(vertical, cell);
                let (i0, j0, _, _) = h.cell_of(p.x, p.z);
                let (d2, q, n) = h.nearest_within(p, i0, j0, span, true);
                let (d2_all, q_all, n_all) = h.nearest_within(p, i0, j0, span, false);
                let bits = |v: DVec3| v.to_array().map(f64::to_bits);
                assert_eq!(
                    (d2.to_bits(), bits(q), bits(n)),
                    (d2_all.to_bits(), bits(q_all), bits(n_all)),
                    "field {field}, probe {k} at {p}"
                );
                probes += 1;
                // How many cells the pruning passed over.
                let r = d2.sqrt();
                pruned_away += (j0 - span..=j0 + span)
                    .flat_map(|j| (i0 - span..=i0 + span).map(move |i| (i, j)))
                    .filter(|&(i, j)| {
                        let gap = |c: f64, from: f64| (from - c).max(c - from - cell).max(0.0);
                        let dx = gap(p.x, origin.x + i as f64 * cell);
                        let dz = gap(p.z, origin.y + j as f64 * cell);
                        (dx * dx + dz * dz).sqrt() > 1.01 * r + 1e-3 * cell
                    })
                    .count();
            }
        }
        // The pruning had work to do: most cells of the spans lie too far.
        assert!(
            pruned_away > 10 * probes,
            "{pruned_away} cells of {probes} probes"
        );
    }

    #[test]
    fn a_steps_edge_is_met_at_the_edge() {
        let s = Steps {
            direction: DVec3::X,
            start: 1.0,
            height: 0.1,
            depth: 0.5,
            count: 3,
        };
        // On the first tread, on top, before the flight.
        for (at, y) in [(0.9, 0.0), (1.2, 0.1), (1.7, 0.2), (9.0, 0.3)] {
            assert!((s.profile(at) - y).abs() < 1e-15, "{at}: {}", s.profile(at));
        }
        // Straight above a tread: its height.
        let (d, n) = s.probe(DVec3::new(1.25, 0.15, 0.0), 1.0).unwrap();
        assert!((d - 0.05).abs() < 1e-12 && n == UP, "{d} {n}");
        // In front of the first riser, at half its height: the riser.
        let (d, n) = s.probe(DVec3::new(0.97, 0.06, 0.3), 1.0).unwrap();
        assert!((d - 0.03).abs() < 1e-12 && (n + DVec3::X).length() < 1e-12);
        // Beyond the edge's corner: the distance to the corner.
        let p = DVec3::new(0.97, 0.14, 0.0);
        let (d, n) = s.probe(p, 1.0).unwrap();
        let corner = DVec3::new(1.0, 0.1, 0.0);
        assert!((d - (p - corner).length()).abs() < 1e-12);
        assert!((n - (p - corner).normalize()).length() < 1e-12);
        // Inside the step: negative.
        let (d, _) = s.probe(DVec3::new(1.1, 0.09, 0.0), 1.0).unwrap();
        assert!((d + 0.01).abs() < 1e-12, "{d}");
    }
}
