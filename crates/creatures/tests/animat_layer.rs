//! Sensors and actuators do what their contracts say.
// std's transcendental functions: an independent reference here
#![allow(clippy::disallowed_methods)]

use animats_creatures::actuator::Actuator;
use animats_creatures::actuators::{ForceMagnitude, JointTorque, SpringRestLength};
use animats_creatures::sensor::Sensor;
use animats_creatures::sensors::{HeightSensor, SpeedSensor, TiltSensor, TouchdownSensor};
use animats_engine::{DVec3, ParticleDef, SpringDef, TorqueJointDef, World};
use std::f64::consts::TAU;

#[test]
fn height_sensor_reports_the_lowest_point_clamped_to_unit() {
    let mut w = World::new();
    let p = w
        .add_particle(
            ParticleDef::new(1.0)
                .with_radius(0.1)
                .at(DVec3::new(0.0, 0.35, 0.0)),
        )
        .unwrap();
    let s = HeightSensor { particle: p };
    assert!((s.level(&w) - 0.25).abs() < 1e-15);
    w.set_position(p, DVec3::new(0.0, 3.0, 0.0)).unwrap();
    assert_eq!(s.level(&w), 1.0);
    w.set_position(p, DVec3::new(0.0, 0.05, 0.0)).unwrap();
    assert_eq!(s.level(&w), 0.0);
}

#[test]
fn tilt_sensor_maps_the_lean_angle_linearly_around_one_half() {
    let mut w = World::new();
    let foot = w.add_particle(ParticleDef::new(1.0)).unwrap();
    let hip = w.add_particle(ParticleDef::new(1.0).at(DVec3::Y)).unwrap();
    let s = TiltSensor {
        base: foot,
        tip: hip,
        forward: DVec3::X,
        gain: 1.0 / TAU,
    };
    assert_eq!(s.level(&w), 0.5);
    // Hip 30° forward of the foot: level 0.5 + (π/6)/(2π) = 0.5 + 1/12.
    let a = std::f64::consts::PI / 6.0;
    w.set_position(hip, DVec3::new(a.sin(), a.cos(), 0.0))
        .unwrap();
    assert!((s.level(&w) - (0.5 + 1.0 / 12.0)).abs() < 1e-12);
    // Leaning backwards is below one half; sideways lean does not count.
    w.set_position(hip, DVec3::new(-a.sin(), a.cos(), 0.7))
        .unwrap();
    assert!((s.level(&w) - (0.5 - 1.0 / 12.0)).abs() < 1e-12);
}

#[test]
fn touchdown_sensor_is_the_ballistic_fall_time() {
    let mut w = World::new();
    // Foot 0.2 m up (lowest point), moving up at 1 m/s: t = (1 + sqrt(1 + 2·9.8·0.2)) / 9.8.
    let foot = w
        .add_particle(
            ParticleDef::new(0.1)
                .with_radius(0.03)
                .at(DVec3::new(0.0, 0.23, 0.0))
                .with_velocity(DVec3::Y),
        )
        .unwrap();
    let s = TouchdownSensor {
        height: HeightSensor { particle: foot },
        g: 9.8,
    };
    let expected = (1.0 + (1.0f64 + 2.0 * 9.8 * 0.2).sqrt()) / 9.8;
    assert!((s.level(&w) - expected).abs() < 1e-12);
    // And that is when a ballistic foot really lands (RK4 is exact for it).
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let steps = (expected / 1e-4).round() as usize;
    for _ in 0..steps {
        w.step(1e-4).unwrap();
    }
    assert!((w.position(foot).y - 0.03).abs() < 1e-4);
}

#[test]
fn speed_sensor_reads_forward_velocity() {
    let mut w = World::new();
    let p = w
        .add_particle(ParticleDef::new(1.0).with_velocity(DVec3::new(0.3, 5.0, 0.4)))
        .unwrap();
    let s = SpeedSensor {
        particle: p,
        forward: DVec3::new(0.6, 0.0, 0.8),
    };
    assert!((s.level(&w) - 0.5).abs() < 1e-15);
    let back = SpeedSensor {
        particle: p,
        forward: DVec3::new(-0.6, 0.0, -0.8),
    };
    assert_eq!(back.level(&w), 0.0);
}

#[test]
fn actuators_map_levels_onto_their_range_and_reset_to_the_initial_level() {
    let mut w = World::new();
    let a = w.add_particle(ParticleDef::new(1.0)).unwrap();
    let b = w
        .add_particle(ParticleDef::new(1.0).at(DVec3::new(0.4, 0.0, 0.0)))
        .unwrap();
    let spring = w.add_spring(SpringDef::new(a, b, 10.0, 0.0)).unwrap();
    let mut leg = Actuator::new(SpringRestLength(spring), 0.2, 0.6, &w);
    assert!(
        (leg.initial_level() - 0.5).abs() < 1e-12,
        "0.4 m is the middle of [0.2, 0.6]"
    );
    leg.set_level(&mut w, 0.25);
    assert!((w.forces().springs.get(spring).rest_length - 0.3).abs() < 1e-15);
    leg.set_level(&mut w, 7.0); // clamped
    assert_eq!(w.forces().springs.get(spring).rest_length, 0.6);
    leg.reset(&mut w);
    assert!((w.forces().springs.get(spring).rest_length - 0.4).abs() < 1e-12);

    let motor = w
        .add_torque_joint(TorqueJointDef {
            end: b,
            joint: a,
            axis: DVec3::Z,
            torque: 0.0,
        })
        .unwrap();
    let mut m = Actuator::new(JointTorque(motor), -2.0, 2.0, &w);
    assert_eq!(m.level(), 0.5);
    m.set_level(&mut w, 1.0);
    assert_eq!(w.forces().torque_joints.get(motor).torque, 2.0);
    m.set_level(&mut w, f64::NAN); // a NaN level is clamped, never passed on
    assert_eq!(w.forces().torque_joints.get(motor).torque, -2.0);

    let f = w.add_constant_force(vec![a], DVec3::ZERO).unwrap();
    let axis = DVec3::Y;
    let mut push = Actuator::new(ForceMagnitude { force: f, axis }, -4.0, 4.0, &w);
    assert_eq!(push.level(), 0.5, "a zero force is the middle of [-4, 4]");
    push.set_level(&mut w, 0.875);
    assert_eq!(
        w.forces().constant_forces.get(f).force,
        DVec3::new(0.0, 3.0, 0.0)
    );
    // Negative magnitudes point against the axis; turning the axis keeps the level.
    push.set_level(&mut w, 0.25);
    assert_eq!(
        w.forces().constant_forces.get(f).force,
        DVec3::new(0.0, -2.0, 0.0)
    );
    push.target_mut().axis = DVec3::X;
    push.reapply(&mut w);
    assert_eq!(
        w.forces().constant_forces.get(f).force,
        DVec3::new(-2.0, 0.0, 0.0)
    );
}
