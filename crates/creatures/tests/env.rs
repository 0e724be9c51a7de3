//! The roobot environment is its fitness evaluation with a program in the
//! FSM's place: replaying the levels the FSM chose step by step must give
//! the same trajectory, bit for bit, and rewards that add up to the
//! evaluation's fitness.

use animats_creatures::env::Env;
use animats_creatures::roobot::env::RoobotEnv;
use animats_creatures::roobot::evaluate::{evaluate_with, EvalSettings};
use animats_creatures::roobot::params_file;
use animats_creatures::vec_env::VecEnv;

/// The FSM's levels before each step, and the hip's position after it.
fn fsm_run(settings: &EvalSettings) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, f64, u64) {
    let params = params_file::load("evolved", None).expect("built-in parameters");
    let (mut levels, mut hips) = (Vec::new(), Vec::new());
    let mut first = true;
    let e = evaluate_with(params, settings, |w, r| {
        if first {
            first = false;
            return;
        }
        // Called after each step: the levels the step used.
        levels.push([r.leg.level(), r.hip.level(), r.ankle.level()]);
        hips.push(w.position(r.body.hip).to_array());
    })
    .expect("evaluation");
    let steps = (e.time_up / settings.dt).round() as u64;
    (levels, hips, e.fitness, steps)
}

#[test]
fn replaying_the_fsm_gives_its_trajectory_and_fitness() {
    let settings = EvalSettings::default();
    let (levels, hips, fitness, steps) = fsm_run(&settings);
    assert!(fitness > 2000.0, "the evolved gait's fitness: {fitness}");
    let mut env = RoobotEnv::new(settings, 0.0).unwrap();
    let mut total = 0.0;
    let mut ended_at = None;
    for (k, (a, hip)) in levels.iter().zip(&hips).enumerate() {
        let t = env.step(a).unwrap();
        total += t.reward;
        let got = env.world().position(env.roobot().body.hip).to_array();
        assert_eq!(&got, hip, "step {k}: the hip's position differs");
        if t.terminated || t.truncated {
            ended_at = Some((k + 1, t.truncated));
            break;
        }
    }
    // The evolved gait stays up 20 s: the episode is truncated at 2500 steps.
    assert_eq!(ended_at, Some((steps as usize, true)));
    // Rewards are differences of the fitness: their sum rounds differently.
    assert!(
        (total - fitness).abs() <= 1e-9 * fitness,
        "sum of rewards {total} against fitness {fitness}"
    );
    assert_eq!(env.fitness(), fitness);
    assert!(env.step(&levels[0]).is_err(), "stepping past the end");
}

#[test]
fn a_roobot_that_does_nothing_falls_and_the_episode_terminates() {
    let mut env = RoobotEnv::new(EvalSettings::default(), 0.0).unwrap();
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
fn a_vector_environment_is_the_same_bits_on_any_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let n = 300;
            let mut v =
                VecEnv::new(n, 7, |_| RoobotEnv::new(EvalSettings::default(), 0.05)).unwrap();
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
