//! Damped Hooke spring (thesis §3.1.2.2, Eq. 11): `F = k (l - r) + k_d dl/dt`
//! along the spring, equal and opposite on its ends. The rest length `r` may be
//! changed at run time: it is the muscle that actuators drive.

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::particle::{non_negative, ParticleId};
use glam::DVec3;

/// Handle to one spring of a world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SpringId(pub(crate) u32);

impl SpringId {
    /// Index of the spring in the world's spring collection.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Description of a spring to add to a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringDef {
    /// One end.
    pub a: ParticleId,
    /// The other end.
    pub b: ParticleId,
    /// Stiffness `k`, N/m, >= 0.
    pub stiffness: f64,
    /// Damping `k_d` along the spring, N s/m, >= 0.
    pub damping: f64,
    /// Rest length, m, > 0; `None` means the distance between the ends when
    /// the spring is added.
    pub rest_length: Option<f64>,
}

impl SpringDef {
    /// A spring between `a` and `b` at rest at its initial length.
    pub fn new(a: ParticleId, b: ParticleId, stiffness: f64, damping: f64) -> Self {
        SpringDef {
            a,
            b,
            stiffness,
            damping,
            rest_length: None,
        }
    }
    /// Sets the rest length.
    pub fn with_rest_length(mut self, rest_length: f64) -> Self {
        self.rest_length = Some(rest_length);
        self
    }
}

/// One spring as the world stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    a: u32,
    b: u32,
    /// N/m.
    pub stiffness: f64,
    /// N s/m.
    pub damping: f64,
    /// m.
    pub rest_length: f64,
}

impl Spring {
    /// The two ends.
    pub fn ends(&self) -> (ParticleId, ParticleId) {
        (ParticleId(self.a), ParticleId(self.b))
    }

    /// Signed tension (positive when stretched) at the given state, N.
    pub fn tension(&self, pos: &[DVec3], vel: &[DVec3]) -> f64 {
        let (a, b) = (self.a as usize, self.b as usize);
        let d = pos[b] - pos[a];
        let len = d.length();
        let n = if len > 0.0 { d / len } else { DVec3::ZERO };
        self.stiffness * (len - self.rest_length) + self.damping * (vel[b] - vel[a]).dot(n)
    }
}

/// Every spring of a world, in one flat array so the force loop is tight.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Springs {
    springs: Vec<Spring>,
}

impl Springs {
    /// Number of springs.
    pub fn len(&self) -> usize {
        self.springs.len()
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.springs.is_empty()
    }
    /// The spring `id`.
    pub fn get(&self, id: SpringId) -> &Spring {
        &self.springs[id.index()]
    }
    /// The spring `id`, to change its stiffness, damping or rest length.
    pub fn get_mut(&mut self, id: SpringId) -> &mut Spring {
        &mut self.springs[id.index()]
    }
    /// Sets the rest length of spring `id` (the muscle's activation).
    pub fn set_rest_length(&mut self, id: SpringId, rest_length: f64) {
        self.springs[id.index()].rest_length = rest_length;
    }
    /// All springs, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = &Spring> {
        self.springs.iter()
    }

    /// Adds a spring; `pos` are the current positions (for the default rest length).
    pub(crate) fn add(&mut self, def: &SpringDef, pos: &[DVec3]) -> Result<SpringId, ModelError> {
        if def.a == def.b {
            return Err(ModelError::new(
                "b",
                "a spring needs two different particles",
            ));
        }
        non_negative("stiffness", def.stiffness)?;
        non_negative("damping", def.damping)?;
        let initial = (pos[def.b.index()] - pos[def.a.index()]).length();
        if initial == 0.0 {
            return Err(ModelError::new(
                "b",
                "the two ends start at the same point: a spring of zero length has no direction",
            ));
        }
        let rest_length = def.rest_length.unwrap_or(initial);
        non_negative("rest_length", rest_length)?;
        if rest_length == 0.0 {
            return Err(ModelError::new("rest_length", "must be > 0, got 0"));
        }
        self.springs.push(Spring {
            a: def.a.0,
            b: def.b.0,
            stiffness: def.stiffness,
            damping: def.damping,
            rest_length,
        });
        Ok(SpringId(self.springs.len() as u32 - 1))
    }
}

impl Force for Springs {
    #[inline]
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let (pos, vel) = (ctx.pos, ctx.vel);
        for s in &self.springs {
            let (a, b) = (s.a as usize, s.b as usize);
            let d = pos[b] - pos[a];
            let len = d.length();
            // A spring squashed to a point has no direction: it pushes nowhere.
            let n = d * if len > 0.0 { 1.0 / len } else { 0.0 };
            let f =
                n * (s.stiffness * (len - s.rest_length) + s.damping * (vel[b] - vel[a]).dot(n));
            forces[a] += f;
            forces[b] -= f;
        }
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        self.springs
            .iter()
            .map(|s| {
                let x = (ctx.pos[s.b as usize] - ctx.pos[s.a as usize]).length() - s.rest_length;
                0.5 * s.stiffness * x * x
            })
            .sum()
    }

    fn is_conservative(&self) -> bool {
        self.springs.iter().all(|s| s.damping == 0.0)
    }

    fn is_passive(&self) -> bool {
        true // damping only removes energy
    }

    fn name(&self) -> &str {
        "springs"
    }
}
