//! The ground's shape as triangles, when the floor is not the plane y = 0:
//! the page draws the mesh, the renderer ray-casts it. The mesh is the
//! terrain's own surface (a slope's plane, the steps' treads and risers,
//! the heightfield's triangles), reaching [`FAR`] m out on every side.

use animats_engine::{DVec3, Terrain};
use serde::Serialize;

/// How far the ground's mesh reaches from the origin, m (the fog hides its
/// edge).
pub const FAR: f64 = 200.0;

/// Heightfields with more vertices than this are drawn from every k-th
/// height, so that the page gets a mesh it can hold.
const MOST_VERTICES: usize = 250_000;

/// Triangles: `positions` holds x, y, z of each vertex, `triangles` three
/// vertex indices each, counter-clockwise seen from above (from the front
/// of a riser).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GroundMesh {
    /// x, y, z per vertex, m.
    pub positions: Vec<f64>,
    /// Three vertex indices per triangle.
    pub triangles: Vec<u32>,
}

impl GroundMesh {
    fn vertex(&mut self, p: DVec3) -> u32 {
        let k = (self.positions.len() / 3) as u32;
        self.positions.extend([p.x, p.y, p.z]);
        k
    }

    /// The quad a, b, c, d (counter-clockwise seen from its front).
    fn quad(&mut self, [a, b, c, d]: [DVec3; 4]) {
        let (a, b, c, d) = (
            self.vertex(a),
            self.vertex(b),
            self.vertex(c),
            self.vertex(d),
        );
        self.triangles.extend([a, b, c, a, c, d]);
    }

    /// Vertex `k`.
    pub fn point(&self, k: u32) -> DVec3 {
        let k = 3 * k as usize;
        DVec3::new(
            self.positions[k],
            self.positions[k + 1],
            self.positions[k + 2],
        )
    }

    /// Each triangle's three corners.
    pub fn corners(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.triangles
            .chunks_exact(3)
            .map(|t| [self.point(t[0]), self.point(t[1]), self.point(t[2])])
    }
}

/// The mesh of `terrain`; `None` for the flat floor (drawn as a plane).
pub fn mesh(terrain: &Terrain) -> Option<GroundMesh> {
    let mut m = GroundMesh::default();
    match terrain {
        Terrain::Flat => return None,
        Terrain::Slope(_) => {
            let at = |x: f64, z: f64| DVec3::new(x, terrain.height(x, z), z);
            m.quad([at(-FAR, -FAR), at(-FAR, FAR), at(FAR, FAR), at(FAR, -FAR)]);
        }
        Terrain::Steps(s) => {
            // Along d, across e (d × up), treads then risers.
            let (d, e) = (s.direction, s.direction.cross(DVec3::Y));
            let at = |along: f64, across: f64, y: f64| d * along + e * across + DVec3::Y * y;
            let riser = |j: u32| s.start + f64::from(j - 1) * s.depth;
            for j in 0..=s.count {
                let y = f64::from(j) * s.height;
                let from = if j == 0 { -FAR } else { riser(j) };
                let to = if j == s.count { FAR } else { riser(j + 1) };
                m.quad([
                    at(from, -FAR, y),
                    at(from, FAR, y),
                    at(to, FAR, y),
                    at(to, -FAR, y),
                ]);
                if j >= 1 {
                    let (x, low) = (riser(j), y - s.height);
                    m.quad([
                        at(x, -FAR, low),
                        at(x, -FAR, y),
                        at(x, FAR, y),
                        at(x, FAR, low),
                    ]);
                }
            }
        }
        Terrain::Heightfield(h) => {
            let every = (h.nx * h.nz).div_ceil(MOST_VERTICES).max(1);
            let every = (every as f64).sqrt().ceil() as usize;
            // The grid's vertices (every `every`-th, and the last), and a
            // ring FAR out at the edge's heights.
            let axis = |n: usize, origin: f64| {
                let end = origin + (n - 1) as f64 * h.cell;
                let mut v: Vec<(f64, usize)> = vec![((origin - h.cell).min(-FAR), 0)];
                v.extend(
                    (0..n)
                        .step_by(every)
                        .map(|i| (origin + i as f64 * h.cell, i)),
                );
                if !(n - 1).is_multiple_of(every) {
                    v.push((end, n - 1));
                }
                v.push(((end + h.cell).max(FAR), n - 1));
                v
            };
            let (xs, zs) = (axis(h.nx, h.origin.x), axis(h.nz, h.origin.y));
            let first = m.positions.len() / 3;
            for &(z, j) in &zs {
                for &(x, i) in &xs {
                    m.vertex(DVec3::new(x, h.heights[j * h.nx + i], z));
                }
            }
            let k = |i: usize, j: usize| (first + j * xs.len() + i) as u32;
            for j in 0..zs.len() - 1 {
                for i in 0..xs.len() - 1 {
                    let (a, b, c, d) = (k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1));
                    // The engine's split: a–c diagonal.
                    m.triangles.extend([a, c, b, a, d, c]);
                }
            }
        }
    }
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use animats_engine::{DVec2, Heightfield, Slope, Steps};

    /// Every vertex lies on the terrain (at its height, or on a riser).
    fn on_surface(t: &Terrain) {
        let m = mesh(t).unwrap();
        for k in 0..m.positions.len() as u32 / 3 {
            let p = m.point(k);
            let (d, _) = t.probe(p, 1.0).unwrap();
            assert!(d.abs() < 1e-9, "{p}: {d} off");
        }
        // Up-facing triangles face up.
        for [a, b, c] in m.corners() {
            let n = (b - a).cross(c - a);
            assert!(n.y >= -1e-9, "{a} {b} {c}: {n}");
        }
    }

    #[test]
    fn the_mesh_lies_on_the_terrain() {
        on_surface(&Terrain::Slope(Slope {
            angle: 0.2,
            uphill: DVec3::new(0.6, 0.0, -0.8),
        }));
        on_surface(&Terrain::Steps(Steps {
            direction: DVec3::Z,
            start: 0.5,
            height: 0.1,
            depth: 0.3,
            count: 4,
        }));
        let heights = (0..12).map(|k| 0.01 * f64::from(k % 5)).collect();
        on_surface(&Terrain::Heightfield(Heightfield::new(
            DVec2::new(-0.2, 0.1),
            0.1,
            4,
            3,
            heights,
        )));
        assert!(mesh(&Terrain::Flat).is_none());
    }
}
