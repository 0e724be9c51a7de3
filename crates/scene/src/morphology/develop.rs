//! Development: a [`Body`] written into the rest of its scene as ordinary
//! entries. The body is placed with the bottom centre of its bounding box
//! at `origin` (its lowest sphere's lowest point at `origin[1]`); particle
//! `i` is `body.p{i}`, spring `j` is `body.s{j}`, the muscle on spring `j`
//! is actuator `body.m{j}` (its rest length from `1 − muscle_strain` to
//! `1 + muscle_strain` times its built length, level 0.5 at the built
//! length, at most `muscle_rate` a second), driven by controller `body`, an
//! oscillator (or, for a `neural` body, a one-layer network fed by touch
//! sensor `body.t{i}` on every particle and a clock); `[contacts]` (`model = "penalty"`: a force, which stores no
//! energy it does not give back) makes the body's spheres collide with
//! each other (pairs a spring joins never do) unless `self_contact = false`.
//! The scene's `[evolve]` gets `controller = "body"`, and unless it says
//! otherwise `robust = true` and `particles` = the body's.
//!
//! The text is the one definition of the creature: an evaluation during
//! evolution parses it exactly as `animats evaluate` parses `best.toml`,
//! and every number is written in its shortest round-trip form, so the two
//! agree to the bit.

use super::genome::Body;
use super::Morphology;
use animats_engine::DVec3;
use toml_edit::{value, Array, ArrayOfTables, DocumentMut, Item, Table};

/// The controller a developed body is driven by, and its particles' prefix.
pub const NAME: &str = "body";

/// Where each particle of `body` is built, placed as the module says.
pub fn placed(body: &Body, m: &Morphology) -> Vec<DVec3> {
    if body.nodes.is_empty() {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mut bottom = f64::INFINITY;
    for n in &body.nodes {
        lo = lo.min(n.position);
        hi = hi.max(n.position);
        bottom = bottom.min(n.position.y - n.radius);
    }
    let shift = DVec3::new(
        m.origin.x - 0.5 * (lo.x + hi.x),
        m.origin.y - bottom,
        m.origin.z - 0.5 * (lo.z + hi.z),
    );
    body.nodes.iter().map(|n| n.position + shift).collect()
}

/// What to write besides the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Brain {
    /// The oscillator and the scene's `[evolve]` table: the creature.
    Driven,
    /// No controller, no `[evolve]` and no `[archive]`: the muscles hold
    /// their built lengths (the settle check's scene).
    Held,
}

/// `base` (the scene without its `[morphology]`) with `body` written in,
/// preceded by `comment` as `#` lines.
pub fn develop(
    base: &DocumentMut,
    body: &Body,
    m: &Morphology,
    brain: Brain,
    comment: &str,
) -> Result<String, String> {
    let mut doc = base.clone();
    let at = placed(body, m);
    let names: Vec<String> = (0..body.nodes.len())
        .map(|i| format!("{NAME}.p{i}"))
        .collect();
    let mut particles = Vec::with_capacity(body.nodes.len());
    for ((n, p), name) in body.nodes.iter().zip(&at).zip(&names) {
        let mut t = Table::new();
        t["name"] = value(name.as_str());
        t["mass"] = value(n.mass);
        t["position"] = value(floats(&[p.x, p.y, p.z]));
        t["radius"] = value(n.radius);
        t["mu_s"] = value(m.mu_s);
        t["mu_k"] = value(m.mu_k);
        t["restitution"] = value(m.restitution);
        particles.push(t);
    }
    append(&mut doc, "particle", particles)?;
    let mut springs = Vec::with_capacity(body.edges.len());
    let mut actuators = Vec::new();
    let mut oscillator = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut duty = Vec::new();
    for (j, e) in body.edges.iter().enumerate() {
        let mut t = Table::new();
        t["name"] = value(format!("{NAME}.s{j}"));
        t["a"] = value(format!("{NAME}.p{}", e.a));
        t["b"] = value(format!("{NAME}.p{}", e.b));
        t["stiffness"] = value(e.stiffness);
        t["damping"] = value(m.damping);
        springs.push(t);
        if let Some(mu) = e.muscle {
            let length = (at[e.a] - at[e.b]).length();
            let mut a = Table::new();
            a["name"] = value(format!("{NAME}.m{j}"));
            a["spring"] = value(format!("{NAME}.s{j}"));
            a["min"] = value(length * (1.0 - m.muscle_strain));
            a["max"] = value(length * (1.0 + m.muscle_strain));
            a["rate"] = value(m.muscle_rate);
            actuators.push(a);
            oscillator.0.push(format!("{NAME}.m{j}"));
            oscillator.1.push(mu.amplitude);
            oscillator.2.push(mu.phase);
            oscillator.3.push(mu.offset);
            duty.push(mu.duty);
        }
    }
    append(&mut doc, "spring", springs)?;
    append(&mut doc, "actuator", actuators)?;
    match brain {
        Brain::Driven => {
            let c = if body.neural {
                let sensors = touch_sensors(&names);
                let c = neural(body, &oscillator.0);
                append(&mut doc, "sensor", sensors)?;
                c
            } else {
                let mut c = Table::new();
                c["name"] = value(NAME);
                c["kind"] = value("oscillator");
                c["outputs"] = value(oscillator.0.iter().map(String::as_str).collect::<Array>());
                c["frequency"] = value(body.frequency);
                c["amplitude"] = value(floats(&oscillator.1));
                c["phase"] = value(floats(&oscillator.2));
                c["offset"] = value(floats(&oscillator.3));
                if body.skewed {
                    c["duty"] = value(floats(&duty));
                }
                c
            };
            append(&mut doc, "controller", vec![c])?;
            if let Some(evolve) = doc.get_mut("evolve").and_then(Item::as_table_mut) {
                evolve["controller"] = value(NAME);
                if !evolve.contains_key("robust") {
                    evolve["robust"] = value(true);
                }
                // The body's centre of mass, not the scene's.
                if !evolve.contains_key("particles") {
                    evolve["particles"] = value(all(&names));
                }
            }
        }
        Brain::Held => {
            doc.remove("evolve");
            doc.remove("archive");
        }
    }
    if m.self_contact && !doc.contains_key("contacts") {
        let mut t = Table::new();
        t["particles"] = value(all(&names));
        t["model"] = value("penalty");
        doc["contacts"] = Item::Table(t);
    }
    Ok(crate::evaluate::commented(comment, &doc))
}

/// `names` as a TOML array.
fn all(names: &[String]) -> Array {
    names.iter().map(String::as_str).collect()
}

/// A touch sensor `body.t{i}` on every particle (any of them may reach the
/// floor).
fn touch_sensors(particles: &[String]) -> Vec<Table> {
    particles
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut t = Table::new();
            t["name"] = value(format!("{NAME}.t{i}"));
            t["kind"] = value("touch");
            t["particle"] = value(p.as_str());
            t
        })
        .collect()
}

/// A `neural` body's controller: one layer from the touch sensors and a
/// clock at the body's frequency to every muscle. Muscle `j` on the spring
/// from `a` to `b` computes `σ(4 (offset − ½) + 4 amplitude sin(2π f t +
/// phase) + 2 touch[0] t_a + 2 touch[1] t_b)`: the network sees a touch
/// level `t` as `2t − 1`, so its weight on `a`'s sensor is `touch[0]`, and
/// its bias carries `touch[0] + touch[1]`; `A sin(ωt + φ)` is `A cos φ` on
/// the clock's sine and `A sin φ` on its cosine.
fn neural(body: &Body, outputs: &[String]) -> Table {
    let n = body.nodes.len();
    let muscles: Vec<_> = body
        .edges
        .iter()
        .filter_map(|e| e.muscle.map(|mu| (e.a, e.b, mu)))
        .collect();
    let mut weights = Vec::with_capacity(muscles.len() * (n + 3));
    for &(a, b, mu) in &muscles {
        let mut row = vec![0.0; n + 2];
        row[a] = mu.touch[0];
        row[b] = mu.touch[1];
        row[n] = 4.0 * mu.amplitude * animats_engine::math::cos(mu.phase);
        row[n + 1] = 4.0 * mu.amplitude * animats_engine::math::sin(mu.phase);
        weights.extend(row);
    }
    for &(_, _, mu) in &muscles {
        weights.push(4.0 * (mu.offset - 0.5) + mu.touch[0] + mu.touch[1]);
    }
    let mut c = Table::new();
    c["name"] = value(NAME);
    c["kind"] = value("neural");
    c["inputs"] = value((0..n).map(|i| format!("{NAME}.t{i}")).collect::<Array>());
    c["outputs"] = value(outputs.iter().map(String::as_str).collect::<Array>());
    c["clock"] = value(body.frequency);
    c["weights"] = value(floats(&weights));
    c
}

fn floats(xs: &[f64]) -> Array {
    xs.iter().copied().collect()
}

/// Appends `tables` to the `[[kind]]` array (made if missing); refused if
/// the scene wrote `kind` another way (an inline array).
fn append(doc: &mut DocumentMut, kind: &str, tables: Vec<Table>) -> Result<(), String> {
    if tables.is_empty() {
        return Ok(());
    }
    if !doc.contains_key(kind) {
        doc[kind] = Item::ArrayOfTables(ArrayOfTables::new());
    }
    let array = doc[kind].as_array_of_tables_mut().ok_or_else(|| {
        format!("`{kind}` must be written as [[{kind}]] tables in a scene with [morphology]")
    })?;
    for t in tables {
        array.push(t);
    }
    Ok(())
}
