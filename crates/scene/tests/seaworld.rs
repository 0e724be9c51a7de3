//! `scenes/seaworld.toml` for its full 120 s (issue 4): every jellyfish
//! enters both track and hover, its energy stays within [0, 1], and over its
//! tracking phases its horizontal distance to the food falls on average; the
//! seaweed stays anchored and sways; the number of bubbles stays constant
//! while bubbles are recycled; every rock ends at rest on the floor; nothing
//! goes non-finite.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use std::collections::{HashMap, HashSet};
use std::path::Path;

#[test]
fn seaworld_runs_for_two_minutes_as_the_thesis_describes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seaworld.toml");
    let mut s = animats_scene::load(&path).unwrap();
    let dt = s.dt;
    let count = s.world.len();
    let food = s.particle("food").unwrap();
    let named = |prefix: &str| -> Vec<animats_engine::ParticleId> {
        s.names
            .iter()
            .enumerate()
            .filter(|(_, n)| n.starts_with(prefix))
            .map(|(i, _)| animats_engine::ParticleId::from_index(i))
            .collect()
    };
    let bubbles = named("bubbles");
    let rocks = named("rock");
    let bases: Vec<_> = (0..5)
        .map(|k| s.particle(&format!("seaweed{k}.0")).unwrap())
        .collect();
    let tips: Vec<_> = (0..5)
        .map(|k| s.particle(&format!("seaweed{k}.12")).unwrap())
        .collect();
    let base_at: Vec<_> = bases.iter().map(|b| s.world.position(*b)).collect();
    assert_eq!((bubbles.len(), rocks.len()), (60, 10));

    let mut states: HashMap<String, HashSet<&'static str>> = HashMap::new();
    let mut previous: HashMap<String, &'static str> = HashMap::new();
    // Per jellyfish: distance when its current tracking phase began, and the
    // changes over its finished tracking phases.
    let mut started: HashMap<String, f64> = HashMap::new();
    let mut changes: HashMap<String, Vec<f64>> = HashMap::new();
    let mut tip_x: Vec<(f64, f64)> = vec![(f64::INFINITY, f64::NEG_INFINITY); 5];
    let mut recycled = 0;
    let mut heights: Vec<f64> = bubbles.iter().map(|b| s.world.position(*b).y).collect();

    for _ in 0..(s.duration / dt).round() as usize {
        s.step(dt).expect("SeaWorld stays finite");
        for a in &s.actors {
            let Some(st) = a.status() else { continue };
            let e = st.energy.unwrap();
            assert!((0.0..=1.0).contains(&e), "{}: energy {e}", st.name);
            states.entry(st.name.clone()).or_default().insert(st.state);
            let dome = s
                .world
                .position(s.particle(&format!("{}.dome0", st.name)).unwrap());
            let f = s.world.position(food);
            let distance = (dome.x - f.x).hypot(dome.z - f.z);
            let was = previous.insert(st.name.clone(), st.state).unwrap_or("idle");
            if st.state == "track" && was != "track" {
                started.insert(st.name.clone(), distance);
            } else if st.state != "track" && was == "track" {
                if let Some(d0) = started.remove(&st.name) {
                    changes
                        .entry(st.name.clone())
                        .or_default()
                        .push(distance - d0);
                }
            }
        }
        for (k, t) in tips.iter().enumerate() {
            let x = s.world.position(*t).x;
            tip_x[k] = (tip_x[k].0.min(x), tip_x[k].1.max(x));
        }
        for (i, b) in bubbles.iter().enumerate() {
            let y = s.world.position(*b).y;
            assert!(y <= 1.5 + 0.05, "a bubble above the water: {y} m");
            if y < heights[i] - 0.2 {
                recycled += 1; // jumped back down to the column's base
            }
            heights[i] = y;
        }
        assert_eq!(s.world.len(), count, "the number of particles changed");
    }

    for name in ["jelly0", "jelly1", "jelly2"] {
        let seen = &states[name];
        assert!(
            seen.contains("track") && seen.contains("hover"),
            "{name} went through {seen:?}"
        );
        let c = &changes[name];
        let mean = c.iter().sum::<f64>() / c.len() as f64;
        assert!(
            c.len() >= 10 && mean < 0.0,
            "{name}: {} tracking phases, mean change {mean:+} m",
            c.len()
        );
    }
    for (k, b) in bases.iter().enumerate() {
        assert_eq!(s.world.position(*b), base_at[k], "seaweed{k} came loose");
        let sway = tip_x[k].1 - tip_x[k].0;
        // The tips follow the water's orbits, about 2 cm across at their depth.
        assert!(sway > 0.01, "seaweed{k}'s tip moved only {sway} m");
    }
    assert!(
        recycled > 100,
        "only {recycled} bubbles recycled in 2 minutes"
    );
    for r in &rocks {
        let radius = s.world.particles().radius[r.index()];
        let gap = s.world.position(*r).y - radius;
        let speed = s.world.velocity(*r).length();
        assert!(
            gap.abs() < 1e-6 && speed < 1e-6,
            "a rock is not at rest on the floor: gap {gap}, speed {speed}"
        );
    }
}

#[test]
fn new_entries_are_validated() {
    let base = "[world]\ndt = 0.01\n[fluid]\n[floor]\n[[food]]\nposition = [0.0, 1.0, 0.0]\n";
    for (entry, expect) in [
        (
            "[[jellyfish]]\nposition = [0.0, 0.5, 0.0]\nfood = \"lunch\"\n",
            "jellyfish[0].food: no particle `lunch`",
        ),
        (
            "[[jellyfish]]\nposition = [0.0, 0.5, 0.0]\ndome_mass = -1.0\n",
            "jellyfish[0].dome_mass",
        ),
        (
            "[[jellyfish]]\nposition = [0.0, 0.5, 0.0]\nwings = 2\n",
            "unknown field `wings`",
        ),
        (
            "[[seaweed]]\nposition = [0.0, 0.0, 0.0]\nsegments = 0\n",
            "seaweed[0].segments",
        ),
        (
            "[[seaweed]]\nposition = [0.0, 0.0, 0.0]\ndensity = 0.0\n",
            "seaweed[0].density",
        ),
        (
            "[[bubble_column]]\nposition = [0.0, 0.0, 0.0]\nbubbles = 0\n",
            "bubble_column[0].bubbles",
        ),
        (
            "[[bubble_column]]\nposition = [0.0, 0.0, 0.0]\ninterval = [0.4, 0.1]\n",
            "bubble_column[0].interval",
        ),
        (
            "[[bubble_column]]\nposition = [0.0, 0.0, 0.0]\ndensity = nan\n",
            "bubble_column[0].density",
        ),
        ("[[rocks]]\ndensity = -2000.0\n", "rocks[0].density"),
        ("[[rocks]]\nmass = [0.3, 0.05]\n", "rocks[0].mass"),
        (
            "[[food]]\nposition = [1.0, 1.0, 0.0]\n",
            "food[1].name: duplicate particle name `food`",
        ),
    ] {
        let text = format!("{base}{entry}");
        let e = animats_scene::parse(&text, "sea.toml")
            .err()
            .unwrap_or_else(|| panic!("accepted {entry}"));
        assert!(e.to_string().contains(expect), "{entry}: {e}");
    }
    // Without any food, a jellyfish is refused too.
    let e = animats_scene::parse("[[jellyfish]]\nposition = [0.0, 0.5, 0.0]\n", "sea.toml")
        .err()
        .unwrap();
    assert!(e.to_string().contains("add a [[food]] entry"), "{e}");
}

#[test]
fn the_same_seed_places_the_same_rocks_and_another_seed_does_not() {
    let scene = |seed: u64| {
        let text = format!("[world]\nseed = {seed}\n[[rocks]]\ncount = 4\n");
        let s = animats_scene::parse(&text, "r.toml").unwrap();
        s.world.state().pos.clone()
    };
    assert_eq!(scene(7), scene(7));
    assert_ne!(scene(7), scene(8));
}
