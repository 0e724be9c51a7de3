//! Richer fitness (issue 43): the actuators' positive work against closed
//! forms, a target, noisy trials and measure terms.

use animats_scene::evaluate::{evaluate, perturb, score, Evaluation};

fn parse(text: &str) -> animats_scene::Scene {
    animats_scene::parse(text, "f.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn scored(text: &str) -> Evaluation {
    score(|| animats_scene::parse(text, "f.toml").map_err(|e| e.to_string())).unwrap()
}

/// Two nailed particles 0.3 m apart joined by a 100 N/m muscle whose rest
/// length an oscillator swings over [0.1, 0.2] m at 1 Hz.
fn muscle(evolve: &str) -> String {
    format!(
        "[world]\ndt = 0.001\ngravity = [0, 0, 0]\n\n\
         [[particle]]\nname = \"a\"\nmass = 1.0\nposition = [0, 0, 0]\nradius = 0.01\nfixed = true\n\n\
         [[particle]]\nname = \"b\"\nmass = 1.0\nposition = [0.3, 0, 0]\nradius = 0.01\nfixed = true\n\n\
         [[spring]]\nname = \"m\"\na = \"a\"\nb = \"b\"\nstiffness = 100.0\nrest_length = 0.15\n\n\
         [[actuator]]\nname = \"m\"\nspring = \"m\"\nmin = 0.1\nmax = 0.2\n\n\
         [[controller]]\nname = \"osc\"\nkind = \"oscillator\"\noutputs = [\"m\"]\nfrequency = 1.0\n\
         amplitude = [0.5]\nphase = [0.0]\noffset = [0.5]\n\n\
         [evolve]\ncontroller = \"osc\"\nduration = 3.0\n{evolve}\n"
    )
}

#[test]
fn a_muscles_positive_work_is_what_it_puts_into_its_spring() {
    // The ends are nailed: l = 0.3 m throughout, and the spring stores
    // ½ k (l − r)². Each shortening of the rest length from 0.2 to 0.1 m
    // puts in ½ k [(0.3 − 0.1)² − (0.3 − 0.2)²] = 1.5 J; each lengthening
    // takes it back, which does not count. Three periods: 4.5 J.
    let e = scored(&muscle("energy_weight = 2.0"));
    let energy = e.energy.unwrap();
    println!("work {energy} J, fitness {}", e.fitness);
    // The level is sampled once a step: the turning points are met within
    // a step (2π·1 Hz·1 ms of phase), which misses (1 − cos) of a swing.
    assert!((energy - 4.5).abs() < 1e-4, "{energy}");
    // fitness = time_weight × 3 s + 0 m − 2 × work.
    assert!(
        (e.fitness - (3.0 - 2.0 * energy)).abs() < 1e-12,
        "{}",
        e.fitness
    );
    // Without a weight nothing is summed.
    assert_eq!(scored(&muscle("")).energy, None);
}

#[test]
fn a_motors_work_is_the_kinetic_energy_it_gives() {
    // A 2 N m motor spins a 0.5 kg mass on a 0.2 m arm round a nailed hub
    // (held at 0.2 m by a stiff spring), no gravity: its positive work is
    // the kinetic energy the mass has gained, to the integrator's error.
    let text = "[world]\ndt = 0.0001\ngravity = [0, 0, 0]\nintegrator = \"rk4\"\n\n\
         [[particle]]\nname = \"hub\"\nmass = 1.0\nposition = [0, 0, 0]\nradius = 0.01\nfixed = true\n\n\
         [[particle]]\nname = \"m\"\nmass = 0.5\nposition = [0.2, 0, 0]\nradius = 0.01\n\n\
         [[spring]]\na = \"hub\"\nb = \"m\"\nstiffness = 100000.0\ndamping = 0.0\n\n\
         [[torque_joint]]\nname = \"motor\"\nend = \"m\"\njoint = \"hub\"\naxis = [0, 0, 1]\n\n\
         [[actuator]]\nname = \"drive\"\ntorque_joint = \"motor\"\nmin = 0.0\nmax = 4.0\nlevel = 0.5\n\n\
         [evolve]\nduration = 0.5\nenergy_weight = 1.0\n";
    let e = scored(text);
    let mut s = parse(text);
    let before = s.world.energy().total();
    for _ in 0..5000 {
        s.step(s.dt).unwrap();
    }
    // The mechanical energy it has gained: the mass's kinetic energy and
    // the spring's, stretched 2.5 mm by the 250 N the turn needs.
    let gained = s.world.energy().total() - before;
    let energy = e.energy.unwrap();
    println!("motor work {energy} J, mechanical energy gained {gained} J");
    // τ t / (m r) = 2·0.5/(0.5·0.2) = 10 m/s: about 25 J.
    assert!((gained - 25.0).abs() < 1.0, "{gained}");
    // The trapezoidal sum of τ ω h against RK4's exact-to-h⁴ energy.
    assert!(
        (energy - gained).abs() < 1e-4 * gained,
        "{energy} vs {gained}"
    );
}

#[test]
fn a_target_costs_its_weight_per_metre_of_the_final_distance() {
    let text = "[world]\ndt = 0.001\n\n[floor]\n\n\
         [[particle]]\nname = \"ball\"\nmass = 1.0\nradius = 0.05\nposition = [1, 0.05, 0]\n\n\
         [evolve]\nduration = 1.0\ntarget = [4, 0.05, 4]\ntarget_weight = 3.0\n";
    let e = scored(text);
    // It rests where it stands: 5 m from the target (3-4-5).
    assert!((e.target_distance.unwrap() - 5.0).abs() < 1e-12);
    assert!(
        (e.fitness - (1.0 - 3.0 * 5.0)).abs() < 1e-9,
        "{}",
        e.fitness
    );
}

/// A walker whose start and muscles vary by trial.
fn walker(evolve: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/walker_evolved.toml"
    ))
    .unwrap();
    let text = text.replace("duration = 10.0\nparticles", "duration = 2.0\nparticles");
    text.replace("[evolve]\n", &format!("[evolve]\n{evolve}\n"))
}

#[test]
fn trials_score_their_mean_or_their_worst_and_repeat_to_the_bit() {
    let plain = scored(&walker(""));
    // Noise 0: every trial is the plain run.
    let same = scored(&walker("trials = 3"));
    assert_eq!(same, plain);
    // Noisy trials, each its own perturbation of the start and the muscles.
    let text = walker("trials = 4\nnoise = 0.2");
    let each: Vec<Evaluation> = (0..4)
        .map(|k| {
            let mut s = parse(&text);
            perturb(&mut s, k).unwrap();
            evaluate(s).unwrap()
        })
        .collect();
    let fitness: Vec<f64> = each.iter().map(|e| e.fitness).collect();
    println!("plain {}, trials {fitness:?}", plain.fitness);
    assert!(fitness.windows(2).all(|w| w[0] != w[1]), "{fitness:?}");
    let mean = scored(&text);
    let sum: f64 = fitness.iter().sum();
    assert_eq!(mean.fitness, sum / 4.0);
    let worst = scored(&walker("trials = 4\nnoise = 0.2\naggregate = \"worst\""));
    let lowest = fitness.iter().cloned().fold(f64::INFINITY, f64::min);
    assert_eq!(worst.fitness, lowest);
    // Again, the same bits; another scene seed, other trials.
    assert_eq!(scored(&text), mean);
    let reseeded = text.replace("[world]\n", "[world]\nseed = 99\n");
    assert_ne!(scored(&reseeded).fitness, mean.fitness);
}

#[test]
fn terms_add_their_measures_times_their_weights() {
    let text = walker(
        "terms = [{ kind = \"mean_height\", weight = 100.0 }, { kind = \"feet\", weight = -2.0 }]",
    );
    let plain = scored(&walker(""));
    let e = scored(&text);
    println!("terms {:?}", e.terms);
    assert_eq!(e.terms.len(), 2);
    // The walker stands: its hips' centre averages 0.1–0.2 m, 2–4 feet down.
    assert!(e.terms[0] > 0.05 && e.terms[0] < 0.25, "{:?}", e.terms);
    assert!(e.terms[1] >= 1.0 && e.terms[1] <= 4.0, "{:?}", e.terms);
    let expected = plain.fitness + 100.0 * e.terms[0] - 2.0 * e.terms[1];
    assert!(
        (e.fitness - expected).abs() < 1e-9,
        "{} vs {expected}",
        e.fitness
    );
}

#[test]
fn bad_fitness_keys_are_named() {
    let bad = |evolve: &str, expect: &str| {
        let text = muscle(evolve);
        let e = match animats_scene::parse(&text, "f.toml") {
            Ok(_) => panic!("accepted {evolve}"),
            Err(e) => e.to_string(),
        };
        println!("{e}");
        assert!(e.contains(expect), "{evolve}: {e}");
    };
    bad("trials = 0", "evolve.trials: must be between 1 and 1000");
    bad("noise = 2.0", "evolve.noise");
    bad("target_weight = 2.0", "evolve.target_weight");
    bad("aggregate = \"median\"", "unknown variant `median`");
    bad(
        "terms = [{ kind = \"feet\" }]",
        "evolve.terms[0]: missing field `weight`",
    );
    bad(
        "terms = [{ kind = \"zest\", weight = 1 }]",
        "evolve.terms[0]",
    );
    bad("energy_weight = nan", "evolve.energy_weight");
    // A weight of 1e308 once overflowed every fitness to infinity.
    bad(
        "time_weight = 1e308",
        "evolve.time_weight: must be between -1e12 and 1e12, got 1e308",
    );
    bad(
        "distance_weight = -2e12",
        "evolve.distance_weight: must be between",
    );
    bad(
        "energy_weight = 1e13",
        "evolve.energy_weight: must be between",
    );
    bad(
        "target = [0, 0, 0]\ntarget_weight = 1e300",
        "evolve.target_weight: must be between",
    );
    bad(
        "terms = [{ kind = \"mean_height\", weight = 1e200 }]",
        "evolve.terms[0].weight: must be between",
    );
    bad("robust_halvings = 2", "evolve.robust_halvings: halves the step of a robust evaluation (2 given): set `robust = true` too");
    bad(
        "robust = true\nrobust_halvings = 0",
        "evolve.robust_halvings: must be between 1",
    );
    bad(
        "robust = true\nrobust_halvings = 5",
        "evolve.robust_halvings: must be between 1 (the step and half of it) and 4, got 5",
    );
    bad(
        "robust = true\nrobust_halvings = -1",
        "evolve.robust_halvings",
    );
}

#[test]
fn of_several_genomes_that_fail_to_build_the_first_is_reported() {
    // Genome 1 fails slowly, genome 6 at once: on two threads genome 6's
    // failure comes first in time, but the report names genome 1, as one
    // thread would.
    use animats_scene::evaluate::{engine_runs, score_all, Make};
    let text = muscle("");
    let builds: Vec<Box<Make<'_>>> = (0..8)
        .map(|g| -> Box<Make<'_>> {
            let text = text.clone();
            Box::new(move || match g {
                1 => {
                    std::thread::sleep(std::time::Duration::from_millis(200));
                    Err("genome 1 cannot be built".to_string())
                }
                6 => Err("genome 6 cannot be built".to_string()),
                _ => animats_scene::parse(&text, "f.toml").map_err(|e| e.to_string()),
            })
        })
        .collect();
    let makes: Vec<&Make<'_>> = builds.iter().map(|b| b.as_ref()).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for _ in 0..3 {
        let got = pool.install(|| score_all(&makes, &|_, _| true, &engine_runs));
        assert_eq!(got.unwrap_err(), "genome 1 cannot be built");
    }
}

/// The check a winner must pass (`check_finer`): a quarter of the step
/// with another integrator, scored as `evaluate` scores the scene written
/// that way; implicit Euler is kept.
#[test]
fn the_finer_check_is_the_scene_at_a_quarter_step_with_another_integrator() {
    use animats_engine::IntegratorKind;
    use animats_scene::evaluate::check_finer;
    // The muscle's scene is on RK4 at 1 ms: symplectic Euler at 0.25 ms.
    let text = muscle("energy_weight = 2.0");
    let (kind, dt, e) = check_finer(parse(&text)).unwrap();
    assert_eq!((kind, dt), (IntegratorKind::Symplectic, 0.00025));
    let written = text.replace(
        "dt = 0.001\n",
        "dt = 0.00025\nintegrator = \"symplectic\"\n",
    );
    let want = evaluate(parse(&written)).unwrap();
    assert_eq!(e.fitness.to_bits(), want.fitness.to_bits());
    // Not the scene's own run: its work is summed at other steps.
    assert_ne!(
        e.fitness.to_bits(),
        evaluate(parse(&text)).unwrap().fitness.to_bits()
    );
    // Symplectic Euler goes to RK4, implicit Euler stays.
    for (from, to) in [
        ("symplectic", IntegratorKind::Rk4),
        ("implicit", IntegratorKind::Implicit),
    ] {
        let t = text.replace(
            "dt = 0.001\n",
            &format!("dt = 0.001\nintegrator = \"{from}\"\n"),
        );
        assert_eq!(check_finer(parse(&t)).unwrap().0, to);
    }
}

/// Both checks (`checks_finer`): a quarter of the step with the scene's
/// own integrator, then with another, each as `evaluate` scores the scene
/// written that way; one run for implicit Euler.
#[test]
fn both_finer_checks_are_the_scene_at_a_quarter_step_with_its_own_integrator_and_another() {
    use animats_engine::IntegratorKind;
    use animats_scene::evaluate::checks_finer;
    let text = muscle("energy_weight = 2.0");
    let runs = checks_finer(|| Ok(parse(&text))).unwrap();
    let kinds: Vec<_> = runs.iter().map(|r| (r.0, r.1)).collect();
    assert_eq!(
        kinds,
        [
            (IntegratorKind::Rk4, 0.00025),
            (IntegratorKind::Symplectic, 0.00025)
        ]
    );
    let own = evaluate(parse(&text.replace("dt = 0.001\n", "dt = 0.00025\n"))).unwrap();
    assert_eq!(runs[0].2.fitness.to_bits(), own.fitness.to_bits());
    let (_, _, other) = animats_scene::evaluate::check_finer(parse(&text)).unwrap();
    assert_eq!(runs[1].2.fitness.to_bits(), other.fitness.to_bits());
    // Not the scene's own run: its work is summed at other steps.
    assert_ne!(
        runs[0].2.fitness.to_bits(),
        evaluate(parse(&text)).unwrap().fitness.to_bits()
    );
    let implicit = text.replace("dt = 0.001\n", "dt = 0.001\nintegrator = \"implicit\"\n");
    let runs = checks_finer(|| Ok(parse(&implicit))).unwrap();
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0].0, IntegratorKind::Implicit);
}

/// An evaluation under `stoppable` ends within 256 steps once its question
/// says stop (Python's Ctrl-C during one long evaluation), and one not
/// stopped is the same bits as without: the muscle for a simulated day
/// (86.4 M steps) is stopped 50 ms in by a flag another thread sets; a
/// flag set before it begins stops it at once; outside `stoppable` the
/// flag is not heard.
#[test]
fn a_stopped_evaluation_ends_within_it_and_an_unstopped_one_is_the_same_bits() {
    use animats_scene::evaluate::{stoppable, INTERRUPTED};
    use std::rc::Rc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let plain = evaluate(parse(&muscle(""))).unwrap();
    let flag = Arc::new(AtomicBool::new(false));
    let asks = |flag: &Arc<AtomicBool>| -> Rc<dyn Fn() -> bool> {
        let flag = flag.clone();
        Rc::new(move || flag.load(Ordering::Relaxed))
    };
    let heard = stoppable(asks(&flag), || evaluate(parse(&muscle("")))).unwrap();
    assert_eq!(heard.fitness.to_bits(), plain.fitness.to_bits());
    assert_eq!(heard.energy, plain.energy);
    let day = muscle("").replace("duration = 3.0", "duration = 86400.0");
    let setter = {
        let flag = flag.clone();
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(50));
            flag.store(true, Ordering::Relaxed);
        })
    };
    let began = std::time::Instant::now();
    let e = stoppable(asks(&flag), || evaluate(parse(&day))).unwrap_err();
    setter.join().unwrap();
    let took = began.elapsed().as_secs_f64();
    println!("stopped after {took:.3} s");
    assert_eq!(e, INTERRUPTED);
    assert!(took < 5.0, "took {took} s to stop");
    // Set before it begins: not one step.
    assert_eq!(
        stoppable(asks(&flag), || evaluate(parse(&muscle("")))).unwrap_err(),
        INTERRUPTED
    );
    // Outside `stoppable` (and after it) the flag is no one's.
    let after = evaluate(parse(&muscle(""))).unwrap();
    assert_eq!(after.fitness.to_bits(), plain.fitness.to_bits());
}
