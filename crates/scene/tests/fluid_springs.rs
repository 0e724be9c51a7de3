//! `[fluid] springs`: the scene's springs become rods the fluid pushes on
//! across their length (`RodDrag`). A pair joined by a spring and coasting
//! across itself slows faster with them; coasting along itself it moves
//! to the bit as without them; a spring with an end outside the fluid is
//! no rod; bad values are refused by name.

use animats_engine::DVec3;

/// Two 0.1 kg spheres (radius 1 cm) 0.3 m apart along x, joined by a
/// spring, moving with `v`, in still water (no gravity), with `fluid`
/// added to the `[fluid]` table.
fn pair(v: [f64; 3], fluid: &str) -> String {
    format!(
        "[world]\ndt = 0.001\nintegrator = \"rk4\"\ngravity = [0.0, 0.0, 0.0]\n\
         [fluid]\n{fluid}\n\
         [[particle]]\nname = \"a\"\nmass = 0.1\nradius = 0.01\nposition = [0.0, 0.0, 0.0]\nvelocity = {v:?}\n\
         [[particle]]\nname = \"b\"\nmass = 0.1\nradius = 0.01\nposition = [0.3, 0.0, 0.0]\nvelocity = {v:?}\n\
         [[spring]]\na = \"a\"\nb = \"b\"\nstiffness = 100.0\n"
    )
}

/// The velocity of particle `a` after 1 s.
fn coast(text: &str) -> DVec3 {
    let mut s = animats_scene::parse(text, "pair.toml").unwrap();
    let dt = s.dt;
    s.steps(1000, dt).unwrap();
    let a = s.particle("a").unwrap();
    s.world.velocity(a)
}

#[test]
fn springs_in_the_fluid_drag_across_themselves_and_not_along() {
    let rods = "springs = { diameter = 0.02 }";
    // Across: the rod's drag (½ C ρ D L = 3.6 N s²/m² on 0.2 kg) dwarfs
    // the spheres' (½ C ρ π r² = 0.074 each): v₀ / (1 + k v₀ t) with
    // k = 18 + 0.74 per metre, 0.0520 m/s after 1 s, against 0.808 m/s
    // with the spheres' drag alone.
    let across = coast(&pair([0.0, 2.0, 0.0], rods));
    let spheres_only = coast(&pair([0.0, 2.0, 0.0], ""));
    let k = 0.5 * 1.2 * 1000.0 * 0.02 * 0.3 / 0.2
        + 0.5 * 0.47 * 1000.0 * std::f64::consts::PI * 1e-4 / 0.1;
    let want = 2.0 / (1.0 + k * 2.0);
    assert!(
        (across.y - want).abs() < 1e-6 * want,
        "across: {across}, expected {want} along y"
    );
    assert!(
        spheres_only.y > 15.0 * across.y,
        "{spheres_only} against {across}"
    );
    // Along: not a bit of difference.
    assert_eq!(
        coast(&pair([2.0, 0.0, 0.0], rods)),
        coast(&pair([2.0, 0.0, 0.0], ""))
    );
    // A spring with an end outside the fluid is no rod.
    assert_eq!(
        coast(&pair(
            [0.0, 2.0, 0.0],
            "particles = [\"a\"]\nsprings = { diameter = 0.02 }"
        )),
        coast(&pair([0.0, 2.0, 0.0], "particles = [\"a\"]"))
    );
}

#[test]
fn bad_rod_values_are_refused_by_name() {
    for (fluid, expect) in [
        ("springs = { diameter = 0.0 }", "fluid.springs.diameter"),
        ("springs = { diameter = nan }", "fluid.springs.diameter"),
        (
            "springs = { diameter = 0.02, drag_coefficient = -1.0 }",
            "fluid.springs.drag_coefficient",
        ),
        (
            "springs = { diameter = 0.02, width = 1.0 }",
            "unknown field `width`",
        ),
        (
            "springs = { drag_coefficient = 1.0 }",
            "missing field `diameter`",
        ),
    ] {
        let e = animats_scene::parse(&pair([0.0; 3], fluid), "pair.toml")
            .err()
            .unwrap_or_else(|| panic!("{fluid} was accepted"))
            .to_string();
        assert!(e.contains(expect), "{fluid}: {e}");
        assert!(e.contains("pair.toml"), "{fluid}: {e}");
    }
}
