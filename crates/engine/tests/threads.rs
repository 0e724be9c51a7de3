//! Results are the same bits whatever the number of threads (and whatever
//! the CPU's vector width): a world whose n-body force or springs are split
//! among threads ends in the same state on 1, 2 and 3 threads, and that
//! state's hash is pinned, so a change of the numerics shows up here first.

use animats_engine::{
    DVec3, FloorDef, IntegratorKind, NBodyGravity, ParticleDef, ParticleId, SpringDef, Targets,
    World,
};

/// 300 bodies of unequal masses (more than the gather's threshold for
/// threads) spread through a unit cube by the R3 sequence.
fn world(softening: f64) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Symplectic);
    let g = 1.220_744_084_505_759_6f64;
    for i in 0..300 {
        let c = |k: i32| {
            let x = 0.5 + (i + 1) as f64 / g.powi(k);
            x - x.floor() - 0.5
        };
        w.add_particle(ParticleDef::new(1.0 + (i % 7) as f64 / 7.0).at(DVec3::new(
            c(1),
            c(2),
            c(3),
        )))
        .unwrap();
    }
    w.add_nbody(NBodyGravity::new(1e-3, softening, Targets::All))
        .unwrap();
    w
}

/// FNV-1a over every position's and velocity's bits.
fn hash(w: &World) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for v in w.state().pos.iter().chain(&w.state().vel) {
        for x in v.to_array() {
            for b in x.to_bits().to_le_bytes() {
                h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    h
}

/// The hash of `world` after `steps` steps of 1 ms on `threads` threads.
fn run_world(threads: usize, world: impl FnOnce() -> World + Send, steps: usize) -> u64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = world();
        for _ in 0..steps {
            w.step(1e-3).unwrap();
        }
        hash(&w)
    })
}

fn run(threads: usize, softening: f64) -> u64 {
    run_world(threads, || world(softening), 50)
}

/// A 64 × 64 cloth (4,096 particles and 16,002 springs, as many as the
/// thresholds for threads: one thread adds each spring's force to its ends
/// in turn, several add to their own pieces and sum the shared particles at
/// the end) with damping, hung by two corners above a floor it falls onto,
/// its springs listed in mesh order (most particles belong to one thread) or
/// shuffled (most are shared).
fn cloth(kind: IntegratorKind, shuffle: bool) -> World {
    let n = 64;
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.81, 0.0));
    for i in 0..n {
        for j in 0..n {
            let x = DVec3::new(
                i as f64 * 0.02,
                0.05 + 0.01 * ((i * j) % 5) as f64,
                j as f64 * 0.02,
            );
            let mut p = ParticleDef::new(0.001 + 1e-5 * ((i + 2 * j) % 3) as f64).at(x);
            p.fixed = (i == 0 || i == n - 1) && j == 0;
            w.add_particle(p).unwrap();
        }
    }
    let mut edges = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let p = i * n + j;
            if j + 1 < n {
                edges.push((p, p + 1));
            }
            if i + 1 < n {
                edges.push((p + n, p));
            }
            if i + 1 < n && j + 1 < n {
                edges.push((p, p + n + 1));
            }
            if i + 1 < n && j > 0 {
                edges.push((p + n - 1, p));
            }
        }
    }
    // A fixed shuffle: some particles' springs listed together, most not.
    let k = edges.len();
    for i in (1..k).rev() {
        if shuffle && i % 4 != 0 {
            edges.swap(i, (i * 7919) % (i + 1));
        }
    }
    let id = ParticleId::from_index;
    for (a, b) in edges {
        w.add_spring(SpringDef::new(id(a), id(b), 100.0, 0.05))
            .unwrap();
    }
    w.add_floor(FloorDef::default()).unwrap();
    w
}

#[test]
fn a_mass_spring_world_is_the_same_bits_on_any_number_of_threads() {
    for kind in IntegratorKind::ALL {
        for shuffle in [false, true] {
            let one = run_world(1, || cloth(kind, shuffle), 100);
            let two = run_world(2, || cloth(kind, shuffle), 100);
            let three = run_world(3, || cloth(kind, shuffle), 100);
            assert_eq!(two, one, "2 threads, {kind}, shuffled {shuffle}");
            assert_eq!(three, one, "3 threads, {kind}, shuffled {shuffle}");
        }
    }
    // More threads than a piece has rows; still the same.
    let kind = IntegratorKind::Symplectic;
    assert_eq!(
        run_world(40, || cloth(kind, false), 20),
        run_world(1, || cloth(kind, false), 20)
    );
    let golden = run_world(2, || cloth(IntegratorKind::Symplectic, true), 100);
    assert_eq!(golden, CLOTH_GOLDEN, "{golden:#018x}");
}

/// `hash` of the symplectic cloth after 100 steps on 2 threads.
const CLOTH_GOLDEN: u64 = 0x5fda_9dc1_3f39_8401;

#[test]
fn an_n_body_world_is_the_same_bits_on_any_number_of_threads() {
    for softening in [0.01, 0.05] {
        let one = run(1, softening);
        assert_eq!(run(2, softening), one, "2 threads, softening {softening}");
        assert_eq!(run(3, softening), one, "3 threads, softening {softening}");
    }
    // The golden hash: the same on every CPU (AVX-512, AVX2 or neither).
    assert_eq!(run(2, 0.01), GOLDEN, "{:#018x}", run(2, 0.01));
}

/// `hash` after 50 steps on 2 threads, softening 0.01 (first measured on an
/// AVX-512 machine; the kernel test shows AVX2 and SSE2 give the same bits).
const GOLDEN: u64 = 0x550e_2088_816d_8ecb;
