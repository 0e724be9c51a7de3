//! Results are the same bits whatever the number of threads (and whatever
//! the CPU's vector width): a world whose n-body force or springs are split
//! among threads ends in the same state on 1, 2 and 3 threads, and that
//! state's hash is pinned, so a change of the numerics shows up here first.

use animats_engine::{
    ByPieces, DVec3, DiscreteEvent, EventContext, EventState, FloorCollision, FloorDef,
    IntegratorKind, NBodyGravity, ParticleDef, ParticleId, Properties, SimError, SphereContactDef,
    SpringDef, Targets, TrialPiece, World,
};
use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

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
    let mut w = bare_cloth(kind, shuffle);
    w.add_floor(FloorDef::default()).unwrap();
    w
}

/// [`cloth`] without its floor.
fn bare_cloth(kind: IntegratorKind, shuffle: bool) -> World {
    cloth_of(kind, shuffle, false)
}

/// [`cloth`] with its springs listed as a mesh lists them, each from a
/// particle to later ones (summed as families of springs).
fn mesh_cloth(kind: IntegratorKind, floor: bool) -> World {
    let mut w = cloth_of(kind, false, true);
    if floor {
        w.add_floor(FloorDef::default()).unwrap();
    }
    w
}

/// The cloth, its springs in mesh order or `shuffle`d; `forward`: every
/// spring from its earlier particle to its later one.
fn cloth_of(kind: IntegratorKind, shuffle: bool, forward: bool) -> World {
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
            let turn = |a, b| if forward { (b, a) } else { (a, b) };
            if i + 1 < n {
                edges.push(turn(p + n, p));
            }
            if i + 1 < n && j + 1 < n {
                edges.push((p, p + n + 1));
            }
            if i + 1 < n && j > 0 {
                edges.push(turn(p + n - 1, p));
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
    // Without the floor's contact force, each thread adds its springs and
    // updates each run of its particles as soon as their forces are
    // complete (symplectic Euler), the shared ones after the join.
    let kind = IntegratorKind::Symplectic;
    for shuffle in [false, true] {
        let one = run_world(1, || bare_cloth(kind, shuffle), 100);
        for threads in [2, 3] {
            let many = run_world(threads, || bare_cloth(kind, shuffle), 100);
            assert_eq!(many, one, "no floor, {threads} threads, shuffled {shuffle}");
        }
    }
    // More threads than a piece has rows; still the same.
    for world in [cloth, bare_cloth] {
        assert_eq!(
            run_world(40, || world(kind, false), 20),
            run_world(1, || world(kind, false), 20)
        );
    }
    // Listed as a mesh lists them: summed as families, each thread its
    // own run of particles (and the springs reaching into it).
    for kind in IntegratorKind::ALL {
        for floor in [false, true] {
            let one = run_world(1, || mesh_cloth(kind, floor), 50);
            for threads in [2, 3, 40] {
                let many = run_world(threads, || mesh_cloth(kind, floor), 50);
                assert_eq!(
                    many, one,
                    "mesh order, {kind}, floor {floor}, {threads} threads"
                );
            }
        }
    }
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

/// `hash` after 50 steps on 2 threads, softening 0.01, since the n-body
/// force visits each pair once (measured on an Intel Xeon, where its kernel
/// runs AVX2; the kernel's test shows AVX-512, AVX2 and SSE2 give the same
/// bits).
const GOLDEN: u64 = 0x15e1_de14_aec2_b678;

/// Pieces handled by every [`Clamp`] so far.
static PIECES_HANDLED: AtomicUsize = AtomicUsize::new(0);
/// Pieces settled by every [`Clamp`] so far.
static PIECES_SETTLED: AtomicUsize = AtomicUsize::new(0);

/// The peer kit's floor rule at a height (`if y < h { if v_y < 0 { v_y ←
/// −e v_y }; y ← h }`), a user event written for one thread only, or also
/// piece by piece, or settling pieces; a particle more than `envelope`
/// below the height is missed.
#[derive(Clone)]
struct Clamp {
    height: f64,
    envelope: f64,
    mode: Mode,
    below: Vec<usize>,
}

/// How a [`Clamp`] answers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Whole,
    Pieces,
    Settles,
}

impl Clamp {
    fn new(height: f64, mode: Mode) -> Self {
        Clamp {
            height,
            envelope: f64::INFINITY,
            mode,
            below: Vec::new(),
        }
    }

    fn below(&self, x: DVec3, w: f64) -> bool {
        x.y < self.height && w != 0.0
    }

    /// Occurring, or missed if any of the particles below is too deep.
    fn state(&self, deepest: Option<f64>) -> EventState {
        match deepest {
            None => EventState::None,
            Some(y) if y < self.height - self.envelope => EventState::Missed,
            Some(_) => EventState::Occurring,
        }
    }

    fn bounce(&self, x: &mut DVec3, v: &mut DVec3, e: f64) {
        if v.y < 0.0 {
            v.y *= -e;
        }
        x.y = self.height;
    }
}

impl DiscreteEvent for Clamp {
    fn check(&mut self, ctx: &EventContext) -> EventState {
        self.below = (0..ctx.pos.len())
            .filter(|&i| self.below(ctx.pos[i], ctx.particles.inv_mass[i]))
            .collect();
        let deepest = self.below.iter().map(|&i| ctx.pos[i].y).reduce(f64::min);
        self.state(deepest)
    }

    fn handle(&mut self, _t: f64, pos: &mut [DVec3], vel: &mut [DVec3], p: &Properties) {
        for &i in &self.below {
            self.bounce(&mut pos[i], &mut vel[i], p.restitution[i]);
        }
    }

    fn by_pieces(&self) -> Option<&dyn ByPieces> {
        Some(self)
    }
}

impl ByPieces for Clamp {
    fn check_piece(&self, ctx: &EventContext, range: Range<usize>) -> Option<EventState> {
        let deepest = range
            .filter(|&i| self.below(ctx.pos[i], ctx.particles.inv_mass[i]))
            .map(|i| ctx.pos[i].y)
            .reduce(f64::min);
        (self.mode == Mode::Pieces).then_some(self.state(deepest))
    }

    fn handles_pieces(&self) -> bool {
        self.mode == Mode::Pieces
    }

    fn settles_pieces(&self) -> bool {
        self.mode == Mode::Settles
    }

    fn settle_piece(&self, piece: &mut TrialPiece) -> EventState {
        PIECES_SETTLED.fetch_add(1, Ordering::Relaxed);
        let p = piece.particles;
        let w = |i: usize| p.inv_mass[piece.first + i];
        let deepest = (0..piece.pos.len())
            .filter(|&i| self.below(piece.pos[i], w(i)))
            .map(|i| piece.pos[i].y)
            .reduce(f64::min);
        let state = self.state(deepest);
        if state == EventState::Occurring || piece.finest {
            for (i, (x, v)) in piece.pos.iter_mut().zip(piece.vel.iter_mut()).enumerate() {
                if self.below(*x, w(i)) {
                    self.bounce(x, v, p.restitution[piece.first + i]);
                }
            }
        }
        state
    }

    fn handle_piece(
        &self,
        _t: f64,
        first: usize,
        pos: &mut [DVec3],
        vel: &mut [DVec3],
        p: &Properties,
    ) {
        PIECES_HANDLED.fetch_add(1, Ordering::Relaxed);
        for (i, (x, v)) in pos.iter_mut().zip(vel.iter_mut()).enumerate() {
            if self.below(*x, p.inv_mass[first + i]) {
                self.bounce(x, v, p.restitution[first + i]);
            }
        }
    }
}

/// A large world checks and handles events piece by piece on many threads
/// where they allow it, and on one thread where any does not (the engine's
/// floor keeps records of its bounces): the same bits either way, and as on
/// one thread.
#[test]
fn events_checked_and_handled_by_pieces_are_the_same_bits() {
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        // Above the floor, the clamp alone catches the cloth; at the
        // floor's height both act, the floor bouncing first.
        for (floor, height, steps) in [(false, 0.04, 100), (true, 0.0, 150)] {
            let world = |by_pieces: bool| {
                move || {
                    let mut w = if floor {
                        cloth(kind, true)
                    } else {
                        bare_cloth(kind, true)
                    };
                    let mode = if by_pieces { Mode::Pieces } else { Mode::Whole };
                    w.add_event(Box::new(Clamp::new(height, mode)));
                    w
                }
            };
            let one = run_world(1, world(false), steps);
            let handled = PIECES_HANDLED.load(Ordering::Relaxed);
            for threads in [2, 3] {
                let why = format!("{kind}, {threads} threads, floor {floor}");
                assert_eq!(run_world(threads, world(true), steps), one, "{why}");
                assert_eq!(run_world(threads, world(false), steps), one, "{why}");
            }
            if floor {
                // The floor did bounce particles.
                let mut w = world(true)();
                let mut bounces = 0;
                for _ in 0..steps {
                    w.step(1e-3).unwrap();
                    bounces += w.event::<FloorCollision>().unwrap().collisions().len();
                }
                assert!(bounces > 10, "{bounces} bounces");
            } else {
                // The pieces were handled apart (this test alone uses the
                // counter).
                assert!(PIECES_HANDLED.load(Ordering::Relaxed) > handled);
            }
        }
    }
    // The clamp did act: particles rest on it, none below.
    let mut w = bare_cloth(IntegratorKind::Symplectic, true);
    w.add_event(Box::new(Clamp::new(0.04, Mode::Pieces)));
    for _ in 0..100 {
        w.step(1e-3).unwrap();
    }
    let on = w.state().pos.iter().filter(|x| x.y == 0.04).count();
    let under = w.state().pos.iter().filter(|x| x.y < 0.04).count();
    assert!(
        on > 100 && under == 0,
        "{on} particles on the clamp, {under} below"
    );
}

/// An event that settles pieces (checks and handles each as it is
/// written) gives the bits of the same event checked and handled whole, on
/// any number of threads, with every integrator (those that do not write
/// by pieces fall back to `check` and `handle`), also when it is missed and
/// the steps are retaken in pieces down to the finest.
#[test]
fn events_settled_piece_by_piece_are_the_same_bits() {
    for kind in [
        IntegratorKind::Symplectic,
        IntegratorKind::Rk4,
        IntegratorKind::Euler,
    ] {
        // No envelope; then one so thin that the cloth's fall is missed and
        // the step halved down to its finest pieces, where it is handled.
        for envelope in [f64::INFINITY, 1e-5] {
            let world = |mode: Mode| {
                move || {
                    let mut w = bare_cloth(kind, true);
                    let mut clamp = Clamp::new(0.04, mode);
                    clamp.envelope = envelope;
                    w.add_event(Box::new(clamp));
                    w
                }
            };
            let why = format!("{kind}, envelope {envelope}");
            let whole = run_world(1, world(Mode::Whole), 60);
            let settled = PIECES_SETTLED.load(Ordering::Relaxed);
            for threads in [1, 2, 3] {
                assert_eq!(
                    run_world(threads, world(Mode::Settles), 60),
                    whole,
                    "{why}, {threads} threads"
                );
            }
            let used = PIECES_SETTLED.load(Ordering::Relaxed) > settled;
            assert_eq!(used, kind != IntegratorKind::Euler, "{why}: pieces settled");
            // The clamp acted; with the thin envelope, by backtracking.
            let mut w = world(Mode::Settles)();
            for _ in 0..60 {
                w.step(1e-3).unwrap();
            }
            let on = w.state().pos.iter().filter(|x| x.y == 0.04).count();
            let under = w.state().pos.iter().filter(|x| x.y < 0.04).count();
            assert!(
                on > 0 && under == 0,
                "{why}: {on} particles on the clamp, {under} below"
            );
            let stats = w.stats();
            assert_eq!(
                stats.backtracks > 0,
                envelope.is_finite(),
                "{why}: {stats:?}"
            );
            assert_eq!(stats.unresolved > 0, envelope < 1e-6, "{why}: {stats:?}");
        }
    }
}

/// The engine's floor settles pieces: alone in a world it takes that path,
/// and beside an event that does not settle (an inert clamp far below) the
/// path before. The same states and the same bounces, recorded in the same
/// order, every step, on 1, 2 and 3 threads, with an envelope thin enough
/// that trials are thrown away (their bounces with them) and retaken.
#[test]
fn the_floor_settles_pieces_with_the_same_bits_and_bounces() {
    for kind in [IntegratorKind::Symplectic, IntegratorKind::Rk4] {
        let world = |settle: bool| {
            let mut w = bare_cloth(kind, true);
            w.add_floor(FloorDef {
                envelope: 2e-4,
                ..FloorDef::default()
            })
            .unwrap();
            if !settle {
                w.add_event(Box::new(Clamp::new(-1.0, Mode::Whole)));
            }
            w
        };
        let run = |threads: usize, settle: bool| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut w = world(settle);
                let mut bounces = Vec::new();
                for _ in 0..150 {
                    w.step(1e-3).unwrap();
                    bounces.extend_from_slice(w.event::<FloorCollision>().unwrap().collisions());
                }
                (hash(&w), bounces, w.stats())
            })
        };
        let before = run(1, false);
        assert!(before.1.len() > 100, "{kind}: {} bounces", before.1.len());
        assert!(before.2.backtracks > 0, "{kind}: {:?}", before.2);
        for threads in [1, 2, 3] {
            let settled = run(threads, true);
            assert!(settled == before, "{kind}, {threads} threads");
        }
    }
}

/// A large world that blows up names the same particle at the same time on
/// any number of threads (each thread looks at its own piece first).
#[test]
fn a_blow_up_is_named_alike_on_any_number_of_threads() {
    let blow_up = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut w = bare_cloth(IntegratorKind::Symplectic, true);
            w.set_velocity(ParticleId::from_index(3000), DVec3::new(0.0, 1e300, 0.0))
                .unwrap();
            for k in 0..1000 {
                if let Err(e) = w.step(1e-3) {
                    return (k, e, w.time());
                }
            }
            panic!("no blow-up on {threads} threads");
        })
    };
    let (k, e, t) = blow_up(1);
    assert!(matches!(e, SimError::NonFinite { .. }), "{e}");
    for threads in [2, 3] {
        let (k2, e2, t2) = blow_up(threads);
        assert_eq!(
            (k2, e2.to_string(), t2),
            (k, e.to_string(), t),
            "{threads} threads"
        );
    }
}

/// A large pile of spheres: sphere contact cannot answer by pieces, so the
/// world checks its events on one thread from its first step on, and again
/// by pieces once an event is added that can (with contact still there, the
/// answer is again no). The same bits on 1, 2 and 3 threads either way.
#[test]
fn a_large_world_with_sphere_contact_is_the_same_bits_on_any_number_of_threads() {
    let pile = |clamp: bool| {
        move || {
            let mut w = spheres(IntegratorKind::Symplectic);
            if clamp {
                w.add_event(Box::new(Clamp::new(0.015, Mode::Pieces)));
            }
            w
        }
    };
    // The spheres do touch: the second layer rests on the first, which
    // without contact it would have fallen into (to about 0.014 m).
    let mut w = pile(false)();
    for _ in 0..60 {
        w.step(1e-3).unwrap();
    }
    let second = (256..512)
        .map(|i| w.state().pos[i].y)
        .fold(f64::INFINITY, f64::min);
    assert!(second > 0.025, "second layer down to {second} m");
    for clamp in [false, true] {
        let one = run_world(1, pile(clamp), 60);
        for threads in [2, 3] {
            assert_eq!(
                run_world(threads, pile(clamp), 60),
                one,
                "{threads} threads, clamp {clamp}"
            );
        }
    }
}

/// A force that adds nothing and counts where it was evaluated: on a rayon
/// pool's thread, or not.
#[derive(Clone, Default)]
struct WhereEvaluated {
    on_pool: std::sync::Arc<AtomicUsize>,
    elsewhere: std::sync::Arc<AtomicUsize>,
}

impl animats_engine::Force for WhereEvaluated {
    fn apply(&mut self, _ctx: &animats_engine::ForceContext, _forces: &mut [DVec3]) {
        let count = if rayon::current_thread_index().is_some() {
            &self.on_pool
        } else {
            &self.elsewhere
        };
        count.fetch_add(1, Ordering::Relaxed);
    }
}

/// A world to step: its name, how to make it, and how many of its force
/// evaluations in five RK4 steps should run on the pool and elsewhere.
type Case = (&'static str, fn() -> World, (usize, usize));

/// A world that splits its work, stepped from outside any pool (as the CLI
/// and the Python bindings step), runs each whole step on the global pool's
/// threads (then its splits are fork-joins among them, not one round trip
/// from this thread each) and ends in the same bits as on one thread; a
/// small world never leaves the calling thread (waking the pool would cost
/// more than its step), nor does a large pile of spheres once its contact
/// has said it cannot answer by pieces (its per-particle loops then stay in
/// one piece).
#[test]
fn a_world_that_splits_steps_on_the_pool_and_a_small_one_where_it_is_called() {
    assert!(
        rayon::current_thread_index().is_none(),
        "tests run outside the pool"
    );
    // Five RK4 steps: twenty evaluations.
    let (all_on_pool, none) = if rayon::current_num_threads() > 1 {
        ((20, 0), (4, 16))
    } else {
        ((0, 20), (0, 20))
    };
    let cases: [Case; 4] = [
        (
            "the 64 × 64 cloth",
            || bare_cloth(IntegratorKind::Rk4, true),
            all_on_pool,
        ),
        (
            "300 bodies' gravity",
            || {
                let mut w = world(0.01);
                w.set_integrator(IntegratorKind::Rk4);
                w
            },
            all_on_pool,
        ),
        (
            "4,096 spheres with contact",
            || spheres(IntegratorKind::Rk4),
            none,
        ),
        ("a 10-particle chain", || chain(10), (0, 20)),
    ];
    for (name, make, expected) in cases {
        let counts = WhereEvaluated::default();
        let mut w = make();
        w.add_force(Box::new(counts.clone()));
        for _ in 0..5 {
            w.step(1e-3).unwrap();
        }
        let (pool, here) = (
            counts.on_pool.load(Ordering::Relaxed),
            counts.elsewhere.load(Ordering::Relaxed),
        );
        assert_eq!((pool, here), expected, "{name}: (on the pool, elsewhere)");
        // What `steps_on_pool` tells a caller with a loop of steps: true
        // exactly for the worlds whose steps went to the pool.
        let splits = expected == all_on_pool && rayon::current_num_threads() > 1;
        assert_eq!(w.steps_on_pool(), splits, "{name}: steps_on_pool");
        let moved = &mut w; // a World is Send, not Sync
        assert!(
            !animats_engine::on_pool(move || moved.steps_on_pool()),
            "{name}: on a pool thread, a step stays where it is"
        );
        let mut alone = make();
        alone.add_force(Box::new(WhereEvaluated::default()));
        let one = run_world(1, move || alone, 5);
        assert_eq!(hash(&w), one, "{name}: the same bits as on one thread");
        // The same five steps as one loop inside `on_pool`: every
        // evaluation on the pool, the same bits.
        let counts = WhereEvaluated::default();
        let mut looped = make();
        looped.add_force(Box::new(counts.clone()));
        animats_engine::on_pool(|| {
            for _ in 0..5 {
                looped.step(1e-3).unwrap();
            }
        });
        assert_eq!(
            (
                counts.on_pool.load(Ordering::Relaxed),
                counts.elsewhere.load(Ordering::Relaxed)
            ),
            (20, 0),
            "{name}: a loop inside on_pool evaluates on the pool"
        );
        assert_eq!(hash(&looped), one, "{name}: the same bits inside on_pool");
    }
}

/// 4,096 spheres of radius 1 cm in a jittered 16-wide cube of layers
/// 1 mm apart, sphere contact and a floor, integrated by `kind`.
fn spheres(kind: IntegratorKind) -> World {
    let mut w = World::new();
    w.set_integrator(kind);
    w.set_gravity(DVec3::new(0.0, -9.81, 0.0));
    w.add_floor(FloorDef::default()).unwrap();
    for i in 0..4096 {
        let (x, y, z) = (i % 16, i / 256, (i / 16) % 16);
        let at = DVec3::new(x as f64, y as f64 + 0.5, z as f64) * 0.021
            + DVec3::new(0.001 * (i % 3) as f64, 0.0, 0.001 * (i % 5) as f64);
        w.add_particle(ParticleDef::new(0.01).at(at).with_radius(0.01))
            .unwrap();
    }
    w.add_sphere_contact(SphereContactDef::default()).unwrap();
    w
}

/// `n` particles in a row joined by springs, the first nailed.
fn chain(n: usize) -> World {
    let mut w = World::new();
    w.set_integrator(IntegratorKind::Rk4);
    w.set_gravity(DVec3::new(0.0, -9.81, 0.0));
    for i in 0..n {
        let mut p = ParticleDef::new(0.1).at(DVec3::new(0.1 * i as f64, 1.0, 0.0));
        p.fixed = i == 0;
        w.add_particle(p).unwrap();
    }
    for i in 1..n {
        let id = ParticleId::from_index;
        w.add_spring(SpringDef::new(id(i - 1), id(i), 50.0, 0.1))
            .unwrap();
    }
    w
}
