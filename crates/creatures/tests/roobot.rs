//! The roobot's hopping FSM on its own: its transitions and feedback laws
//! are Appendix B's. (The roobot in a scene, evaluated, evolved and driven
//! as an environment: `crates/scene/tests/roobot.rs`.)

use animats_creatures::roobot::{Command, HopFsm, HopParams, HopSenses as Senses, HopState};

#[test]
fn fsm_transitions_follow_appendix_b() {
    let p = HopParams::INITIAL;
    let s = |angle: f64, height: f64| Senses {
        height,
        angle,
        speed: 0.2,
        touchdown: 0.3,
        hip_velocity: 0.2,
    };
    let dt = 0.008;
    // (state, senses, leg level) → (next state, leg order)
    let table: [(HopState, Senses, f64, HopState); 8] = [
        (HopState::Stance, s(0.50, 0.0), 0.5, HopState::Stance), // angle below p1 = 0.55: keep compressing
        (HopState::Stance, s(0.56, 0.0), 0.5, HopState::Leap),   // passed p1
        (HopState::Leap, s(0.56, 0.0), 0.5, HopState::Leap),     // leg below p6 = 1.0: extend
        (HopState::Leap, s(0.56, 0.0), 1.0, HopState::Launch),   // reached p6
        (HopState::Launch, s(0.56, 0.01), 1.0, HopState::Launch), // foot below p9 = 0.02
        (HopState::Launch, s(0.56, 0.03), 0.9, HopState::Flight), // cleared p9
        (HopState::Flight, s(0.52, 0.10), 0.8, HopState::Flight),
        (HopState::Flight, s(0.52, 0.0), 0.4, HopState::Stance), // touched down
    ];
    for (from, senses, leg, to) in table {
        let mut fsm = HopFsm::new(p);
        // Drive the machine to `from` through its own transitions.
        let path = [
            HopState::Stance,
            HopState::Leap,
            HopState::Launch,
            HopState::Flight,
        ];
        let mut guard = 0;
        while fsm.state() != from {
            let drive = [s(0.9, 0.0), s(0.9, 0.0), s(0.9, 0.5), s(0.9, 0.0)];
            let i = path.iter().position(|x| *x == fsm.state()).unwrap();
            fsm.step(&drive[i], 1.0, dt);
            guard += 1;
            assert!(guard < 10);
        }
        let orders = fsm.step(&senses, leg, dt);
        assert_eq!(fsm.state(), to, "{from} with {senses:?}, leg {leg}");
        assert_eq!(fsm.last_transition().is_some(), from != to);
        if from == to {
            // Staying in a state always drives the leg, within [0, 1].
            match orders.leg {
                Command::Set(l) => assert!((0.0..=1.0).contains(&l)),
                other => panic!("{from}: leg order {other:?}"),
            }
        }
    }
}

#[test]
fn fsm_feedback_laws_match_appendix_b() {
    let p = HopParams::INITIAL.0;
    let mut fsm = HopFsm::new(HopParams::INITIAL);
    let dt = 0.008;
    let senses = Senses {
        height: 0.0,
        angle: 0.52,
        speed: 0.1,
        touchdown: 0.0,
        hip_velocity: 0.1,
    };
    let o = fsm.step(&senses, 0.6, dt);
    let rate = p[3] * (0.6 - p[0]) / (p[1] - 0.52);
    assert_eq!(o.leg, Command::Set(p[0].max(0.6 - rate * dt)));
    assert_eq!(
        o.ankle,
        Command::Set(0.5 + p[4] * (p[1] - 0.52) + p[5] * (p[2] - 0.1))
    );
    assert_eq!(o.hip, Command::Reset);
}
