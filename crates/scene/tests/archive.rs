//! `[archive]` measures against what physics says they must be: a body in
//! free fall (RK4 is exact for a constant acceleration, so the mean of the
//! heights after each step is the discrete sum in closed form), drift at
//! constant velocity, a ball resting on the floor and one held above it;
//! the body measures of a built scene; and every malformed table refused,
//! naming its field.

use animats_scene::evaluate::evaluate;

const G: f64 = 9.81;

/// One ball, no floor unless asked, and an [archive] of `measures`.
fn scene(gravity: f64, y0: f64, vx: f64, floor: bool, measures: &str) -> String {
    let k = measures.matches("kind").count();
    format!(
        r#"
[world]
gravity = [0.0, {g}, 0.0]
dt = 0.01
integrator = "rk4"

{floor}

[[particle]]
name = "ball"
mass = 2.0
position = [0.0, {y0}, 0.0]
velocity = [{vx}, 0.0, 0.0]
radius = 0.1

[evolve]
duration = 1.0
particles = ["ball"]

[archive]
measures = [{measures}]
bins = [{bins}]
ranges = [{ranges}]
"#,
        g = -gravity,
        floor = if floor { "[floor]" } else { "" },
        bins = vec!["10"; k].join(", "),
        ranges = vec!["[0.0, 1.0]"; k].join(", "),
    )
}

fn measures(text: &str) -> Vec<f64> {
    let s = animats_scene::parse(text, "test.toml").unwrap();
    evaluate(s).unwrap().measures
}

#[test]
fn free_fall_mean_height_is_the_discrete_sum() {
    let y0 = 100.0;
    let m = measures(&scene(G, y0, 0.0, false, r#"{ kind = "mean_height" }"#));
    // Heights after steps k = 1..N of dt: y0 − g (k dt)² / 2; their mean is
    // y0 − g dt² (N + 1)(2N + 1) / 12.
    let (n, dt) = (100.0, 0.01);
    let expected = y0 - G * dt * dt * (n + 1.0) * (2.0 * n + 1.0) / 12.0;
    assert!((m[0] - expected).abs() < 1e-9, "{} vs {expected}", m[0]);
}

#[test]
fn drift_gives_displacement_and_speed() {
    let m = measures(&scene(
        0.0,
        5.0,
        0.7,
        false,
        r#"{ kind = "displacement" }, { kind = "speed" }, { kind = "displacement", axis = [0.0, 0.0, 1.0] }"#,
    ));
    assert!((m[0] - 0.7).abs() < 1e-12, "{m:?}");
    assert!((m[1] - 0.7).abs() < 1e-12, "{m:?}");
    assert_eq!(m[2], 0.0);
}

#[test]
fn contact_fraction_is_one_at_rest_and_zero_above() {
    let on = measures(&scene(
        G,
        0.1,
        0.0,
        true,
        r#"{ kind = "contact_fraction", particle = "ball" }, { kind = "feet" }"#,
    ));
    assert_eq!(on, vec![1.0, 1.0]);
    let above = measures(&scene(
        0.0,
        0.5,
        0.0,
        true,
        r#"{ kind = "contact_fraction", particle = "ball" }, { kind = "feet" }"#,
    ));
    assert_eq!(above, vec![0.0, 0.0]);
}

/// A ball dropped from 1.1 m reaches the floor after sqrt(2 · 1 / g) =
/// 0.4515 s; the floor holds it (restitution 0) for the rest of the 1 s:
/// it is on the floor in 1 − 0.4515 of the steps, to a step or two.
#[test]
fn contact_fraction_of_a_drop() {
    let text = scene(
        G,
        1.1,
        0.0,
        true,
        r#"{ kind = "contact_fraction", particle = "ball" }"#,
    )
    .replace("radius = 0.1", "radius = 0.1\nrestitution = 0.0");
    let m = measures(&text);
    let expected = 1.0 - (2.0f64 / G).sqrt();
    assert!((m[0] - expected).abs() <= 0.021, "{} vs {expected}", m[0]);
}

#[test]
fn body_measures_count_what_was_built() {
    let text = r#"
[world]
gravity = [0.0, 0.0, 0.0]

[[particle]]
name = "a"
mass = 1.5
position = [0.0, 1.0, 0.0]
radius = 0.01

[[particle]]
name = "b"
mass = 0.5
position = [0.3, 1.4, 0.0]
radius = 0.01

[[particle]]
name = "nail"
mass = 9.0
position = [5.0, 1.0, 0.0]
radius = 0.01
fixed = true

[[spring]]
name = "s"
a = "a"
b = "b"
stiffness = 100.0

[[actuator]]
name = "m"
spring = "s"
min = 0.4
max = 0.6

[evolve]
duration = 0.1

[archive]
measures = [{ kind = "particles" }, { kind = "muscles" }, { kind = "mass" }, { kind = "size" }]
bins = [4, 4, 4, 4]
ranges = [[0, 4], [0, 4], [0, 4], [0, 1]]
"#;
    let m = measures(text);
    assert_eq!(m[..3], [2.0, 1.0, 2.0]);
    assert!((m[3] - 0.4).abs() < 1e-12, "{m:?}");
}

/// Malformed tables: each refused with the field named.
#[test]
fn bad_archives_are_refused_naming_the_field() {
    let base = scene(G, 1.0, 0.0, false, r#"{ kind = "speed" }"#);
    let cases = [
        (
            base.replace(r#"kind = "speed""#, r#"kind = "joy""#),
            "measures[0]",
        ),
        (base.replace("bins = [10]", "bins = [10, 10]"), "bins"),
        (
            base.replace("ranges = [[0.0, 1.0]]", "ranges = [[0.0, 1.0], [0.0, 1.0]]"),
            "ranges",
        ),
        (
            base.replace("ranges = [[0.0, 1.0]]", "ranges = [[1.0, 1.0]]"),
            "ranges[0]",
        ),
        (
            base.replace("ranges = [[0.0, 1.0]]", "ranges = [[2.0, 1.0]]"),
            "ranges[0]",
        ),
        (base.replace("bins = [10]", "bins = [100000000]"), "bins"),
        (base.replace("bins = [10]", "bins = [0]"), "bins[0]"),
        (
            base.replace(
                r#"kind = "speed""#,
                r#"kind = "contact_fraction", particle = "nobody""#,
            ),
            "measures[0].particle",
        ),
        (
            base.replace("bins = [10]", "bins = [10]\nlearning_rate = 0.5"),
            "threshold_min",
        ),
        (
            base.replace("bins = [10]", "bins = [10]\nlearning_rate = 2.0"),
            "learning_rate",
        ),
        (
            base.replace("measures = [{ kind = \"speed\" }]", "measures = []"),
            "measures",
        ),
    ];
    for (text, field) in cases {
        let e = match animats_scene::parse(&text, "bad.toml") {
            Ok(_) => panic!("accepted a scene whose {field} is wrong"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("bad.toml") && e.contains(field),
            "the error should name bad.toml and {field}: {e}"
        );
    }
    // The grid of over 10^7 cells is refused before anything is allocated.
    let huge = base
        .replace("bins = [10]", "bins = [4000]\n")
        .replace(
            r#"measures = [{ kind = "speed" }]"#,
            r#"measures = [{ kind = "speed" }, { kind = "mass" }, { kind = "size" }]"#,
        )
        .replace("bins = [4000]", "bins = [4000, 4000, 4000]")
        .replace("ranges = [[0.0, 1.0]]", "ranges = [[0, 1], [0, 1], [0, 1]]");
    let e = animats_scene::parse(&huge, "bad.toml")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.contains("64000000000 cells") && e.contains("10000000"),
        "{e}"
    );
}

/// A body map's bodies pass the same checks as without the table (the
/// settle check's scene has no [evolve], and once refused every body for
/// the [archive] that needs one), and each developed body returns the
/// body measures of what was built.
#[test]
fn bodies_of_a_map_are_checked_and_measured_as_bodies() {
    use animats_creatures::random::Random;
    use animats_scene::morphology::MorphologyProblem;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/bodies_walk.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let bare = &text[..text.find("[archive]").unwrap()];
    let map = MorphologyProblem::parse(&text, "bodies_walk.toml").unwrap();
    let plain = MorphologyProblem::parse(bare, "bodies_walk.toml").unwrap();
    assert!(map.grid().is_some() && plain.grid().is_none());
    let mut passed = 0;
    for k in 0..12 {
        let g = map.random(&mut Random::for_entry(7, k));
        let (a, b) = (map.check(&g), plain.check(&g));
        assert_eq!(a, b, "body {k}");
        if a.is_ok() {
            passed += 1;
            let scene = animats_scene::parse(&map.develop(&g, "").unwrap(), "b.toml").unwrap();
            let stats = map.stats(&g).unwrap();
            let size = scene.archive.as_ref().map(|a| a.measures.len());
            assert_eq!(size, Some(2));
            assert_eq!(stats.particles, scene.world.len());
        }
    }
    assert!(passed >= 3, "{passed} of 12 random bodies passed");
}
