//! `[terrain]` in a scene file: each kind builds the floor's shape, bad
//! values are named, and a scene's creatures and rules see the ground.

fn ball_on(terrain: &str, y: f64) -> String {
    format!(
        "[world]\ndt = 0.001\n\n\
         [[particle]]\nname = \"ball\"\nmass = 0.1\nposition = [0.2, {y}, 0.1]\nradius = 0.05\n\
         mu_s = 0.5\nmu_k = 0.3\n\n{terrain}"
    )
}

fn run(text: &str, seconds: f64) -> animats_scene::Scene {
    let mut s = animats_scene::parse(text, "t.toml").unwrap_or_else(|e| panic!("{e}"));
    for _ in 0..(seconds / s.dt).round() as usize {
        s.step(s.dt).unwrap();
    }
    s
}

fn error(text: &str) -> String {
    match animats_scene::parse(text, "t.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn each_kind_of_terrain_holds_a_dropped_ball_on_its_surface() {
    let kinds = [
        "[terrain]\nkind = \"slope\"\nangle = 10\n",
        "[terrain]\nkind = \"slope\"\nangle = 10\ndirection = [0, 0, -1]\n\n[floor]\n",
        "[terrain]\nkind = \"steps\"\nheight = 0.1\ndepth = 0.3\nstart = 0.0\ncount = 3\n",
        "[terrain]\nkind = \"heightfield\"\ncell = 0.25\nheights = [[0, 0.1, 0], [0.05, 0.2, 0.1], [0, 0, 0]]\n",
        "[terrain]\nkind = \"heightfield\"\ncell = 0.1\nsize = [20, 20]\nroughness = 0.02\nseed = 4\n",
    ];
    for terrain in kinds {
        let s = run(&ball_on(terrain, 0.6), 3.0);
        let ball = animats_engine::ParticleId::from_index(0);
        let (x, v) = (s.world.position(ball), s.world.velocity(ball));
        let ground = s.world.terrain().expect("a floor").height(x.x, x.z);
        let gap = s.world.clearance(ball);
        println!(
            "{terrain}: at {x}, ground {ground:.4}, gap {gap:.2e}, speed {:.2e}",
            v.length()
        );
        // Resting on it (within the contact tolerance), not under it.
        assert!((0.0..=1e-6).contains(&gap), "{terrain}: gap {gap}");
        assert!(x.y > ground, "{terrain}");
        assert!(v.length() < 1e-6, "{terrain}: still moving at {v}");
    }
}

#[test]
fn a_generated_heightfield_is_the_same_for_the_same_seed_and_follows_the_scene_seed() {
    let field = "[terrain]\nkind = \"heightfield\"\ncell = 0.1\nsize = [8, 8]\nroughness = 0.03\n";
    let height = |text: &str| {
        let s = animats_scene::parse(text, "t.toml").unwrap();
        let t = s.world.terrain().unwrap().clone();
        (0..20)
            .map(|k| t.height(-0.3 + 0.03 * f64::from(k), 0.1))
            .collect::<Vec<_>>()
    };
    let a = height(&ball_on(field, 1.0));
    assert_eq!(a, height(&ball_on(field, 1.0)));
    assert!(a.iter().all(|h| h.abs() <= 0.03) && a.iter().any(|h| h.abs() > 0.005));
    let other = ball_on(field, 1.0).replace("dt = 0.001", "dt = 0.001\nseed = 9");
    assert_ne!(a, height(&other));
}

#[test]
fn bad_terrain_is_named() {
    for (terrain, expect) in [
        ("kind = \"slope\"\nangle = 95", "terrain.angle"),
        // The bound the message gives is the one applied.
        (
            "kind = \"slope\"\nangle = 89.9999999",
            "terrain.angle: must be at least 0° and under 89.99994°",
        ),
        (
            "kind = \"slope\"\nangle = 10\ndirection = [0, 1, 0]",
            "terrain.direction",
        ),
        ("kind = \"steps\"\nheight = 0.1\ndepth = 0", "terrain.depth"),
        ("kind = \"cliff\"", "unknown variant `cliff`"),
        (
            "kind = \"heightfield\"\ncell = 0.1\nheights = [[0, 1], [0]]",
            "row 1 has 1 heights",
        ),
        ("kind = \"heightfield\"\ncell = 0.1", "needs `heights`"),
        (
            "kind = \"heightfield\"\ncell = 0.1\nsize = [4, 4]",
            "needs `roughness`",
        ),
        (
            "kind = \"heightfield\"\ncell = 0.1\nsize = [100000, 100000]\nroughness = 0.1",
            "at most",
        ),
        (
            "kind = \"heightfield\"\ncell = -1\nheights = [[0, 1], [0, 0]]",
            "terrain.cell",
        ),
        (
            "kind = \"heightfield\"\ncell = 0.1\nheights = [[0, 1]]",
            "2 × 2",
        ),
    ] {
        let e = error(&ball_on(&format!("[terrain]\n{terrain}\n"), 0.5));
        println!("{e}");
        assert!(e.contains(expect), "{terrain}: {e}");
        assert!(e.starts_with("t.toml"), "{e}");
    }
}

#[test]
fn a_ball_starting_inside_the_terrain_is_warned_about() {
    let s = animats_scene::parse(
        &ball_on("[terrain]\nkind = \"slope\"\nangle = 30\n", 0.1),
        "t.toml",
    )
    .unwrap();
    // At x = 0.2 a 30° slope stands 0.115 m high: the ball's centre is
    // under it.
    assert!(
        s.warnings.iter().any(|w| w.contains("inside the terrain")),
        "{:?}",
        s.warnings
    );
}
