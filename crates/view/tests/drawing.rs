//! The one drawing model: what the page and the renderer both draw,
//! decided from the scene's structure (its creatures as data, its kinds of
//! part), not from names.

use animats_engine::DVec3;
use animats_view::drawing::Look;
use animats_view::{CreatureState, Drawing};

fn scene(file: &str) -> animats_scene::Scene {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file);
    animats_scene::load(&path).unwrap()
}

#[test]
fn balls_and_rods_follow_the_palette_and_the_radius_rules() {
    let s = scene("seaworld.toml");
    let d = Drawing::of(&s, 3.0);
    assert_eq!(d.balls.len(), s.world.len());
    let radius = &s.world.particles().radius;
    for (i, b) in d.balls.iter().enumerate() {
        assert_eq!(
            b.colour,
            animats_view::palette::colour_of(s.kinds[i].name())
        );
        assert_eq!(b.radius, radius[i].max(0.001));
        let bubble = s.kinds[i] == animats_scene::PartKind::Bubble;
        assert_eq!(b.shadow, !bubble);
        assert_eq!(b.look == Look::Clear, bubble);
    }
    assert_eq!(d.rods.len(), s.world.forces().springs.len());
    for r in &d.rods {
        let thin = radius[r.a].min(radius[r.b]);
        assert_eq!(r.radius, (0.3 * thin).clamp(0.0015, 0.012));
    }
    // Water (1000 kg/m³) and a fine checker seen from 3 m; a coarse one
    // from 10 m; air over the roobot's floor.
    assert!(d.water);
    assert_eq!(d.floor, Some(0.1));
    assert_eq!(Drawing::of(&s, 10.0).floor, Some(0.5));
    assert!(!Drawing::of(&scene("roobot.toml"), 3.0).water);
}

#[test]
fn each_jellyfish_gets_a_bell_over_its_dome_opening_towards_its_tentacles() {
    let s = scene("seaworld.toml");
    let d = Drawing::of(&s, 3.0);
    assert_eq!(d.bells.len(), 3, "three jellyfish");
    let pos = &s.world.state().pos;
    let idle: Vec<CreatureState> = d
        .bells
        .iter()
        .map(|b| CreatureState {
            name: b.name.clone(),
            state: "idle".into(),
            energy: None,
            phase: Some(std::f64::consts::FRAC_PI_2),
        })
        .collect();
    let shapes = d.bell_shapes(pos, &idle);
    for (plan, shape) in d.bells.iter().zip(&shapes) {
        let shape = shape.expect("a dome of three masses has a bell");
        assert_eq!(plan.dome.len(), 3);
        assert_eq!(plan.tentacles.len(), 12);
        let axis = DVec3::from_array(shape.axis);
        assert!((axis.length() - 1.0).abs() < 1e-12);
        let centre = plan.dome.iter().map(|&i| pos[i]).sum::<DVec3>() / 3.0;
        let tentacles = plan.tentacles.iter().map(|&i| pos[i]).sum::<DVec3>() / 12.0;
        assert!(
            axis.dot(centre - tentacles) > 0.0,
            "the crown faces away from the tentacles"
        );
        // Relaxed (idle): the rim wraps the ring and the masses' own size.
        let ring = plan
            .dome
            .iter()
            .map(|&i| pos[i].distance(centre))
            .sum::<f64>()
            / 3.0;
        assert!((shape.radius - 1.08 * (ring + plan.size)).abs() < 1e-12);
    }
    // At the top of the power stroke the bell is narrower and taller.
    let pulsing: Vec<CreatureState> = idle
        .into_iter()
        .map(|c| CreatureState {
            state: "track".into(),
            ..c
        })
        .collect();
    let squeezed = d.bell_shapes(pos, &pulsing);
    for (a, b) in shapes.iter().zip(&squeezed) {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!((b.radius / a.radius - 0.80 / 1.08).abs() < 1e-12);
        assert!((b.height / a.height - 1.20 / 0.75).abs() < 1e-12);
    }
}

/// Every joint is drawn as an axle through its joint particle: square to
/// an angle joint's plane (perpendicular to both arms), along a torque
/// joint's axis, 2 × 1.6 radii long; an undriven joint steel, a driven one
/// its motor's colour (the thesis's roobot: its hip and knee are driven).
#[test]
fn joints_are_axles_square_to_their_plane_or_along_their_axis() {
    for file in ["joints.toml", "hop_evolver.toml"] {
        let s = scene(file);
        let forces = s.world.forces();
        let d = Drawing::of(&s, 3.0);
        let (angles, torques) = (forces.angle_joints.len(), forces.torque_joints.len());
        assert_eq!(d.axles.len(), angles + torques, "{file}");
        assert!(!d.axles.is_empty(), "{file} has joints");
        let pos = &s.world.state().pos;
        let ends = d.axle_ends(pos);
        let radius = &s.world.particles().radius;
        for (k, (x, [a, b])) in d.axles.iter().zip(&ends).enumerate() {
            let (a, b) = (DVec3::from_array(*a), DVec3::from_array(*b));
            let centre = pos[x.joint];
            assert!(
                ((a + b) / 2.0 - centre).length() < 1e-12,
                "{file}: axle {k}"
            );
            assert!(((b - a).length() - 3.2 * radius[x.joint].max(0.001)).abs() < 1e-12);
            let dir = (b - a).normalize();
            if k < angles {
                let (p, j, q) = forces.angle_joints.iter().nth(k).unwrap().particles();
                assert_eq!(j.index(), x.joint);
                for arm in [pos[p.index()] - centre, pos[q.index()] - centre] {
                    if arm.length() > 0.0 {
                        assert!(
                            dir.dot(arm.normalize()).abs() < 1e-9,
                            "{file}: axle {k} not square to its arm"
                        );
                    }
                }
            } else {
                let t = forces.torque_joints.iter().nth(k - angles).unwrap();
                assert_eq!(t.particles().1.index(), x.joint);
                assert!(
                    (dir.dot(t.axis()).abs() - 1.0).abs() < 1e-12,
                    "{file}: axle {k}"
                );
            }
        }
        // Colours: steel undriven; a motor follows its actuator's level.
        let levels = vec![1.0; s.nervous.actuators.len()];
        for (x, c) in d.axles.iter().zip(d.axle_colours(&levels)) {
            match x.motor {
                Some(_) => assert_eq!(c, animats_view::drawing::muscle_colour(1.0), "{file}"),
                None => assert_eq!(c, x.colour, "{file}"),
            }
        }
    }
    // The roobot's joints are driven (its hip and knee motors).
    let d = Drawing::of(&scene("hop_evolver.toml"), 3.0);
    assert!(d.axles.iter().any(|x| x.motor.is_some()));
}
