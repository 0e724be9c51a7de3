//! A scene as an environment is its `[evolve]` evaluation with a program
//! in the controllers' place: replaying what the controller ordered gives
//! the same trajectory, bit for bit, and rewards that add up to the
//! evaluation's fitness.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::env::Env;
use animats_scene::env::{Observation, SceneEnv};
use animats_scene::evaluate::{evaluate_with, Ended};

/// The pogo stick scored on staying up and on its height gained (its
/// centre of mass along +y), for 5 s.
fn pogo() -> String {
    format!(
        "{}\n[evolve]\ncontroller = \"hop\"\nduration = 5.0\naxis = [0.0, 1.0, 0.0]\n",
        include_str!("../../../scenes/pogo.toml")
    )
}

#[test]
fn replaying_the_controllers_orders_gives_the_evaluation() {
    let scene = animats_scene::parse(&pogo_costed(), "pogo.toml").unwrap();
    let (mut orders, mut centres) = (Vec::new(), Vec::new());
    let mut first = true;
    let e = evaluate_with(scene, |s| {
        if first {
            first = false;
            return;
        }
        // After each step: what each actuator was ordered for it.
        let mut targets = s.nervous.actuator_levels();
        for c in &s.nervous.controllers {
            for (&o, &l) in c.outputs.iter().zip(c.orders()) {
                targets[o] = l;
            }
        }
        orders.push(targets);
        centres.push(s.evolve.as_ref().unwrap().centre(&s.world));
    })
    .unwrap();
    assert_eq!(e.ended, Ended::Timeout);
    assert!(e.distance.abs() > 0.0 && e.energy.unwrap() > 0.0, "{e:?}");

    let mut env = SceneEnv::parse(&pogo_costed(), "pogo.toml", 0.0).unwrap();
    assert_eq!(env.action_names(), ["leg_muscle"]);
    assert_eq!(env.observation_size(), 2);
    let mut total = 0.0;
    let mut last = None;
    for (k, (a, c)) in orders.iter().zip(&centres).enumerate() {
        let t = env.step(a).unwrap();
        total += t.reward;
        let s = env.scene();
        assert_eq!(s.evolve.as_ref().unwrap().centre(&s.world), *c, "step {k}");
        assert!(!t.terminated, "step {k}");
        last = Some(t);
    }
    assert!(
        last.unwrap().truncated,
        "the episode ends at the evaluation's duration"
    );
    // Time, distance, the muscles' work and the target: all of it.
    assert_eq!(env.fitness(), e.fitness);
    assert_eq!(Some(env.energy()), e.energy);
    assert!((total - e.fitness).abs() <= 1e-9 * e.fitness.abs().max(1.0));
    assert!(env.step(&orders[0]).is_err(), "stepping past the end");
}

#[test]
fn an_environment_needs_actuators_and_evolve_and_sensors_to_observe_them() {
    let walker = include_str!("../../../scenes/walker.toml");
    // No sensors: it observes its state.
    let env = SceneEnv::parse(walker, "walker.toml", 0.0).unwrap();
    assert_eq!(env.observation_names()[0], "centre y");
    let err = env
        .with_actions(1, Observation::Sensors)
        .err()
        .expect("the walker has no sensors");
    assert!(err.contains("[[sensor]]"), "{err}");
    let plain = "[world]\ndt = 0.01\n[[particle]]\nname = \"a\"\nmass = 1.0\nposition = [0.0, 1.0, 0.0]\nradius = 0.1\n";
    let err = SceneEnv::parse(plain, "plain.toml", 0.0)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("[evolve]"), "{err}");
}

#[test]
fn reset_noise_is_drawn_from_the_seed() {
    let mut env = SceneEnv::parse(&pogo(), "pogo.toml", 0.01).unwrap();
    let run = |env: &mut SceneEnv, seed| {
        env.reset(seed).unwrap();
        for _ in 0..200 {
            env.step(&[0.7]).unwrap();
        }
        env.fitness()
    };
    let a = run(&mut env, 1);
    let b = run(&mut env, 1);
    let c = run(&mut env, 2);
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert!(env.step(&[f64::NAN]).is_err());
    assert!(env.step(&[0.5, 0.5]).is_err());
}

/// The pogo stick with an energy weight and a target, so that every term
/// of the fitness that an environment rewards is in play.
fn pogo_costed() -> String {
    pogo() + "energy_weight = 0.5\ntarget = [0.3, 1.0, 0.0]\ntarget_weight = 2.0\n"
}

#[test]
fn held_actions_are_single_steps_repeated_and_rewards_still_add_up() {
    let text = pogo_costed();
    let e = animats_scene::evaluate::evaluate(animats_scene::parse(&text, "pogo.toml").unwrap())
        .unwrap();
    let mut one = SceneEnv::parse(&text, "pogo.toml", 0.0).unwrap();
    let mut held = SceneEnv::parse(&text, "pogo.toml", 0.0)
        .unwrap()
        .with_actions(7, Observation::Both)
        .unwrap();
    assert_eq!(held.dt(), 7.0 * one.dt());
    assert_eq!(held.max_steps(), one.max_steps().div_ceil(7));
    let action = |k: u64| [0.5 + 0.4 * (k as f64 * 0.37).sin()];
    let (mut total, mut k) = (0.0, 0u64);
    loop {
        let a = action(k);
        let t = held.step(&a).unwrap();
        total += t.reward;
        for _ in 0..7 {
            if one.physics_done() {
                break;
            }
            one.step(&a).unwrap();
        }
        k += 1;
        let (s, r) = (held.scene(), one.scene());
        assert_eq!(s.world.state().pos, r.world.state().pos, "action {k}");
        if t.ends() {
            assert!(t.truncated && !t.terminated);
            break;
        }
    }
    assert_eq!(k, held.max_steps());
    assert_eq!(held.fitness(), one.fitness());
    assert!((total - held.fitness()).abs() < 1e-9 * held.fitness().abs().max(1.0));
    // The info: distance, work and why it ended.
    assert_eq!(held.ended(), Some(&animats_scene::evaluate::Ended::Timeout));
    assert!(held.energy() > 0.0 && held.distance().abs() > 0.0);
    // Driven by the same orders as its controller, the fitness is the
    // evaluation's, energy and target included.
    println!("evaluation {e:?}; environment {} J", held.energy());
    assert!(e.energy.unwrap() > 0.0 && e.target_distance.unwrap() > 0.0);
}

#[test]
fn the_state_is_relative_to_the_centre_of_mass() {
    let walker = include_str!("../../../scenes/walker.toml");
    let mut env = SceneEnv::parse(walker, "walker.toml", 0.0)
        .unwrap()
        .with_actions(10, Observation::State)
        .unwrap();
    for _ in 0..30 {
        env.step(&[0.5; 6]).unwrap();
    }
    let names = env.observation_names();
    let mut o = vec![0.0; env.observation_size()];
    env.observe(&mut o);
    let s = env.scene();
    let (n, springs) = (s.world.len(), s.world.forces().springs.len());
    // Centre height and velocity, positions, velocities, lengths, contacts.
    assert_eq!(o.len(), 4 + 6 * n + springs + n, "{names:?}");
    let mass = &s.world.particles().mass;
    for k in 0..3 {
        // Σ m (x − c) = 0 for the positions and for the velocities.
        let first = 4 + k * n;
        let moment: f64 = (0..n).map(|i| mass[i] * o[first + i]).sum();
        assert!(moment.abs() < 1e-12, "{}: {moment}", names[first]);
        let first = 4 + 3 * n + k * n;
        let moment: f64 = (0..n).map(|i| mass[i] * o[first + i]).sum();
        assert!(moment.abs() < 1e-12, "{}: {moment}", names[first]);
    }
    let centre = s.evolve.as_ref().unwrap().centre(&s.world);
    let all =
        animats_scene::evaluate::centre_of(&s.world, &s.world.particle_ids().collect::<Vec<_>>());
    assert!((o[0] - all.y).abs() < 1e-12, "{} vs {}", o[0], all.y);
    assert!(centre.is_finite());
    let spine = s.world.forces().springs.iter().next().unwrap();
    let (a, b) = spine.ends();
    let length = (s.world.position(a) - s.world.position(b)).length();
    assert_eq!(o[4 + 6 * n], length, "{}", names[4 + 6 * n]);
    // The walker stands on its four feet, not its hips.
    let contacts = &o[4 + 6 * n + springs..];
    assert_eq!(contacts.iter().sum::<f64>(), 4.0, "{contacts:?}");
    let bounds = env.observation_bounds();
    assert_eq!(bounds[0], (f64::NEG_INFINITY, f64::INFINITY));
    assert_eq!(bounds[o.len() - 1], (0.0, 1.0));
}

#[test]
fn an_action_may_last_the_whole_episode_but_no_longer() {
    let text = pogo(); // 5 s at the pogo's step
    let env = || SceneEnv::parse(&text, "pogo.toml", 0.0).unwrap();
    let steps = env().max_steps();
    // One action for the whole episode is an open-loop creature: allowed.
    let whole = env().with_actions(steps as u32, Observation::Both).unwrap();
    assert_eq!(whole.max_steps(), 1);
    let err = env()
        .with_actions(steps as u32 + 1, Observation::Both)
        .err()
        .expect("an action longer than the episode");
    assert!(
        err.contains(&format!("frame_skip {}", steps + 1)) && err.contains("5 s"),
        "{err}"
    );
    // act_hz: about 50 Hz is 1/(50 dt) steps; faster than the steps is
    // every step; one action in 10 s of a 5 s episode is refused, and so
    // is a rate whose steps overflow frame_skip.
    let dt = env().scene().dt;
    assert_eq!(
        env().frame_skip_for(50.0),
        Ok((1.0 / 50.0 / dt).round() as u32)
    );
    assert_eq!(env().frame_skip_for(1e9), Ok(1));
    assert_eq!(env().frame_skip_for(0.2), Ok(steps as u32));
    let err = env().frame_skip_for(0.1).unwrap_err();
    assert!(
        err.contains("act_hz 0.1 asks for an action every 10 s, longer than the episode (5 s)"),
        "{err}"
    );
    assert!(env().frame_skip_for(1e-300).is_err());
}
