//! The thesis's roobot as a scene (`scenes/hop_evolver.toml`): its hopping
//! FSM and Raibert's controller are brains in the nervous system, its
//! fitness and end rules the `[evolve]` table's, its environment the
//! scene's.
//!
//! What must hold (issue 3): Appendix B's initial parameters hop and fall
//! within the first few landings (the thesis's starting point); the evolved
//! parameters hop for the full 20 s and travel forward, visiting stance →
//! leap → launch → flight → stance on every hop; the hip motor acts only in
//! flight and the ankle motor only in stance. Raibert's controller does
//! what each of its parts is for.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::env::Env;
use animats_creatures::roobot::{foot_down, raibert, HopParams};
use animats_creatures::vec_env::VecEnv;
use animats_engine::DVec3;
use animats_scene::env::SceneEnv;
use animats_scene::evaluate::{evaluate_with, Ended, Evaluation, SceneProblem};
use animats_scene::{Scene, HOP_EVOLVER, HOP_EVOLVER_FILE};

fn thesis() -> SceneProblem {
    SceneProblem::parse(HOP_EVOLVER, HOP_EVOLVER_FILE).unwrap()
}

fn evolved() -> HopParams {
    animats_scene::params::load("evolved", None).unwrap()
}

/// One letter per FSM state: S, L, A (launch), F.
fn letter(s: &Scene) -> char {
    match s.nervous.controllers[0].brain.state() {
        Some("stance") => 'S',
        Some("leap") => 'L',
        Some("launch") => 'A',
        Some("flight") => 'F',
        other => panic!("not a hopping state: {other:?}"),
    }
}

/// The phase sequence of a whole evaluation as letters, its landings
/// (flight → stance), and the evaluation.
fn phases(params: HopParams) -> (String, u32, Evaluation) {
    let mut seq = String::new();
    let mut landings = 0;
    let scene = thesis().scene(&params.0).unwrap();
    let e = evaluate_with(scene, |s| {
        let c = letter(s);
        if seq.ends_with('F') && c == 'S' {
            landings += 1;
        }
        if !seq.ends_with(c) {
            seq.push(c);
        }
    })
    .unwrap();
    (seq, landings, e)
}

#[test]
fn initial_parameters_land_three_times_then_fall_on_the_head_with_the_hip_clear() {
    // docs/ROOBOT.md: three landings, then the head touches the floor while
    // the hip is still clear (the thesis's rule, the hip alone, would let
    // the run go on; ours counts any part but the foot).
    let (seq, landings, e) = phases(HopParams::INITIAL);
    println!("initial: {seq} {e:?}");
    assert_eq!(e.ended, Ended::Touch("roobot.head".into()));
    assert_eq!(landings, 3);
    assert!(seq.starts_with("SLAFSLAFSLAFS"), "it hops: {seq}");
    let mut last = None;
    evaluate_with(thesis().scene(&HopParams::INITIAL.0).unwrap(), |s| {
        let clear = |name: &str| {
            let p = s.particle(name).unwrap();
            s.world.position(p).y - s.world.particles().radius[p.index()]
        };
        last = Some((clear("roobot.hip"), clear("roobot.head")));
    })
    .unwrap();
    let (hip, head) = last.unwrap();
    println!("at the end: hip {hip:.4} m clear, head {head:.2e} m");
    assert!(head <= 1e-9, "the head touched down: {head}");
    assert!(hip > 0.02, "the hip is still clear: {hip}");
}

#[test]
fn evolved_parameters_hop_for_twenty_seconds_and_travel_forward() {
    let e = thesis().evaluate(&evolved().0).unwrap();
    assert_eq!(e.ended, Ended::Timeout);
    assert_eq!(e.time, 20.0);
    assert!(e.distance > 10.0, "{} m", e.distance);
    // The number users rely on (README, docs/ROOBOT.md).
    assert_eq!(e.fitness, 2172.090056744124);
}

#[test]
fn every_evolved_hop_goes_stance_leap_launch_flight() {
    let (seq, landings, _) = phases(evolved());
    // The whole run is the hop "SLAF" repeated, once per landing, ending in
    // the phase it was in at 20 s.
    let hops = landings as usize;
    assert!(hops >= 10);
    let expected = "SLAF".repeat(hops + 1);
    assert!(
        expected.starts_with(&seq) && seq.len() > 4 * hops,
        "phase sequence {seq} is not SLAF×{hops}"
    );
}

#[test]
fn hip_motor_acts_only_in_flight_and_ankle_only_in_stance() {
    // A table of the steps of Appendix B's initial gait (which keeps an
    // active stance) by FSM phase and foot contact: for each, how many steps
    // the hip and ankle motors pushed. Thesis §3.2.1.2: the hip motor swings
    // the leg in flight, the ankle motor pitches the body in stance.
    use std::collections::BTreeMap;
    // The torques acting during a step were set from the senses at its
    // start: classify each step by the foot's contact then.
    let mut table: BTreeMap<(char, bool), [u32; 3]> = BTreeMap::new();
    let mut down_before: Option<bool> = None;
    evaluate_with(thesis().scene(&HopParams::INITIAL.0).unwrap(), |s| {
        // The roobot's two motors, hip first.
        let motors: Vec<f64> = s
            .world
            .forces()
            .torque_joints
            .iter()
            .map(|m| m.torque)
            .collect();
        let foot = s.particle("roobot.foot").unwrap();
        let Some(down) = down_before.replace(foot_down(&s.world, foot)) else {
            return; // before the first step
        };
        let row = table.entry((letter(s), down)).or_default();
        row[0] += 1;
        row[1] += (motors[0] != 0.0) as u32;
        row[2] += (motors[1] != 0.0) as u32;
    })
    .unwrap();
    println!("(phase, foot down): [steps, hip on, ankle on] {table:?}");
    for (&(phase, down), &[steps, hip, ankle]) in &table {
        if down {
            assert_eq!(hip, 0, "{phase} on the floor: the hip motor pushed");
        } else {
            assert_eq!(ankle, 0, "{phase} in the air: the ankle motor pushed");
        }
        assert!(steps > 0);
    }
    // And each motor does act in its own phase.
    let on = |phase: char, down: bool, i: usize| table.get(&(phase, down)).map_or(0, |r| r[i]);
    assert!(
        on('F', false, 1) > 10,
        "the hip never swung the leg in flight"
    );
    assert!(on('S', true, 2) > 10, "the ankle never acted in stance");
}

/// A scene of one roobot with `entry`'s keys, in the thesis's world.
fn one_roobot(entry: &str) -> Scene {
    let text = format!(
        "[world]\ndt = 0.008\n[floor]\nenvelope = 0.01\nstatic_speed = 0.2\n[fluid]\ndensity = 1.2\n[[roobot]]\nname = \"r\"\n{entry}\n"
    );
    animats_scene::parse(&text, "one.toml").unwrap()
}

#[test]
fn the_evolved_gait_hops_whichever_way_it_faces() {
    // The planar body is held in its plane, so a heading only rotates the
    // same hop (up to rounding, which this chaotic gait shrugs off).
    let straight = thesis().evaluate(&evolved().0).unwrap().distance;
    for heading in [0.3, std::f64::consts::FRAC_PI_2, 3.0, -2.0] {
        let mut s = one_roobot(&format!(
            "position = [1.0, 0.0, -2.0]\nheading = {heading}\nparams = \"evolved\""
        ));
        let hip = s.particle("r.hip").unwrap();
        let forward = DVec3::new(f64::cos(heading), 0.0, -f64::sin(heading));
        let x0 = s.world.position(hip);
        for _ in 0..2500 {
            assert!(
                s.world.position(hip).y > 0.1,
                "heading {heading}: fell at {} s",
                s.world.time()
            );
            s.step(0.008).unwrap();
        }
        let moved = s.world.position(hip) - x0;
        let along = moved.dot(forward);
        // The gait is chaotic: rounding moves each landing a little, so the
        // distance varies by a few per cent from one start to another.
        assert!(
            (along - straight).abs() < 0.1 * straight,
            "heading {heading}: {along} m vs {straight} m"
        );
        let sideways = moved.dot(forward.cross(DVec3::Y));
        assert!(
            sideways.abs() < 1e-9 * along,
            "heading {heading}: drifted {sideways} m sideways"
        );
    }
}

/// The thesis's scene with Raibert's controller (its hand-set gains).
fn raibert_problem() -> SceneProblem {
    let text = HOP_EVOLVER.replace("params = \"initial\"", "brain = \"raibert\"");
    let problem = SceneProblem::parse(&text, "raibert.toml").unwrap();
    assert_eq!(problem.start(), raibert::START);
    problem
}

/// Mean of the hip's highest point in each flight after the first 5 s, the
/// mean forward speed over the last 10 s, and how the run ended.
fn raibert_gait(gains: [f64; raibert::GAIN_COUNT]) -> (f64, f64, Ended) {
    let scene = raibert_problem().scene(&gains).unwrap();
    let dt = scene.dt;
    let (mut apexes, mut top, mut x10) = (Vec::new(), f64::MIN, None);
    let mut last_x = 0.0;
    let e = evaluate_with(scene, |s| {
        let hip = s.world.position(s.particle("roobot.hip").unwrap());
        let flying = !foot_down(&s.world, s.particle("roobot.foot").unwrap());
        let t = s.world.time();
        if t > 5.0 {
            if flying {
                top = top.max(hip.y);
            } else if top > f64::MIN {
                apexes.push(top);
                top = f64::MIN;
            }
        }
        if (t - 10.0).abs() < 0.5 * dt {
            x10 = Some(hip.x);
        }
        last_x = hip.x;
    })
    .unwrap();
    let apex = apexes.iter().sum::<f64>() / apexes.len().max(1) as f64;
    let speed = x10.map_or(f64::NAN, |x| (last_x - x) / 10.0);
    (apex, speed, e.ended)
}

#[test]
fn raiberts_hand_set_gains_hop_for_20_s_and_evaluations_repeat() {
    let p = raibert_problem();
    let mut landings = 0;
    let mut flying = false;
    let a = evaluate_with(p.scene(&raibert::START).unwrap(), |s| {
        let state = s.nervous.controllers[0].brain.state();
        if flying && state == Some("stance") {
            landings += 1;
        }
        flying = state == Some("flight");
    })
    .unwrap();
    let b = p.evaluate(&raibert::START).unwrap();
    assert_eq!(a, b);
    println!("Raibert, hand-set gains: {a:?}, {landings} landings");
    assert_eq!(a.ended, Ended::Timeout, "{a:?}");
    assert!(landings > 20 && a.distance > 5.0, "{a:?}");
}

#[test]
fn more_stance_thrust_hops_higher() {
    let mut apexes = Vec::new();
    for thrust in [0.1, 0.125, 0.15] {
        let mut g = raibert::START;
        g[0] = thrust;
        let (apex, _, ended) = raibert_gait(g);
        println!("thrust {thrust}: apex {apex:.3} m ({ended})");
        assert_eq!(ended, Ended::Timeout);
        apexes.push(apex);
    }
    assert!(apexes[0] < apexes[1] && apexes[1] < apexes[2], "{apexes:?}");
}

#[test]
fn the_speed_wanted_sets_the_speed_it_hops_at() {
    let mut speeds = Vec::new();
    for wanted in [0.5, 0.75, 1.0] {
        let mut g = raibert::START;
        g[3] = wanted;
        g[2] = 0.15;
        let (_, speed, ended) = raibert_gait(g);
        println!("wanted {wanted} m/s: {speed:.3} m/s ({ended})");
        assert_eq!(ended, Ended::Timeout);
        speeds.push(speed);
    }
    assert!(speeds[0] < speeds[1] && speeds[1] < speeds[2], "{speeds:?}");
    // Tracked within a third.
    for (s, w) in speeds.iter().zip([0.5, 0.75, 1.0]) {
        assert!((s - w).abs() < w / 3.0, "{s} m/s for {w} wanted");
    }
}

#[test]
fn replaying_the_fsm_in_the_environment_gives_its_trajectory_and_fitness() {
    // The environment is the evaluation with a program in the FSM's place:
    // the levels the FSM chose, replayed step by step, give the same hip
    // positions bit for bit (the gates still hold each motor off in its
    // other phase) and rewards that add up to the fitness.
    let scene = thesis().scene(&evolved().0).unwrap();
    let (mut levels, mut hips) = (Vec::new(), Vec::new());
    let mut first = true;
    let e = evaluate_with(scene, |s| {
        if first {
            first = false;
            return;
        }
        levels.push(s.nervous.actuator_levels());
        hips.push(s.world.position(s.particle("roobot.hip").unwrap()));
    })
    .unwrap();
    let steps = (e.time / 0.008).round() as usize;
    let mut env = SceneEnv::parse(HOP_EVOLVER, HOP_EVOLVER_FILE, 0.0).unwrap();
    assert_eq!(
        env.action_names(),
        ["roobot.leg", "roobot.hip", "roobot.ankle"]
    );
    assert_eq!(
        env.observation_names(),
        [
            "roobot.foot_height",
            "roobot.leg_angle",
            "roobot.hip_speed",
            "roobot.touchdown"
        ]
    );
    let mut total = 0.0;
    let mut ended_at = None;
    for (k, (a, hip)) in levels.iter().zip(&hips).enumerate() {
        let t = env.step(a).unwrap();
        total += t.reward;
        let s = env.scene();
        assert_eq!(
            s.world.position(s.particle("roobot.hip").unwrap()),
            *hip,
            "step {k}"
        );
        if t.terminated || t.truncated {
            ended_at = Some((k + 1, t.truncated));
            break;
        }
    }
    // The evolved gait stays up 20 s: the episode is truncated at 2500 steps.
    assert_eq!(ended_at, Some((steps, true)));
    assert!(
        (total - e.fitness).abs() <= 1e-9 * e.fitness,
        "sum of rewards {total} against fitness {}",
        e.fitness
    );
    assert_eq!(env.fitness(), e.fitness);
    assert!(env.step(&levels[0]).is_err(), "stepping past the end");
}

#[test]
fn a_roobot_that_does_nothing_falls_and_the_episode_terminates() {
    let mut env = SceneEnv::parse(HOP_EVOLVER, HOP_EVOLVER_FILE, 0.0).unwrap();
    let mut obs = [0.0; 4];
    env.observe(&mut obs);
    assert!(obs.iter().all(|o| (0.0..=1.0).contains(o)), "{obs:?}");
    // Hip swung fully one way: it topples within a few seconds.
    let mut k = 0;
    loop {
        let t = env.step(&[0.5, 1.0, 0.5]).unwrap();
        k += 1;
        assert!(!t.truncated, "it never fell");
        if t.terminated {
            break;
        }
    }
    assert!(k < 2500, "{k}");
    assert!(env.step(&[0.5; 3]).is_err());
    env.reset(0).unwrap();
    assert_eq!(env.time(), 0.0);
    assert!(env.step(&[0.5, f64::NAN, 0.5]).is_err());
    assert!(env.step(&[0.5]).is_err());
}

#[test]
fn a_vector_of_roobots_is_the_same_bits_on_any_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let n = 300;
            let mut v = VecEnv::new(n, 7, |_| {
                SceneEnv::parse(HOP_EVOLVER, HOP_EVOLVER_FILE, 0.05).map_err(|e| e.to_string())
            })
            .unwrap();
            let mut out = vec![
                animats_creatures::env::Transition {
                    reward: 0.0,
                    terminated: false,
                    truncated: false,
                };
                n
            ];
            let mut obs = vec![0.0; n * 4];
            let mut rewards = Vec::new();
            for s in 0..400 {
                let actions: Vec<f64> = (0..n * 3)
                    .map(|i| ((i * 7 + s * 13) % 100) as f64 / 100.0)
                    .collect();
                v.step(&actions, &mut out).unwrap();
                rewards.extend(out.iter().map(|t| t.reward));
            }
            v.observe(&mut obs);
            (rewards, obs)
        })
    };
    let (r1, o1) = run(1);
    let (r2, o2) = run(2);
    assert_eq!(r1, r2);
    assert_eq!(o1, o2);
    // The noise makes the copies differ.
    assert_ne!(o1[0..4], o1[4..8]);
}

/// A step or reset told to stop before it starts moves no copy and says
/// so; untold, the same vector steps on as one never told.
#[test]
fn a_vector_step_told_to_stop_moves_no_copy() {
    use std::sync::atomic::AtomicBool;
    let make = || {
        VecEnv::new(200, 3, |_| {
            SceneEnv::parse(HOP_EVOLVER, HOP_EVOLVER_FILE, 0.05).map_err(|e| e.to_string())
        })
        .unwrap()
    };
    let transition = animats_creatures::env::Transition {
        reward: 0.0,
        terminated: false,
        truncated: false,
    };
    let (mut v, mut w) = (make(), make());
    let (mut out, mut out_w) = (vec![transition; 200], vec![transition; 200]);
    let actions = vec![0.6; 200 * 3];
    let (mut before, mut after) = (vec![0.0; 200 * 4], vec![0.0; 200 * 4]);
    v.observe(&mut before);
    let stop = AtomicBool::new(true);
    let err = v.step_unless(&actions, &mut out, &stop).unwrap_err();
    assert_eq!(err, animats_creatures::vec_env::INTERRUPTED);
    v.observe(&mut after);
    assert_eq!(before, after, "no copy moved");
    assert!(v.reset_unless(9, &stop).is_err());
    for _ in 0..50 {
        v.step(&actions, &mut out).unwrap();
        w.step(&actions, &mut out_w).unwrap();
    }
    v.observe(&mut before);
    w.observe(&mut after);
    assert_eq!(before, after);
    assert_eq!(out, out_w);
}
