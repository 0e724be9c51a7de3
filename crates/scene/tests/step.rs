//! `[world] dt = "auto"`: the world's recommended step for its integrator
//! (`World::recommended_dt`), at most the default 1 ms; a step that is
//! neither a number nor "auto" is refused, naming the field.

use animats_engine::IntegratorKind;

/// Two 10 g particles on one stiff spring (ω = √(2k/m) ≈ 14,142 rad/s),
/// with the given `[world]` lines.
fn scene(world: &str, k: f64) -> String {
    format!(
        "[world]\n{world}\ngravity = [0, 0, 0]\n\n\
         [[particle]]\nname = \"a\"\nmass = 0.01\nradius = 0.01\nposition = [0, 1, 0]\n\n\
         [[particle]]\nname = \"b\"\nmass = 0.01\nradius = 0.01\nposition = [0.1, 1, 0]\n\n\
         [[spring]]\na = \"a\"\nb = \"b\"\nstiffness = {k}\n"
    )
}

#[test]
fn auto_takes_the_recommended_step_of_the_scene_integrator() {
    let omega = (2.0 * 1e6 / 0.01f64).sqrt();
    for (name, kind) in [
        ("symplectic", IntegratorKind::Symplectic),
        ("rk4", IntegratorKind::Rk4),
    ] {
        let text = scene(&format!("dt = \"auto\"\nintegrator = \"{name}\""), 1e6);
        let s = animats_scene::parse(&text, "stiff.toml").unwrap();
        assert_eq!(s.dt, kind.stable_omega_h() / omega, "{name}");
        assert_eq!(Some(s.dt), s.world.recommended_dt(kind));
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    }
}

#[test]
fn auto_is_at_most_the_default_step_and_a_given_step_is_kept() {
    // A soft spring allows 2/√(2·1/0.01) = 0.14 s: auto keeps 1 ms.
    let soft = animats_scene::parse(&scene("dt = \"auto\"", 1.0), "soft.toml").unwrap();
    assert_eq!(soft.dt, 0.001);
    let given = animats_scene::parse(&scene("dt = 0.004", 1.0), "soft.toml").unwrap();
    assert_eq!(given.dt, 0.004);
    // The stiff spring at 1 ms: warned, naming the spring's particles.
    let fast = animats_scene::parse(&scene("dt = 0.001", 1e6), "stiff.toml").unwrap();
    let w = fast.warnings.join("\n");
    assert!(
        w.contains("`a`–`b`") && w.contains("expect a blow-up"),
        "{w}"
    );
}

#[test]
fn a_step_that_is_neither_a_number_nor_auto_is_refused() {
    let err = animats_scene::parse(&scene("dt = \"fast\"", 1.0), "bad.toml")
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("bad.toml") && err.contains("dt") && err.contains("\"auto\""),
        "{err}"
    );
}
