//! Determinism: a fixed world per integrator ends in a pinned state (a hash
//! of every bit of it), a cloned world and a world restored from a snapshot
//! continue bit for bit as the original, and time and state always agree.
//! As Box2D's `test_determinism.c` and Rapier's snapshot round-trip do: a
//! change that alters any result by one bit shows here, deliberately.

use animats_engine::{
    AngleJointDef, Current, FloorDef, FluidMedium, IntegratorKind, ParticleDef, ReefWater,
    SpringDef, TorqueJointDef, World,
};
use glam::DVec3;

/// A little of everything: a swinging, bouncing chain with springs, angle
/// joints, a motor and a push, in water with a reef current, over the floor.
fn world(kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let nail = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.0, 0.3, 0.0)).fixed())
        .unwrap();
    let mut chain = vec![nail];
    for i in 1..8 {
        let p = w
            .add_particle(
                ParticleDef::new(0.05 + 0.01 * i as f64)
                    .with_radius(0.02)
                    .with_restitution(0.4)
                    .at(DVec3::new(
                        0.07 * i as f64,
                        0.3 + 0.01 * i as f64,
                        0.01 * i as f64,
                    )),
            )
            .unwrap();
        w.add_spring(SpringDef::new(chain[i - 1], p, 80.0, 0.05))
            .unwrap();
        chain.push(p);
    }
    for i in 1..7 {
        w.add_angle_joint(AngleJointDef::new(
            chain[i - 1],
            chain[i],
            chain[i + 1],
            0.05,
            0.001,
        ))
        .unwrap();
    }
    w.add_torque_joint(TorqueJointDef {
        end: chain[7],
        joint: chain[6],
        axis: DVec3::Z,
        torque: 0.02,
    })
    .unwrap();
    w.add_constant_force(vec![chain[4]], DVec3::new(0.1, 0.0, -0.05))
        .unwrap();
    w.add_fluid(FluidMedium {
        current: Current::Reef(ReefWater::default()),
        ..FluidMedium::water()
    })
    .unwrap();
    w.add_floor(FloorDef {
        envelope: 1e-4,
        ..FloorDef::default()
    })
    .unwrap();
    w
}

/// FNV-1a over every bit of the clock, positions and velocities.
fn hash(w: &World) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |x: f64| {
        for b in x.to_bits().to_le_bytes() {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    };
    eat(w.time());
    for (p, v) in w.state().pos.iter().zip(&w.state().vel) {
        for x in p.to_array().into_iter().chain(v.to_array()) {
            eat(x);
        }
    }
    h
}

const DT: f64 = 0.002;
const STEPS: usize = 1500;

fn run(w: &mut World, steps: usize) {
    for _ in 0..steps {
        w.step(DT).unwrap();
    }
}

#[test]
fn each_integrator_ends_in_its_pinned_state() {
    // Pinned from this code on x86-64 (f64, no fast-math, libm for the
    // transcendental functions, so the same on every platform).
    let golden = [
        (IntegratorKind::Euler, 0x3fe8_fcd2_985a_3dcau64),
        (IntegratorKind::Midpoint, 0xb3b1_ef03_1dc0_4e2b),
        (IntegratorKind::Rk4, 0xe110_08ad_a8d8_5541),
        (IntegratorKind::Symplectic, 0x64ca_95da_8c7e_e742),
    ];
    let mut report = Vec::new();
    let mut wrong = false;
    for (kind, want) in golden {
        let mut w = world(kind);
        run(&mut w, STEPS);
        let got = hash(&w);
        report.push(format!(
            "{kind}: {got:#018x}, pinned {want:#018x} (backtracks {})",
            w.stats().backtracks
        ));
        assert!(
            w.stats().backtracks > 0,
            "{kind}: the floor never backtracked"
        );
        wrong |= got != want;
    }
    println!("{}", report.join("\n"));
    assert!(!wrong, "{}", report.join("\n"));
}

#[test]
fn a_clone_and_a_restored_snapshot_continue_bit_for_bit() {
    for kind in IntegratorKind::ALL {
        let mut original = world(kind);
        run(&mut original, STEPS / 2);
        let mut copy = original.clone();
        let json = serde_json::to_string(&original.snapshot()).unwrap();
        // Into a world built the same way, that has run differently since.
        let mut restored = world(kind);
        run(&mut restored, 10);
        restored
            .restore(&serde_json::from_str(&json).unwrap())
            .unwrap();
        run(&mut original, STEPS / 2);
        run(&mut copy, STEPS / 2);
        run(&mut restored, STEPS / 2);
        assert_eq!(hash(&copy), hash(&original), "{kind}: clone");
        assert_eq!(hash(&restored), hash(&original), "{kind}: restored");
        assert_eq!(restored.stats(), original.stats());
    }
}

#[test]
fn a_snapshot_of_another_world_is_refused_and_changes_nothing() {
    let mut w = world(IntegratorKind::Rk4);
    run(&mut w, 10);
    let before = hash(&w);
    let mut other = World::new();
    other
        .add_particle(ParticleDef::new(1.0).with_radius(0.1))
        .unwrap();
    let err = w.restore(&other.snapshot()).unwrap_err();
    assert!(err.to_string().contains("another world"), "{err}");
    let mut bad = w.snapshot();
    bad.masses[3] = -1.0;
    assert!(w.restore(&bad).is_err());
    bad = w.snapshot();
    bad.positions[2][1] = f64::NAN;
    assert!(w.restore(&bad).is_err());
    assert_eq!(hash(&w), before);
}

#[test]
fn a_restored_snapshot_keeps_each_radius_to_the_bit() {
    // A radius given with a particle is not the cube root of its volume
    // to the last bit (0.024586… from `scenes/bodies_walk_evolved.toml`):
    // a restore that made each radius again from its volume moved a foot's
    // contact with the floor, and the restored run parted from the
    // original 180 steps on.
    let r = 0.024_586_280_027_645_36;
    let mut w = World::new();
    let p = w
        .add_particle(ParticleDef::new(0.1).with_radius(r))
        .unwrap();
    let back = animats_engine::particle::sphere_radius(w.particles().volume[p.index()]);
    assert_ne!(
        back.to_bits(),
        r.to_bits(),
        "this radius must not round-trip"
    );
    let json = serde_json::to_string(&w.snapshot()).unwrap();
    w.set_volume(p, 1e-6).unwrap();
    w.restore(&serde_json::from_str(&json).unwrap()).unwrap();
    assert_eq!(w.particles().radius[p.index()].to_bits(), r.to_bits());
    // A snapshot written before radii were held: each follows its volume.
    let mut old: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(old.as_object_mut().unwrap().remove("radii").is_some());
    w.restore(&serde_json::from_value(old).unwrap()).unwrap();
    assert_eq!(w.particles().radius[p.index()].to_bits(), back.to_bits());
    // Radii that do not fit are refused.
    let mut bad = w.snapshot();
    bad.radii = vec![r, r];
    assert!(w.restore(&bad).unwrap_err().to_string().contains("radii"));
    bad.radii = vec![f64::NAN];
    assert!(w.restore(&bad).is_err());
}
