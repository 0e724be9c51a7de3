//! A mass changed after a particle was added (`World::set_mass`, or a
//! snapshot restored with other masses) moves the particle exactly as if it
//! had been made with that mass, under every integrator (the integrators
//! keep their own per-coordinate copy of the inverse masses).

use animats_engine::{DVec3, IntegratorKind, ParticleDef, SpringDef, World};

fn world(m: f64, kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let a = w.add_particle(ParticleDef::new(1.0).fixed()).unwrap();
    let b = w
        .add_particle(ParticleDef::new(m).at(DVec3::new(0.3, -0.1, 0.2)))
        .unwrap();
    w.add_spring(SpringDef::new(a, b, 40.0, 0.2)).unwrap();
    w
}

fn run(mut w: World) -> Vec<u64> {
    for _ in 0..500 {
        w.step(1e-3).unwrap();
    }
    let s = w.state();
    s.pos
        .iter()
        .chain(&s.vel)
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .collect()
}

#[test]
fn a_changed_mass_moves_the_particle_as_a_made_one() {
    for kind in IntegratorKind::ALL {
        let made = run(world(2.5, kind));
        let mut changed = world(0.5, kind);
        let b = changed.particle_ids().nth(1).unwrap();
        changed.set_mass(b, 2.5).unwrap();
        assert_eq!(run(changed), made, "{kind}: set_mass");
        // A snapshot of the heavy world restored into the light one.
        let mut light = world(0.5, kind);
        light.restore(&world(2.5, kind).snapshot()).unwrap();
        assert_eq!(run(light), made, "{kind}: restore");
        assert_ne!(run(world(0.5, kind)), made, "{kind}: the mass matters");
    }
}
