//! `[[roobot]]` scene entries: built with their sensors, actuators and
//! brains in the scene's nervous system, validated like every other entry.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

fn scene(roobot: &str) -> Result<animats_scene::Scene, animats_scene::SceneError> {
    let text = format!("[world]\ndt = 0.008\nduration = 3.0\n[floor]\nstatic_speed = 0.2\n[fluid]\ndensity = 1.2\n\n{roobot}");
    animats_scene::parse(&text, "robots.toml")
}

#[test]
fn roobots_in_a_scene_hop_along_their_headings() {
    let mut s = scene(
        "[[roobot]]\nname = \"a\"\nheading = 0.0\n\n[[roobot]]\nname = \"b\"\nposition = [5.0, 0.0, 5.0]\nheading = 2.5\nparams = \"evolved\"\n",
    )
    .unwrap();
    // Their brains are the scene's controllers, named after them.
    let names: Vec<&str> = s
        .nervous
        .controllers
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(names, ["a", "b"]);
    assert!(s.actors.is_empty());
    assert_eq!(
        s.names[..5],
        ["a.hip", "a.foot", "a.head", "a.tail1", "a.tail2"]
    );
    let (ha, hb) = (s.particle("a.hip").unwrap(), s.particle("b.hip").unwrap());
    let (a0, b0) = (s.world.position(ha), s.world.position(hb));
    for _ in 0..375 {
        s.step(0.008).unwrap();
    }
    let fa = animats_engine::DVec3::X;
    let fb = animats_engine::DVec3::new(2.5f64.cos(), 0.0, -2.5f64.sin());
    let (da, db) = (
        (s.world.position(ha) - a0).dot(fa),
        (s.world.position(hb) - b0).dot(fb),
    );
    assert!(da > 2.0 && db > 2.0, "hopped {da} m and {db} m forward");
    // Both are upright and in flight or stance, not fallen.
    assert!(s.world.position(ha).y > 0.2 && s.world.position(hb).y > 0.2);
    let state = s.nervous.controllers[1].brain.state().unwrap();
    assert!(["stance", "leap", "launch", "flight"].contains(&state));
}

#[test]
fn bad_roobot_entries_are_refused() {
    for (entry, expect) in [
        ("[[roobot]]\nparams = [1.0, 2.0]\n", "roobot[0].params"),
        ("[[roobot]]\nparams = \"missing.toml\"\n", "cannot read the parameter file"),
        ("[[roobot]]\nwings = 2\n", "unknown field `wings`"),
        ("[[roobot]]\nheading = nan\n", "roobot[0].heading"),
        ("[[roobot]]\nname = \"x y\"\n", "roobot[0].name"),
        ("[[particle]]\nname = \"r.hip\"\nmass = 1\nposition = [0,1,0]\nradius = 0.1\n[[roobot]]\nname = \"r\"\n", "duplicate particle name `r.hip`"),
        ("[[roobot]]\ngains = [1.0]\n", "roobot[0].gains: `gains` are Raibert's"),
        ("[[roobot]]\nbrain = \"raibert\"\nparams = \"evolved\"\n", "roobot[0].params"),
        ("[[roobot]]\nbrain = \"raibert\"\ngains = [1.0, 2.0]\n", "expected 8 numbers, got 2"),
        ("[[roobot]]\nbrain = \"none\"\ngains = [1.0]\n", "roobot[0].gains"),
        ("[[roobot]]\nbrain = \"fsm\"\n", "unknown variant `fsm`"),
        ("[[roobot]]\nname = \"r\"\n[[sensor]]\nname = \"r.leg_angle\"\nkind = \"height\"\nparticle = \"r.hip\"\n", "duplicate sensor name `r.leg_angle`"),
        ("[[roobot]]\nname = \"r\"\n[[controller]]\nname = \"osc\"\nkind = \"oscillator\"\noutputs = [\"r.leg\"]\n", "actuator `r.leg` is already driven by controller `r`"),
    ] {
        let e = scene(entry).err().unwrap_or_else(|| panic!("accepted {entry}"));
        assert!(e.to_string().contains(expect), "{entry}: {e}");
    }
}

#[test]
fn a_roobot_without_a_brain_takes_a_scene_controller() {
    // Its sensors and actuators are the scene's to wire: an oscillator
    // pumps its leg.
    let mut s = scene(
        "[[roobot]]\nname = \"r\"\nbrain = \"none\"\n\n[[controller]]\nname = \"pump\"\nkind = \"oscillator\"\noutputs = [\"r.leg\"]\nfrequency = 2.0\namplitude = [0.4]\n",
    )
    .unwrap();
    let sensors: Vec<&str> = s.nervous.sensors.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        sensors,
        ["r.foot_height", "r.leg_angle", "r.hip_speed", "r.touchdown"]
    );
    let actuators: Vec<&str> = s
        .nervous
        .actuators
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(actuators, ["r.leg", "r.hip", "r.ankle"]);
    let leg = s.world.forces().springs.iter().next().unwrap().rest_length;
    let mut lengths = Vec::new();
    for _ in 0..125 {
        s.step(0.008).unwrap();
        lengths.push(s.world.forces().springs.iter().next().unwrap().rest_length);
    }
    // 2 Hz for 1 s: the leg's rest length swings both ways about its start.
    let (lo, hi) = lengths
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &l| (a.min(l), b.max(l)));
    assert!(lo < leg - 0.1 && hi > leg + 0.1, "{lo}..{hi} about {leg}");
}
