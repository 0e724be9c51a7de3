//! Handling the contacts found: in up to [`PASSES`] passes, each contact in
//! turn is parted, its approach reversed or stopped, and its sliding
//! opposed by friction (see the module above).

use super::sleep::Sleep;
use super::{Impact, Pair, SphereContact, SphereContactDef, FLOOR_TOLERANCE, PASSES, SETTLED};
use crate::particle::{ParticleId, Properties};
use glam::DVec3;

/// `[a₀ / b₀, a₁ / b₁]`, in one instruction on x86-64: each quotient is
/// correctly rounded either way, so the bits are those of two divisions,
/// for half the divider's time (the contact handling waits on it).
#[inline(always)]
fn div2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_div_pd, _mm_set_pd, _mm_unpackhi_pd};
        // SAFETY: SSE2 is part of x86-64, so every x86-64 CPU has these
        // instructions; they read and write only registers.
        unsafe {
            let q = _mm_div_pd(_mm_set_pd(a[1], a[0]), _mm_set_pd(b[1], b[0]));
            [_mm_cvtsd_f64(q), _mm_cvtsd_f64(_mm_unpackhi_pd(q, q))]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [a[0] / b[0], a[1] / b[1]]
    }
}

/// `[√x₀, √x₁]`, in one instruction on x86-64 (correctly rounded either way).
#[inline(always)]
fn sqrt2(x: [f64; 2]) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_set_pd, _mm_sqrt_pd, _mm_unpackhi_pd};
        // SAFETY: as in `div2`.
        unsafe {
            let r = _mm_sqrt_pd(_mm_set_pd(x[1], x[0]));
            [_mm_cvtsd_f64(r), _mm_cvtsd_f64(_mm_unpackhi_pd(r, r))]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [x[0].sqrt(), x[1].sqrt()]
    }
}

/// What every contact of one handling shares.
struct Handling<'a> {
    def: &'a SphereContactDef,
    p: &'a Properties,
    /// The spheres the floor holds up.
    floor: &'a Option<Vec<bool>>,
    /// The step, s.
    h: f64,
    /// How far apart a pair still counts as a contact, m.
    margin: f64,
    /// When, s (for the impacts).
    t: f64,
}

impl Handling<'_> {
    /// Whether the floor holds sphere `i` up.
    fn held(&self, i: usize) -> bool {
        self.floor
            .as_ref()
            .is_some_and(|f| f.get(i).copied().unwrap_or(false))
    }

    /// Handles contact `q` once (in pass `pass`); returns the overlap it
    /// corrected, m (0 if none).
    fn contact(
        &self,
        q: &Pair,
        pass: usize,
        pos: &mut [DVec3],
        vel: &mut [DVec3],
        sleep: &mut Sleep,
        impacts: &mut Vec<Impact>,
    ) -> f64 {
        let p = self.p;
        let (a, b) = (q.a as usize, q.b as usize);
        let d = pos[b] - pos[a];
        let dist = d.length();
        let reach = p.radius[a] + p.radius[b];
        let overlap = reach - dist;
        if overlap <= -self.margin || dist == 0.0 {
            return 0.0; // parted by an earlier contact, or no direction
        }
        let n = d / dist;
        let (wa, wb) = self.weights(a, b, n, pos, vel, sleep);
        let w = wa + wb;
        if w == 0.0 {
            return 0.0;
        }
        let u = vel[b] - vel[a];
        let un = u.dot(n);
        // Touching or overlapping, they must not approach; across a gap,
        // not close it within the next step. Only a slow approach is
        // limited across a gap: a fast one bounces once they touch.
        let allowed = overlap.min(0.0) / self.h;
        let resting = -un < self.def.rest_speed;
        if un < allowed && (overlap >= 0.0 || resting) {
            let e = if resting || overlap < 0.0 {
                0.0
            } else {
                self.def
                    .restitution
                    .unwrap_or(p.restitution[a] * p.restitution[b])
            };
            let ut = u - n * un;
            let slide = ut.length();
            // The normal impulse and the one that would stop the sliding,
            // in one division.
            let target = if overlap < 0.0 {
                allowed - un
            } else {
                -(1.0 + e) * un
            };
            let [jn, stop] = div2([target, slide], [w, w]);
            let mut impulse = n * jn;
            if slide > 0.0 {
                // Against what friction can give.
                let [mu_s, mu_k] = sqrt2([p.mu_s[a] * p.mu_s[b], p.mu_k[a] * p.mu_k[b]]);
                let jt = if stop <= mu_s * jn { stop } else { mu_k * jn };
                impulse -= ut * (jt / slide);
            }
            vel[a] -= impulse * wa;
            vel[b] += impulse * wb;
            if pass == 0 && !resting {
                impacts.push(Impact {
                    spheres: (ParticleId(q.a), ParticleId(q.b)),
                    t: self.t,
                    speed: -un,
                });
            }
        }
        if overlap > 0.0 {
            let [ka, kb] = div2([overlap * wa, overlap * wb], [w, w]);
            pos[a] -= n * ka;
            pos[b] += n * kb;
        }
        for i in [a, b] {
            if self.held(i) && pos[i].y < p.radius[i] && p.inv_mass[i] != 0.0 {
                pos[i].y = p.radius[i];
                vel[i].y = vel[i].y.max(0.0);
            }
        }
        overlap.max(0.0)
    }

    /// The inverse masses `a` and `b` move with in a contact along `n`: a
    /// sphere resting on the floor, pushed down into it, is held by the
    /// floor (immovable for this contact); a sleeper is immovable unless
    /// struck, when it wakes and takes its part from this contact on (so a
    /// blow passes through a sleeping heap as through an awake one, waking
    /// only what it reaches).
    fn weights(
        &self,
        a: usize,
        b: usize,
        n: DVec3,
        pos: &[DVec3],
        vel: &[DVec3],
        sleep: &mut Sleep,
    ) -> (f64, f64) {
        let p = self.p;
        let on_floor = |i: usize| self.held(i) && pos[i].y <= p.radius[i] + FLOOR_TOLERANCE;
        let mut wa = if n.y > 0.0 && on_floor(a) {
            0.0
        } else {
            p.inv_mass[a]
        };
        let mut wb = if n.y < 0.0 && on_floor(b) {
            0.0
        } else {
            p.inv_mass[b]
        };
        if sleep.count > 0 && (sleep.asleep[a] || sleep.asleep[b]) {
            let struck = -(vel[b] - vel[a]).dot(n) >= self.def.rest_speed;
            for (i, wi) in [(a, &mut wa), (b, &mut wb)] {
                if sleep.asleep[i] {
                    if struck {
                        sleep.wake(i);
                    } else {
                        *wi = 0.0;
                    }
                }
            }
        }
        (wa, wb)
    }
}

impl SphereContact {
    /// Handles the contacts of the last check at time `t`.
    pub(super) fn resolve(&mut self, t: f64, pos: &mut [DVec3], vel: &mut [DVec3], p: &Properties) {
        let handling = Handling {
            def: &self.def,
            p,
            floor: &self.floor,
            h: self.h,
            margin: self.def.rest_speed * self.h,
            t,
        };
        // Sleepers stay where they fell asleep, at rest.
        let sleep = &mut self.sleep;
        if sleep.count > 0 {
            for (i, _) in sleep.asleep.iter().enumerate().filter(|(_, &z)| z) {
                pos[i] = sleep.anchor[i];
                vel[i] = DVec3::ZERO;
            }
        }
        for pass in 0..PASSES {
            let mut largest = 0.0f64;
            for q in &self.pairs {
                let corrected = handling.contact(q, pass, pos, vel, sleep, &mut self.impacts);
                largest = largest.max(corrected);
            }
            if largest <= SETTLED {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{div2, sqrt2};

    /// Two divisions or square roots in one instruction give each lane the
    /// bits of the scalar operation (so the handling keeps its results).
    #[test]
    fn paired_divisions_and_roots_are_the_scalar_ones() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Any sign, exponents over a wide range.
            f64::from_bits((s & 0x800f_ffff_ffff_ffff) | ((s >> 52) % 1400 + 330) << 52)
        };
        for _ in 0..100_000 {
            let (a, b, c, d) = (u(), u(), u(), u());
            let [p, q] = div2([a, b], [c, d]);
            assert_eq!(
                (p.to_bits(), q.to_bits()),
                ((a / c).to_bits(), (b / d).to_bits())
            );
            let [r, t] = sqrt2([a.abs(), b.abs()]);
            assert_eq!(
                (r.to_bits(), t.to_bits()),
                (a.abs().sqrt().to_bits(), b.abs().sqrt().to_bits())
            );
        }
        let [z, inf] = div2([0.0, 1.0], [0.0, 0.0]);
        assert!(z.is_nan() && inf == f64::INFINITY);
    }
}
