//! `[[roobot]]` scene entries: built with their controllers, validated like
//! every other entry.

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
    assert_eq!(s.actors.len(), 2);
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
    assert!(["stance", "leap", "launch", "flight"].contains(&s.actors[1].status().unwrap().state));
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
    ] {
        let e = scene(entry).err().unwrap_or_else(|| panic!("accepted {entry}"));
        assert!(e.to_string().contains(expect), "{entry}: {e}");
    }
}
