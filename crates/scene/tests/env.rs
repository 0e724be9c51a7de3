//! A scene as an environment is its `[evolve]` evaluation with a program
//! in the controllers' place: replaying what the controller ordered gives
//! the same trajectory, bit for bit, and rewards that add up to the
//! evaluation's fitness.

use animats_creatures::env::Env;
use animats_scene::env::SceneEnv;
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
    let scene = animats_scene::parse(&pogo(), "pogo.toml").unwrap();
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
    assert!(e.distance.abs() > 0.0 && e.fitness > 0.0, "{e:?}");

    let mut env = SceneEnv::parse(&pogo(), "pogo.toml", 0.0).unwrap();
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
    assert_eq!(env.fitness(), e.fitness);
    assert!((total - e.fitness).abs() <= 1e-9 * e.fitness.abs().max(1.0));
    assert!(env.step(&orders[0]).is_err(), "stepping past the end");
}

#[test]
fn an_environment_needs_sensors_actuators_and_evolve() {
    let walker = include_str!("../../../scenes/walker.toml");
    let err = SceneEnv::parse(walker, "walker.toml", 0.0)
        .err()
        .expect("the walker has no sensors")
        .to_string();
    assert!(
        err.contains("walker.toml") && err.contains("[[sensor]]"),
        "{err}"
    );
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
