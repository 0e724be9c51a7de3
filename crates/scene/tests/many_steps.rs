//! `Scene::steps(n, dt)`: a loop of steps that enters the thread pool once
//! for a world that splits its work (the Python `World.step(n)` and
//! `animats simulate` run through it). It must give the bits of `n` calls
//! of `Scene::step`, and stop at a blow-up.

/// A `side` × `side` net of 1 g beads 1 cm apart joined by springs, hanging
/// from its two top corners: 4,096 particles at side 64, enough that the
/// world splits its per-particle loops over threads.
fn net(side: usize, stiffness: f64, dt: f64) -> String {
    let mut s =
        format!("[world]\ngravity = [0, -9.8, 0]\nintegrator = \"symplectic\"\ndt = {dt}\n\n");
    let name = |i: usize, j: usize| format!("p{i}_{j}");
    for i in 0..side {
        for j in 0..side {
            let fixed = j == side - 1 && (i == 0 || i == side - 1);
            s += &format!(
                "[[particle]]\nname = \"{}\"\nmass = 0.001\nradius = 0.002\n\
                 position = [{}, {}, 0]\nfixed = {fixed}\n\n",
                name(i, j),
                0.01 * i as f64,
                1.0 + 0.01 * j as f64
            );
        }
    }
    for i in 0..side {
        for j in 0..side {
            let mut spring = |b: String| {
                s += &format!(
                    "[[spring]]\na = \"{}\"\nb = \"{b}\"\nstiffness = {stiffness}\ndamping = 0.001\n\n",
                    name(i, j)
                );
            };
            if i + 1 < side {
                spring(name(i + 1, j));
            }
            if j + 1 < side {
                spring(name(i, j + 1));
            }
        }
    }
    s
}

fn bits(scene: &animats_scene::Scene) -> Vec<u64> {
    let state = scene.world.state();
    state
        .pos
        .iter()
        .chain(&state.vel)
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect()
}

#[test]
fn many_steps_give_the_bits_of_one_step_at_a_time() {
    let text = net(64, 10.0, 1e-4);
    let mut looped = animats_scene::parse(&text, "net.toml").unwrap();
    let mut whole = animats_scene::parse(&text, "net.toml").unwrap();
    let start = bits(&whole);
    if rayon::current_num_threads() > 1 {
        assert!(whole.world.steps_on_pool(), "the net takes the pool's path");
    }
    for _ in 0..20 {
        looped.step(1e-4).unwrap();
    }
    whole.steps(20, 1e-4).unwrap();
    assert_eq!(whole.world.time(), looped.world.time());
    assert!(bits(&whole) == bits(&looped), "the states differ");
    assert!(bits(&whole) != start, "the net sags under gravity");
}

#[test]
fn many_steps_stop_at_a_blow_up_and_say_so() {
    // 1 g beads on 10⁶ N/m springs (ω ≈ 45,000 rad/s) at 1 ms: symplectic
    // Euler is unstable by a factor of 20 and the net blows up within
    // tens of steps (44 here).
    let mut scene = animats_scene::parse(&net(8, 1e6, 1e-3), "net.toml").unwrap();
    let err = scene.steps(100_000, 1e-3).expect_err("it blows up");
    let t = scene.world.time();
    assert!(
        t < 1.0,
        "it stopped at the blow-up, not at the end: t = {t}"
    );
    // The world keeps its last good state, and the error says what and who.
    assert!(scene.world.state().pos.iter().all(|p| p.is_finite()));
    let message = err.to_string();
    assert!(
        message.contains("non-finite") && message.contains("particle #"),
        "{message}"
    );
}

#[test]
fn steps_cut_where_asked_give_the_bits_of_steps_in_one_go() {
    // `steps_while` asks after every 64 steps: stopped at the second ask,
    // then run on to 300 in slices of the caller's, it takes the steps of
    // one `steps(300)` to the bit (Python's `World.step` answering Ctrl-C).
    let text = net(8, 10.0, 1e-4);
    let mut cut = animats_scene::parse(&text, "net.toml").unwrap();
    let mut whole = animats_scene::parse(&text, "net.toml").unwrap();
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let more = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) < 1;
    assert_eq!(cut.steps_while(300, 1e-4, more).unwrap(), 128);
    assert_eq!(asked.into_inner(), 2);
    assert_eq!(cut.steps_while(100, 1e-4, || false).unwrap(), 64);
    assert_eq!(cut.steps_while(108, 1e-4, || true).unwrap(), 108);
    // The last slice is not asked about: nothing is left after it.
    assert_eq!(cut.steps_while(0, 1e-4, || false).unwrap(), 0);
    whole.steps(300, 1e-4).unwrap();
    assert_eq!(cut.world.time(), whole.world.time());
    assert!(bits(&cut) == bits(&whole), "the states differ");
}
