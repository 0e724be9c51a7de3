//! Property tests: random valid scenes never panic (they build, and running
//! them either works or reports a blow-up cleanly), and random corruptions of
//! a valid scene are refused with an error, never a panic.

use proptest::prelude::*;
use std::fmt::Write;

/// A random but valid scene: particles in a box, springs and joints between
/// them, optional floor and fluid, any integrator.
fn valid_scene() -> impl Strategy<Value = String> {
    let particle = (
        0.01f64..10.0,
        prop::array::uniform3(-1.0f64..1.0),
        0.005f64..0.2,
        0.0f64..=1.0,
        any::<bool>(),
    );
    (
        prop::collection::vec(particle, 3..8),
        prop::collection::vec((0usize..8, 0usize..8, 0.0f64..500.0, 0.0f64..2.0), 0..10),
        prop::collection::vec((0usize..8, 0usize..8, 0usize..8, 0.0f64..5.0), 0..4),
        prop::collection::vec((0usize..8, 0usize..8, -2.0f64..2.0), 0..3),
        (any::<bool>(), any::<bool>(), 0usize..5, 1e-4f64..5e-3),
    )
        .prop_map(|(particles, springs, angles, torques, (floor, fluid, integrator, dt))| {
            let n = particles.len();
            let mut s = String::new();
            let kinds = ["euler", "midpoint", "rk4", "symplectic", "implicit"];
            writeln!(s, "[world]\ndt = {dt}\nintegrator = \"{}\"\nduration = 0.05\n", kinds[integrator]).unwrap();
            if floor {
                s.push_str("[floor]\n\n");
            }
            if fluid {
                s.push_str("[fluid]\ncurrent = { kind = \"reef\" }\n\n");
            }
            for (i, (m, p, r, e, fixed)) in particles.iter().enumerate() {
                // Spread the particles out so no two coincide.
                let y = p[1] + 1.5 + i as f64;
                writeln!(
                    s,
                    "[[particle]]\nname = \"p{i}\"\nmass = {m}\nposition = [{}, {y}, {}]\nradius = {r}\nrestitution = {e}\nfixed = {fixed}\n",
                    p[0], p[2]
                )
                .unwrap();
            }
            for (a, b, k, c) in springs {
                let (a, b) = (a % n, b % n);
                if a != b {
                    writeln!(s, "[[spring]]\na = \"p{a}\"\nb = \"p{b}\"\nstiffness = {k}\ndamping = {c}\n").unwrap();
                }
            }
            for (a, j, b, k) in angles {
                let (a, j, b) = (a % n, j % n, b % n);
                if a != j && b != j && a != b {
                    writeln!(s, "[[angle_joint]]\na = \"p{a}\"\njoint = \"p{j}\"\nb = \"p{b}\"\nstiffness = {k}\n").unwrap();
                }
            }
            for (e, j, t) in torques {
                let (e, j) = (e % n, j % n);
                if e != j {
                    writeln!(s, "[[torque_joint]]\nend = \"p{e}\"\njoint = \"p{j}\"\ntorque = {t}\n").unwrap();
                }
            }
            s
        })
}

/// Ways to break a valid scene.
fn corruption() -> impl Strategy<Value = (usize, usize)> {
    (
        0usize..12,
        any::<prop::sample::Index>().prop_map(|i| i.index(1000)),
    )
}

fn corrupt(scene: &str, (kind, at): (usize, usize)) -> String {
    let lines: Vec<&str> = scene.lines().collect();
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    // Pick the at-th line that assigns the key the corruption targets.
    let mut replace = |key: &str, with: &str| {
        let hits: Vec<usize> = (0..out.len())
            .filter(|&i| out[i].starts_with(&format!("{key} =")))
            .collect();
        if hits.is_empty() {
            return false;
        }
        let i = hits[at % hits.len()];
        out[i] = format!("{key} = {with}");
        true
    };
    let done = match kind {
        0 => replace("mass", "-1.0"),
        1 => replace("mass", "nan"),
        2 => replace("radius", "-0.1"),
        3 => replace("restitution", "1.5"),
        4 => replace("dt", "0.0"),
        5 => replace("position", "[0.0, inf, 0.0]"),
        6 => replace("name", "\"p0\""), // a duplicate (or p0 itself: see below)
        7 => replace("a", "\"nobody\""),
        8 => replace("stiffness", "-3.0"),
        9 => replace("integrator", "\"leapfrog\""),
        10 => replace("duration", "\"long\""),
        _ => replace("mass", "1.0\nwingspan = 3.0"),
    };
    if !done || (kind == 6 && out.iter().filter(|l| *l == "name = \"p0\"").count() < 2) {
        // Nothing to corrupt of that kind: add an unknown table instead.
        out.push("[mystery]\nx = 1".into());
    }
    out.join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn random_valid_scenes_build_and_never_panic(text in valid_scene()) {
        let mut scene = animats_scene::parse(&text, "random.toml").map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        for _ in 0..50 {
            // A stiff random scene may blow up: that must be an error, not a panic.
            if scene.step(scene.dt).is_err() {
                break;
            }
        }
    }

    #[test]
    fn random_corruptions_are_refused_cleanly(text in valid_scene(), how in corruption()) {
        let bad = corrupt(&text, how);
        let result = animats_scene::parse(&bad, "bad.toml");
        prop_assert!(result.is_err(), "accepted a corrupted scene:\n{bad}");
        let message = result.err().unwrap().to_string();
        prop_assert!(message.starts_with("bad.toml"), "{message}");
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        let _ = animats_scene::parse(&text, "noise.toml");
    }
}

/// Counts that would make a world too big to build are refused before
/// anything is allocated, naming the entry and the field: no hang, no
/// "capacity overflow" panic, no exhausted memory.
#[test]
fn oversized_counts_are_refused_naming_the_entry_and_field() {
    let huge = [
        "1000001".to_string(),
        "100000000000000".to_string(),
        (u64::MAX / 2).to_string(),
        i64::MAX.to_string(),
    ];
    for n in &huge {
        for (entry, table) in [
            ("rocks[0].count", format!("[[rocks]]\ncount = {n}\n")),
            (
                "seaweed[0].segments",
                format!("[[seaweed]]\nposition = [0.0, 0.0, 0.0]\nsegments = {n}\n"),
            ),
            (
                "bubble_column[0].bubbles",
                format!("[[bubble_column]]\nposition = [0.0, 0.0, 0.0]\nbubbles = {n}\n"),
            ),
        ] {
            let message = match animats_scene::parse(&table, "big.toml") {
                Ok(_) => panic!("accepted {table}"),
                Err(e) => e.to_string(),
            };
            assert!(message.starts_with("big.toml:"), "{message}");
            assert!(message.contains(&format!(": {entry}: ")), "{message}");
            assert!(message.contains("limit"), "{message}");
        }
    }
    // Counts beyond any integer type are a type error, also named.
    let message = animats_scene::parse("[[rocks]]\ncount = 100000000000000000000\n", "big.toml")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.starts_with("big.toml:2: rocks[0].count: "),
        "{message}"
    );
    // Many entries that are each small add up to the same limit.
    let mut text = String::new();
    for k in 0..11 {
        text.push_str(&format!("[[rocks]]\nname = \"r{k}_\"\ncount = 100000\n"));
    }
    let message = animats_scene::parse(&text, "many.toml")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(message.starts_with("many.toml:"), "{message}");
    assert!(message.contains("rocks[10].count"), "{message}");
}

/// Header lines that TOML refuses still give a readable entry, never an
/// empty or garbled one.
#[test]
fn malformed_headers_never_garble_the_entry_name() {
    for (text, expect) in [
        ("[[spring]\n", "bad.toml:1: spring[0]: "),
        ("[[ spring ]]\na = \"x\"\n", "bad.toml:1: spring[0]: "),
        ("[[]]\nx = 1\n", "bad.toml:1: "),
        ("[ ]\nx = 1\n", "bad.toml:1: "),
        ("[world]\n[world.x]\ny = 1\n", "bad.toml:2: world.x: "),
    ] {
        let message = animats_scene::parse(text, "bad.toml")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(message.starts_with(expect), "{text:?} gave {message}");
        assert!(!message.contains("]["), "{message}");
        assert!(!message.contains(": :"), "{message}");
        assert!(
            !message.contains(" .") && !message.contains(".:"),
            "{message}"
        );
    }
}
