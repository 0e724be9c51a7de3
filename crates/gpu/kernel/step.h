/*
 * The per-creature step of animats in C: the second implementation of the
 * Rust engine's physics (crates/engine), for the GPU (compiled by NVRTC as
 * CUDA, one thread per creature) and for the CPU (compiled by the C
 * compiler with -ffp-contract=off, to prove it equal to the engine in CI).
 *
 * Parity, bit for bit, rests on doing each operation of the engine in the
 * engine's order: no fused multiply-add (contraction off on both sides),
 * IEEE division and square root (correctly rounded on both), sums grouped
 * as the Rust groups them (glam's dot product is (x x' + y y') + z z'),
 * forces added in the engine's order (gravity first, then each spring in
 * its order). A change to the engine's physics that this file does not
 * follow fails crates/gpu/tests/parity.rs.
 *
 * Covered today: particles, uniform gravity, damped springs, angle joints
 * (their atan2 ported from the `libm` crate, libm.h), torque joints,
 * constant forces, fluids (still, in a uniform current or under a reef's waves) on every particle and their drag across springs ([fluid]
 * springs), soft (penalty) contact between spheres, sphere contact, the
 * event (spheres.h), the
 * floor, flat or on terrain (terrain.h: its located collisions with backtracking, and its contact force), n-body gravity, the explicit integrators
 * (Euler, midpoint, RK4, symplectic Euler) and implicit Euler (on a GPU
 * only in kernels compiled with AN_WITH_IMPLICIT). Everything else is refused when a world is packed
 * (crates/gpu/src/pack.rs), naming what is missing.
 */
#ifndef ANIMATS_STEP_H
#define ANIMATS_STEP_H

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define AN_FN __device__ static inline
#else
#include <math.h>
#define AN_FN static inline
#endif
#include "libm.h"
#include "trig.h"
#include "exp.h"
#include "terrain.h"
#include "spheres.h"

/* Integrators, as IntegratorKind's order in the engine. */
enum { AN_EULER = 0, AN_MIDPOINT = 1, AN_RK4 = 2, AN_SYMPLECTIC = 3, AN_IMPLICIT = 4 };

/* The parts of the step a batch has: each part's code runs only where
 * AN_HAS(b, part), so a batch whose creatures lack a part skips it whole
 * (b->absent, the host's Batch::absent). A kernel specialised for its
 * batches (src/cuda.rs, `Special`) is compiled with the same bits as the
 * constant AN_ABSENT and the batch's integrator as AN_ONLY_INTEGRATOR,
 * so that the compiler drops that code and the kernel holds fewer
 * registers. Skipped or dropped, the code is what would have run zero
 * times for such a batch (a loop over none of a creature's fluids, a
 * controller kind no creature has): the C on the CPU skips by b->absent
 * in every parity test, so a part wrongly called absent shows there. */
#ifdef AN_ONLY_INTEGRATOR
#if AN_ONLY_INTEGRATOR == 4 && !defined(AN_WITH_IMPLICIT)
#error "AN_ONLY_INTEGRATOR=4 (implicit Euler) needs AN_WITH_IMPLICIT"
#endif
#define AN_INTEGRATOR(b) AN_ONLY_INTEGRATOR
#else
#define AN_INTEGRATOR(b) ((b)->integrator)
#endif
#ifndef AN_ABSENT
#define AN_ABSENT 0
#endif
#define AN_HAS(b, part) (!(((AN_ABSENT) | (b)->absent) & (part)))
enum {
    AN_P_JOINTS = 1 << 0,  /* angle joints */
    AN_P_MOTORS = 1 << 1,  /* torque joints */
    AN_P_PUSHES = 1 << 2,  /* constant forces */
    AN_P_FLUIDS = 1 << 3,  /* fluids */
    AN_P_NBODY = 1 << 4,   /* n-body gravity */
    AN_P_SOFT = 1 << 5,    /* soft contact */
    AN_P_RODS = 1 << 6,    /* drag across springs */
    AN_P_PLANES = 1 << 7,  /* plane constraints */
    AN_P_CONTROL = 1 << 8, /* controller kind k (eval.h, an_act): AN_P_CONTROL << k, k = 0 .. 6 */
    AN_P_REEF = 1 << 15    /* a reef's waves, a fluid's or rods' current (an_current) */
};

/*
 * A batch of creatures of any mix of sizes, as structures of arrays with
 * per-creature offsets: creature c owns particles first_particle[c] ..
 * first_particle[c + 1] - 1 and springs first_spring[c] ..
 * first_spring[c + 1] - 1, whose ends are indices within the creature.
 * Angle joints (first_joint, ends a and b, joint j), torque joints
 * (first_motor, end and joint, unit axis, torque), constant forces (as
 * pushes: first_push, a particle and a vector each, in the engine's order)
 * and fluids on every particle (first_fluid) likewise. Vectors are
 * stored x, y, z per particle. `scratch` holds 15 doubles per particle
 * (force, and RK4's start and sums).
 */
typedef struct {
    const long long *first_particle;
    const long long *first_spring;
    const double *inv_mass;
    const double *mass;
    double *pos;
    double *vel;
    const int *spring_a;
    const int *spring_b;
    const double *stiffness;
    const double *damping;
    double *rest_length; /* muscles move it (eval.h) */
    double *scratch;
    const long long *first_joint;
    const int *joint_a;
    const int *joint_j;
    const int *joint_b;
    const double *joint_stiffness;
    const double *joint_damping;
    double *joint_rest;   /* actuators move it (eval.h) */
    const long long *first_motor;
    const int *motor_end;
    const int *motor_joint;
    const double *motor_axis; /* 3 per motor */
    double *motor_torque; /* actuators and gates move it (eval.h) */
    const long long *first_fluid;
    const double *fluid_drag;    /* -0.5 C rho pi, as the engine forms it */
    const double *fluid_density;
    const double *radius;
    const double *volume;
    const double *restitution;
    const double *mu_s;
    const double *mu_k;
    long long *failed; /* per creature: 0, or the step that gave a non-finite state */
    long long steps_before; /* steps the batch has taken in earlier runs */
    const long long *first_push; /* per creature: its constant forces' pushes */
    const int *push_particle;    /* one push: a constant force on one particle */
    double *push_force;          /* 3 per push; actuators and gates scale it (eval.h) */
    double gx, gy, gz;
    int gravity; /* 1: gravity pulls every particle; 0: none */
    int integrator;
    double dt;
    int floor;         /* 1: the plane y = 0 (collisions); 0: none */
    int floor_contact; /* 1: and its contact force (reaction, friction) */
    double envelope, rest_speed, static_speed, contact_tolerance;
    double flight_shift; /* IntegratorKind::free_flight_shift */
    const long long *first_pair; /* per creature: its soft contact's pairs */
    const int *pair_a;
    const int *pair_b;
    const double *pair_stiffness;
    const double *pair_damping;
    /* A scene's evaluation (eval.h): its spring muscles, its oscillators
     * and its [evolve] rules. */
    const long long *first_muscle; /* per creature: its spring muscles */
    const int *muscle_spring;      /* the spring, within the creature */
    const double *muscle_param;    /* 3 per muscle: min, max, rate (< 0: none) */
    double *muscle_level;
    const long long *first_osc;    /* per creature: its oscillators */
    const double *osc_frequency;
    const long long *first_output; /* per oscillator, over the batch: its outputs */
    const int *output_muscle;      /* the muscle driven, within the creature */
    const double *output_gene;     /* 5 per output: amplitude, phase, offset, shift (NaN: none), duty (NaN: a sine) */
    const long long *first_centre; /* per creature: the particles whose centre counts */
    const int *centre_particle;
    const long long *first_touch;  /* per creature: fail_on_touch */
    const int *touch_particle;
    const long long *first_stretch; /* per creature: fail_on_stretch */
    const int *stretch_pair;        /* 2 per rule */
    const double *stretch_length;
    const int *fixed;              /* per particle: 1 where fixed (the guard skips it) */
    const double *eval_param;      /* 16 per creature: axis x, y, z, time and distance
                                      weights, touch tolerance, clock and its carry;
                                      1 if the muscles' work is summed, energy weight,
                                      1 if a target counts, target x, y, z, its weight,
                                      1 if an actuator is gated */
    const long long *eval_count;   /* 3 per creature: steps to run, steps taken before,
                                      measures of the archive (the rest are terms) */
    double *result;                /* 5 per creature: fitness, distance, time, work, target distance */
    long long *ended;              /* 2 per creature: why (AN_TIMEOUT ...) and which rule */
    const long long *first_measure; /* per creature: its archive measures, then its terms */
    const int *measure_kind;        /* AN_M_CONTACT ... */
    const long long *measure_first_id; /* per measure, over the batch: its particles */
    const int *measure_id;
    const double *measure_axis;     /* 3 per measure */
    const double *measure_fixed;    /* a measure fixed when built: its value */
    const double *measure_weight;   /* a term's weight in the fitness */
    double *measure_sum;            /* per measure: its running sum, then its value */
    double *measure_start;          /* 3 per measure: the centre it starts from */
    const long long *first_sensor; /* per creature: its sensors ([[sensor]]) */
    const int *sensor_kind; /* AN_S_HEIGHT ... */
    const int *sensor_particle; /* 3 per sensor, within the creature */
    const double *sensor_param; /* 5 per sensor: axis x, y, z, min, max */
    double *sensor_level; /* per sensor: its level this step */
    const long long *first_ctrl; /* per creature: its controllers, in order */
    const int *ctrl_kind; /* 0: an oscillator, 1: a neural network, 2: a CTRNN, 3: an FSM, 4: a roobot's hopping FSM (network entries) */
    const int *ctrl_index; /* the oscillator or network, over the batch */
    const long long *net_first_layer; /* per network, over the batch: its layer sizes */
    const int *layer_size; /* inputs (clock included) first, outputs last */
    const long long *net_first_weight; /* per network: its weights and biases */
    const double *net_weight; /* as brains/neural.rs orders them */
    const double *net_clock; /* per network: the clock's Hz (NaN: none) */
    const long long *net_first_input; /* per network: its inputs */
    const int *net_input; /* a sensor, within the creature */
    const long long *net_first_output; /* per network: its outputs */
    const int *net_output_muscle; /* the muscle driven, within the creature */
    const double *net_output_shift; /* a trial's level offset (NaN: none) */
    const long long *net_first_scratch; /* per network: two layers' room */
    double *net_scratch; /* the layers being computed */
    const long long *net_first_neuron; /* per network: a CTRNN's neurons */
    const double *neuron_param; /* 3 per neuron: tau, bias, gain */
    double *neuron_state; /* per neuron: its state y */
    double *muscle_work; /* 3 per muscle: its state before a step (work.rs `Before`) */
    const int *muscle_kind;    /* per muscle: 0 a spring's rest length, 1 an angle joint's rest
                                  angle, 2 a torque joint's torque, 3 a constant force's scale;
                                  muscle_spring is then its spring, joint, motor or force */
    const double *muscle_base; /* 3 per muscle: a force's vector at scale 1 */
    const int *muscle_push;    /* 2 per muscle: a force's first push in the creature, pushes */
    const double *muscle_gate; /* 3 per muscle: its gate's sensor (-1: none), threshold,
                                  1 if open above it */
    const long long *first_rod; /* per creature: its springs dragged across ([fluid] springs) */
    const int *rod_a;           /* a rod's ends, within the creature */
    const int *rod_b;
    const double *rod_drag;     /* per rod: -0.5 C rho D, as forces/rod_drag.rs forms it */
    const double *fluid_current; /* AN_CURRENT per fluid: its current (an_current) */
    const double *rod_current;   /* AN_CURRENT per rod: its fluid's current (an_current) */
    const long long *first_plane; /* per creature: its plane constraints, in the world's order */
    const double *plane_param;    /* 7 per plane: point, unit normal, 1 if handled before the floor */
    const long long *plane_first_particle; /* per plane, over the batch: its particles */
    const int *plane_particle;    /* a particle, within the creature */
    const double *terrain_param;  /* the floor's shape (terrain.h): its numbers */
    const double *terrain_height; /* a heightfield's heights */
    int terrain;                  /* AN_T_FLAT ... (terrain.h) */
    const long long *first_excluded; /* per creature: its sphere contact's excluded pairs */
    const long long *excluded;    /* sorted keys, min << 32 | max (spheres.h) */
    const double *contact_param;  /* 4 per creature: 1 if it has sphere contact, its
                                     envelope, rest speed, restitution (NaN: the spheres') */
    const long long *first_slot;  /* per creature: its room in contact_slot */
    long long *contact_slot;      /* 4 n + n (n - 1) / 2 a creature with sphere contact */
    const long long *first_nbody; /* per creature: its n-body gravity groups */
    const double *nbody_param;    /* 2 per group: G, softening squared */
    const long long *nbody_first_body; /* per group, over the batch: its bodies */
    const int *nbody_body;        /* a body, within the creature, in the group's order */
    const long long *nbody_first_range; /* per group, over the batch: its ranges of rows */
    const long long *nbody_range; /* a range's first row (NBodyGravity::row_ranges) */
    double *clock;                /* 2 per creature of a batch of worlds: its time and the
                                     clock's carry (world/step.rs, `advance_clock`) */
    double *implicit;             /* implicit Euler's room: AN_IMPLICIT_ROOM per particle,
                                     AN_IMPLICIT_SPRING per spring, AN_IMPLICIT_JOINT per
                                     angle joint, a creature's after the ones before it */
    double solver_tolerance;      /* implicit Euler's conjugate gradients: relative tolerance */
    long long solver_iterations;  /* and most iterations */
    unsigned int absent;          /* the parts no creature of the batch has (AN_P_*) */
} an_batch;

/* Where one creature's state is: its positions and velocities (3 doubles
 * a particle) and the step's scratch (15 a particle), and the constants
 * read every step: its springs' ends, stiffness and damping (spring 0 the
 * creature's first), its particles' inverse masses, masses and radii
 * (particle 0 the creature's first); in the batch's arrays (an_batch_state) or in arrays
 * of the thread's own (an_local). */
typedef struct {
    double *x, *v, *sc;
    const int *sa, *sb;
    const double *k, *d;
    const double *w, *m, *r; /* the particles' inverse masses, masses and radii */
} an_state;

/* Creature c's state in the batch's arrays. */
AN_FN an_state an_batch_state(const an_batch *b, long long c) {
    long long p0 = b->first_particle[c], s0 = b->first_spring[c];
    an_state st = {b->pos + 3 * p0,     b->vel + 3 * p0,  b->scratch + 15 * p0,
                   b->spring_a + s0,    b->spring_b + s0, b->stiffness + s0,
                   b->damping + s0,     b->inv_mass + p0, b->mass + p0,
                   b->radius + p0};
    return st;
}

/* glam's dot product and cross product, in its order. */
AN_FN double an_dot(const double *a, const double *b) {
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}
AN_FN void an_cross(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - b[1] * a[2];
    out[1] = a[2] * b[0] - b[2] * a[0];
    out[2] = a[0] * b[1] - b[0] * a[1];
}

/* Angle joints j0 .. j0 + nj - 1 (forces/angle_joint.rs, `apply`). */
/* Angle joint q's arms ra, rb at positions x, their squared lengths, the
 * normal ra x rb and its length nl (AngleJoint::bend): 0 when the arms
 * are collinear or one has no length (no plane of bending). */
AN_FN int an_bend(const an_batch *b, long long q, const double *x, double *ra, double *rb,
                  double *la2, double *lb2, double *normal, double *nl) {
    long long a = b->joint_a[q], j = b->joint_j[q], e = b->joint_b[q];
    for (int k = 0; k < 3; k++) {
        ra[k] = x[3 * a + k] - x[3 * j + k];
        rb[k] = x[3 * e + k] - x[3 * j + k];
    }
    *la2 = an_dot(ra, ra);
    *lb2 = an_dot(rb, rb);
    an_cross(ra, rb, normal);
    double n2 = an_dot(normal, normal);
    if (n2 <= 1e-24 * *la2 * *lb2 || *la2 == 0.0 || *lb2 == 0.0) {
        return 0;
    }
    *nl = sqrt(n2);
    return 1;
}

AN_FN void an_angle_joints(const an_batch *b, long long j0, long long nj, const double *x,
                           const double *v, double *f) {
    for (long long q = j0; q < j0 + nj; q++) {
        long long a = b->joint_a[q], j = b->joint_j[q], e = b->joint_b[q];
        double ra[3], rb[3], normal[3], pa[3], pb[3], va[3], vb[3], la2, lb2, nl;
        if (!an_bend(b, q, x, ra, rb, &la2, &lb2, normal, &nl)) {
            continue; /* collinear or degenerate: no plane of bending */
        }
        double theta = an_atan2(nl, an_dot(ra, rb));
        an_cross(normal, ra, pa);
        an_cross(normal, rb, pb);
        double wa = 1.0 / (nl * la2), wb = 1.0 / (nl * lb2);
        for (int k = 0; k < 3; k++) {
            vb[k] = v[3 * e + k] - v[3 * j + k];
            va[k] = v[3 * a + k] - v[3 * j + k];
        }
        double theta_dot = an_dot(pb, vb) * wb - an_dot(pa, va) * wa;
        double torque = b->joint_stiffness[q] * (theta - b->joint_rest[q])
                      + b->joint_damping[q] * theta_dot;
        double ta = torque * wa, tb = -torque * wb;
        for (int k = 0; k < 3; k++) {
            double fa = pa[k] * ta, fb = pb[k] * tb;
            f[3 * a + k] += fa;
            f[3 * e + k] += fb;
            f[3 * j + k] -= fa + fb;
        }
    }
}

/* Torque joint q's lever arm at positions x: its end's offset from the
 * joint, less its part along the axis, into perp; returns its length
 * squared (0 with the end on the axis). */
AN_FN double an_lever(const an_batch *b, long long q, const double *x, double *perp) {
    long long e = b->motor_end[q], j = b->motor_joint[q];
    const double *axis = b->motor_axis + 3 * q;
    double r[3];
    for (int k = 0; k < 3; k++) {
        r[k] = x[3 * e + k] - x[3 * j + k];
    }
    double along = an_dot(r, axis);
    for (int k = 0; k < 3; k++) {
        perp[k] = r[k] - axis[k] * along;
    }
    return an_dot(perp, perp);
}

/* Torque joints m0 .. m0 + nm - 1 (forces/torque_joint.rs, `apply`). */
AN_FN void an_motors(const an_batch *b, long long m0, long long nm, const double *x, double *f) {
    for (long long q = m0; q < m0 + nm; q++) {
        double torque = b->motor_torque[q];
        if (torque == 0.0) {
            continue;
        }
        long long e = b->motor_end[q], j = b->motor_joint[q];
        double perp[3], c[3];
        double l2 = an_lever(b, q, x, perp);
        if (l2 == 0.0) {
            continue; /* the end sits on the axis: no lever arm */
        }
        an_cross(b->motor_axis + 3 * q, perp, c);
        double s = torque / l2;
        for (int k = 0; k < 3; k++) {
            double fk = c[k] * s;
            f[3 * e + k] += fk;
            f[3 * j + k] -= fk;
        }
    }
}

/* A fluid's current, AN_CURRENT numbers (src/pack.rs `current`): its
 * uniform velocity (still water 0); then NaN, or a reef's (forces/current.rs
 * `ReefWater`) surface, amplitude * omega, k, omega and direction (x, y, z,
 * normalised, y 0), its drift in the first three. */
#define AN_CURRENT 11

/* A reef's current at p at time t, into u (ReefWater::velocity, in its
 * order: glam's dot and its vector sums written out). Out of line on a
 * GPU (AN_COLD): inlined into the fluid's and the rods' loops, its exp,
 * sin and cos took the flat floor's evaluation from 168 registers to 255,
 * spilling, for every creature, in a reef or not. */
AN_COLD void an_reef_current(const double *cur, const double *p, double t, double *u) {
    const double *dir = cur + 8;
    double depth = cur[4] - p[1];
    depth = depth > 0.0 ? depth : 0.0; /* f64::max(depth, 0.0): NaN gives 0 */
    double speed = cur[5] * an_exp(-cur[6] * depth);
    double phase = cur[6] * ((dir[0] * p[0] + dir[1] * p[1]) + dir[2] * p[2]) - cur[7] * t;
    double s = an_sin(phase), c = an_cos(phase);
    double along = speed * c, up = speed * s;
    u[0] = (dir[0] * along + 0.0 * up) + cur[0];
    u[1] = (dir[1] * along + 1.0 * up) + cur[1];
    u[2] = (dir[2] * along + 0.0 * up) + cur[2];
}

/* The current's velocity at p at time t, into u: a uniform current's
 * (still water's 0), or a reef's. */
AN_FN void an_current(const an_batch *b, const double *cur, const double *p, double t,
                      double *u) {
    if (!AN_HAS(b, AN_P_REEF) || cur[3] != cur[3]) {
        u[0] = cur[0];
        u[1] = cur[1];
        u[2] = cur[2];
        return;
    }
    an_reef_current(cur, p, t, u);
}

/* Fluids q0 .. q0 + nq - 1 on every particle of the creature, still, in
 * a uniform current or under a reef's waves, at time t (forces/fluid.rs,
 * `force_on`): quadratic drag against the velocity relative to the
 * water, and buoyancy. In still water the current is 0, and v - 0 is v
 * to the bit (-0 included). */
AN_FN void an_fluids(const an_batch *b, an_state st, long long p0, long long n, long long q0,
                     long long nq, const double *x, const double *v, double *f, double t) {
    double g[3] = {b->gx, b->gy, b->gz};
    if (!b->gravity) {
        g[0] = 0.0;
        g[1] = 0.0;
        g[2] = 0.0;
    }
    for (long long q = q0; q < q0 + nq; q++) {
        double drag = b->fluid_drag[q], density = b->fluid_density[q];
        const double *cur = b->fluid_current + AN_CURRENT * q;
        for (long long i = 0; i < n; i++) {
            double r = st.r[i], u[3];
            an_current(b, cur, x + 3 * i, t, u);
            double vr[3] = {v[3 * i] - u[0], v[3 * i + 1] - u[1], v[3 * i + 2] - u[2]};
            double speed = sqrt(an_dot(vr, vr));
            double s = drag * r * r * speed;
            double lift = -b->volume[p0 + i] * density;
            for (int k = 0; k < 3; k++) {
                f[3 * i + k] += vr[k] * s + g[k] * lift;
            }
        }
    }
}

/* Soft (penalty) contact between the pairs q0 .. q0 + nq - 1 of spheres
 * (forces/soft_contact.rs, `pair`): F = k overlap - c u_n along the line of
 * centres, never pulling; the engine's sweep tests only pairs whose boxes
 * overlap, with the same forces as testing all, as here. */
AN_FN void an_soft_contact(const an_batch *b, an_state st, long long q0, long long nq,
                           const double *x, const double *v, double *f) {
    for (long long q = q0; q < q0 + nq; q++) {
        long long a = b->pair_a[q], e = b->pair_b[q];
        double d[3], u[3], n[3];
        for (int k = 0; k < 3; k++) {
            d[k] = x[3 * e + k] - x[3 * a + k];
        }
        /* A pair apart returns before the square root, as the engine's:
         * d^2 > fl(s^2) means d^2 >= s^2 exactly (no double lies between
         * fl(s^2) and s^2), so the same pairs are skipped, to the bit. */
        double d2 = an_dot(d, d), reach = st.r[a] + st.r[e];
        if (d2 > reach * reach) {
            continue;
        }
        double dist = sqrt(d2);
        double overlap = reach - dist;
        if (overlap <= 0.0 || dist <= 0.0) {
            continue;
        }
        for (int k = 0; k < 3; k++) {
            n[k] = d[k] / dist;
            u[k] = v[3 * e + k] - v[3 * a + k];
        }
        double separating = an_dot(u, n);
        double push = b->pair_stiffness[q] * overlap - b->pair_damping[q] * separating;
        push = push > 0.0 ? push : 0.0; /* f64::max(push, 0.0): NaN gives 0 */
        for (int k = 0; k < 3; k++) {
            double fk = n[k] * push;
            f[3 * a + k] -= fk;
            f[3 * e + k] += fk;
        }
    }
}

/* The two Gauss points along a rod (forces/rod_drag.rs, GAUSS). */
#define AN_GAUSS_0 0.21132486540518708
#define AN_GAUSS_1 0.7886751345948129

/* Drag across the rods q0 .. q0 + nq - 1, in still water, a uniform
 * current or a reef's waves at time t (forces/rod_drag.rs, `apply`):
 * -0.5 C rho D |v_n| v_n per length, v_n the velocity relative to the
 * water across the rod, integrated by two-point Gauss quadrature (the
 * current taken at each point), each point's force split between the
 * ends as a lever splits it. */
AN_FN void an_rod_drag(const an_batch *b, long long q0, long long nq, const double *x,
                       const double *v, double *f, double t) {
    const double gauss[2] = {AN_GAUSS_0, AN_GAUSS_1};
    for (long long q = q0; q < q0 + nq; q++) {
        long long a = b->rod_a[q], e = b->rod_b[q];
        double drag = b->rod_drag[q];
        const double *cur = b->rod_current + AN_CURRENT * q;
        double d[3], u[3], dv[3], fa[3] = {0.0, 0.0, 0.0}, fe[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 3; k++) {
            d[k] = x[3 * e + k] - x[3 * a + k];
        }
        double length = sqrt(an_dot(d, d));
        if (length == 0.0) {
            continue; /* no direction: a rod of no length has no drag */
        }
        for (int k = 0; k < 3; k++) {
            u[k] = d[k] / length;
            dv[k] = v[3 * e + k] - v[3 * a + k];
        }
        for (int g = 0; g < 2; g++) {
            double xi = gauss[g], w[3], vn[3], at[3], uc[3];
            for (int k = 0; k < 3; k++) {
                at[k] = x[3 * a + k] + d[k] * xi;
            }
            an_current(b, cur, at, t, uc);
            for (int k = 0; k < 3; k++) {
                w[k] = (v[3 * a + k] + dv[k] * xi) - uc[k];
            }
            double along = an_dot(w, u);
            for (int k = 0; k < 3; k++) {
                vn[k] = w[k] - u[k] * along;
            }
            double s = drag * 0.5 * length * sqrt(an_dot(vn, vn));
            double lever = 1.0 - xi;
            for (int k = 0; k < 3; k++) {
                double fk = vn[k] * s;
                fa[k] += fk * lever;
                fe[k] += fk * xi;
            }
        }
        for (int k = 0; k < 3; k++) {
            f[3 * a + k] += fa[k];
            f[3 * e + k] += fe[k];
        }
    }
}

/* The friction on resting particle i (forces/floor_contact.rs,
 * `friction`) sliding at vt under the tangential force ft, pressed with
 * `normal`, into fr. h is the trial's step. */
AN_FN void an_friction(const an_batch *b, an_state st, long long i, long long p, const double *vt,
                       const double *ft, double normal, double h, double *fr) {
    double m = st.m[i];
    double speed = sqrt(an_dot(vt, vt));
    if (speed < b->static_speed) {
        double hold[3];
        double k = m / h;
        for (int q = 0; q < 3; q++) {
            hold[q] = -ft[q] - vt[q] * k;
        }
        double needed = sqrt(an_dot(hold, hold));
        if (needed <= b->mu_s[p] * normal) {
            for (int q = 0; q < 3; q++) {
                fr[q] = hold[q];
            }
        } else {
            double cap = b->mu_k[p] * normal;
            double s = (cap < needed ? cap : needed) / needed;
            for (int q = 0; q < 3; q++) {
                fr[q] = hold[q] * s;
            }
        }
    } else {
        double dir[3] = {vt[0] / speed, vt[1] / speed, vt[2] / speed};
        double stop = m * speed / h + an_dot(ft, dir);
        double cap = b->mu_k[p] * normal;
        double pos = stop > 0.0 ? stop : 0.0;
        double kinetic = cap < pos ? cap : pos;
        for (int q = 0; q < 3; q++) {
            fr[q] = -(dir[q] * kinetic);
        }
    }
}

/* The floor's contact force on particle i on terrain (floor_contact.rs,
 * `on_terrain`): as on the flat floor, along the surface's normal at the
 * nearest point, a normal speed within 1 um/s of zero cancelled too. */
AN_COLD void an_terrain_contact(const an_batch *b, an_state st, long long i, long long p,
                              const double *x, const double *v, double *f, double h) {
    if (st.w[i] == 0.0) {
        return;
    }
    double r = st.r[i], d, n[3];
    if (!an_probe(b->terrain, b->terrain_param, b->terrain_height, x, r + b->contact_tolerance,
                  &d, n)) {
        return;
    }
    if (d - r > b->contact_tolerance) {
        return;
    }
    double vn = an_dot(v, n), fn = an_dot(f, n);
    if (vn > 1e-6 || vn < -b->rest_speed || fn >= 0.0) {
        return;
    }
    double m = st.m[i];
    double normal = -fn;
    double ft[3], vt[3], fr[3];
    for (int q = 0; q < 3; q++) {
        ft[q] = f[q] - n[q] * fn;
    }
    double residual = an_fabs(vn) <= 1e-6 ? vn : 0.0;
    double cancel = residual * m / h;
    for (int q = 0; q < 3; q++) {
        f[q] = ft[q] - n[q] * cancel;
        vt[q] = v[q] - n[q] * vn;
    }
    an_friction(b, st, i, p, vt, ft, normal, h, fr);
    for (int q = 0; q < 3; q++) {
        f[q] += fr[q];
    }
}

/* The flat floor's contact force on particle i (forces/floor_contact.rs,
 * `contact` and `friction`): a sphere resting on the plane and pressed
 * into it is held up, and rubs. h is the trial's step. */
AN_FN void an_floor_contact(const an_batch *b, an_state st, long long i, long long p,
                            const double *x, const double *v, double *f, double h) {
    if (AN_ON_TERRAIN(b)) {
        an_terrain_contact(b, st, i, p, x, v, f, h);
        return;
    }
    if (st.w[i] == 0.0 || x[1] - st.r[i] > b->contact_tolerance) {
        return;
    }
    if (v[1] > 0.0 || v[1] < -b->rest_speed || f[1] >= 0.0) {
        return;
    }
    double normal = -f[1];
    f[1] = 0.0;
    double vt[3] = {v[0], 0.0, v[2]}, ft[3] = {f[0], 0.0, f[2]}, fr[3];
    an_friction(b, st, i, p, vt, ft, normal, h, fr);
    for (int q = 0; q < 3; q++) {
        f[q] += fr[q];
    }
}

/* The lanes' sum in nbody/pairs.rs's fixed tree. */
AN_FN double an_tree8(const double *s) {
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/* The n-body pair of the earlier body a and the later e at positions x:
 * d = x_e - x_a and inv = 1 / (r2 sqrt r2), r2 = |d|^2 + eps2, as
 * nbody/pairs.rs forms them; 0 where r2 is not positive (two bodies at one
 * place, unsoftened: the pair pulls nowhere). */
AN_FN int an_pair(const double *x, long long a, long long e, double eps2, double *d,
                  double *inv) {
    for (int c = 0; c < 3; c++) {
        d[c] = x[3 * e + c] - x[3 * a + c];
    }
    double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2;
    if (!(r2 > 0.0)) {
        return 0;
    }
    *inv = 1.0 / (r2 * sqrt(r2));
    return 1;
}

/* N-body gravity, groups g0 .. g0 + ng - 1 (forces/nbody.rs, `apply`, with
 * forces/nbody/pairs.rs's sums). Body k's pull is its row: the bodies
 * after it, body q into accumulator q mod 8 (from +0, in q's order),
 * reduced in the fixed tree; then, range by range, for each range of rows
 * that begins before k (one range below 256 bodies), the reactions its
 * rows before k give k, subtracted from +0 in row order. Each
 * pair's d = x_later - x_earlier, |d|^2 + eps^2 and 1 / (r2 sqrt r2) are
 * formed for each of its bodies alike; a pair whose r2 is not positive
 * (two bodies at one place, unsoftened) pulls nowhere, and is skipped as
 * `small` skips it (the kernel's zero-weighted terms leave its
 * accumulators as they were). The force: the pull times G m_k. Out of
 * line (AN_COLD), so that its registers do not crowd every creature's
 * step. */
AN_COLD void an_nbody(const an_batch *b, an_state st, long long g0, long long ng,
                      const double *x, double *f) {
    for (long long g = g0; g < g0 + ng; g++) {
        double G = b->nbody_param[2 * g], eps2 = b->nbody_param[2 * g + 1];
        long long first = b->nbody_first_body[g], nb = b->nbody_first_body[g + 1] - first;
        const int *body = b->nbody_body + first;
        const long long *range = b->nbody_range + b->nbody_first_range[g];
        long long nr = b->nbody_first_range[g + 1] - b->nbody_first_range[g];
        for (long long k = 0; k < nb; k++) {
            long long i = body[k];
            double s[3][8], pull[3];
            for (int c = 0; c < 3; c++) {
                for (int l = 0; l < 8; l++) {
                    s[c][l] = 0.0;
                }
            }
            for (long long q = k + 1; q < nb; q++) {
                long long e = body[q];
                double d[3], inv;
                if (!an_pair(x, i, e, eps2, d, &inv)) {
                    continue;
                }
                double wj = st.m[e] * inv;
                for (int c = 0; c < 3; c++) {
                    s[c][q % 8] += d[c] * wj;
                }
            }
            for (int c = 0; c < 3; c++) {
                pull[c] = an_tree8(s[c]);
            }
            for (long long r = 0; r < nr && range[r] < k; r++) {
                long long end = r + 1 < nr && range[r + 1] < k ? range[r + 1] : k;
                double re[3] = {0.0, 0.0, 0.0};
                for (long long q = range[r]; q < end; q++) {
                    long long a = body[q];
                    double d[3], inv;
                    if (!an_pair(x, a, i, eps2, d, &inv)) {
                        continue;
                    }
                    double wi = st.m[a] * inv;
                    for (int c = 0; c < 3; c++) {
                        re[c] -= d[c] * wi;
                    }
                }
                for (int c = 0; c < 3; c++) {
                    pull[c] += re[c];
                }
            }
            double gm = G * st.m[i];
            for (int c = 0; c < 3; c++) {
                f[3 * i + c] += pull[c] * gm;
            }
        }
    }
}

/* The forces on a creature's particles at positions x, velocities v, in
 * the engine's order (force_set.rs, `evaluate`): gravity, springs, angle
 * joints, torque joints, constant forces, fluids, n-body gravity, soft contact and then
 * rod drag (user forces of the body stage), the floor's contact force. h: the step
 * of the trial, t: the time the forces are asked at. */
AN_FN void an_forces(const an_batch *b, an_state st, long long c, long long p0, long long n,
                     long long s0, long long ns, const double *x, const double *v, double *f,
                     double h, double t) {
    for (long long i = 0; i < n; i++) {
        if (b->gravity) {
            double m = st.m[i];
            f[3 * i] = m * b->gx;
            f[3 * i + 1] = m * b->gy;
            f[3 * i + 2] = m * b->gz;
        } else {
            f[3 * i] = 0.0;
            f[3 * i + 1] = 0.0;
            f[3 * i + 2] = 0.0;
        }
    }
    for (long long s = s0; s < s0 + ns; s++) {
        long long a = st.sa[s - s0], e = st.sb[s - s0];
        double dx = x[3 * e] - x[3 * a];
        double dy = x[3 * e + 1] - x[3 * a + 1];
        double dz = x[3 * e + 2] - x[3 * a + 2];
        double len = sqrt((dx * dx + dy * dy) + dz * dz);
        double inv = len > 0.0 ? 1.0 / len : 0.0;
        double nx = dx * inv, ny = dy * inv, nz = dz * inv;
        double wx = v[3 * e] - v[3 * a];
        double wy = v[3 * e + 1] - v[3 * a + 1];
        double wz = v[3 * e + 2] - v[3 * a + 2];
        double t = st.k[s - s0] * (len - b->rest_length[s])
                 + st.d[s - s0] * ((wx * nx + wy * ny) + wz * nz);
        double fx = nx * t, fy = ny * t, fz = nz * t;
        f[3 * a] += fx;
        f[3 * a + 1] += fy;
        f[3 * a + 2] += fz;
        f[3 * e] -= fx;
        f[3 * e + 1] -= fy;
        f[3 * e + 2] -= fz;
    }
    long long j0 = b->first_joint[c], m0 = b->first_motor[c];
    if (AN_HAS(b, AN_P_JOINTS)) {
        an_angle_joints(b, j0, b->first_joint[c + 1] - j0, x, v, f);
    }
    if (AN_HAS(b, AN_P_MOTORS)) {
        an_motors(b, m0, b->first_motor[c + 1] - m0, x, f);
    }
    for (long long q = b->first_push[c]; AN_HAS(b, AN_P_PUSHES) && q < b->first_push[c + 1]; q++) {
        long long p = b->push_particle[q];
        for (int k = 0; k < 3; k++) {
            f[3 * p + k] += b->push_force[3 * q + k];
        }
    }
    long long q0 = b->first_fluid[c];
    if (AN_HAS(b, AN_P_FLUIDS)) {
        an_fluids(b, st, p0, n, q0, b->first_fluid[c + 1] - q0, x, v, f, t);
    }
    long long n0 = b->first_nbody[c];
    if (AN_HAS(b, AN_P_NBODY) && b->first_nbody[c + 1] > n0) {
        an_nbody(b, st, n0, b->first_nbody[c + 1] - n0, x, f);
    }
    long long c0 = b->first_pair[c];
    if (AN_HAS(b, AN_P_SOFT)) {
        an_soft_contact(b, st, c0, b->first_pair[c + 1] - c0, x, v, f);
    }
    long long r0 = b->first_rod[c];
    if (AN_HAS(b, AN_P_RODS)) {
        an_rod_drag(b, r0, b->first_rod[c + 1] - r0, x, v, f, t);
    }
    if (b->floor && b->floor_contact) {
        for (long long i = 0; i < n; i++) {
            an_floor_contact(b, st, i, p0 + i, x + 3 * i, v + 3 * i, f + 3 * i, h);
        }
    }
}

#if !defined(__CUDACC_RTC__) || defined(AN_WITH_IMPLICIT)
/* (Implicit Euler's code, from here to an_implicit: on a GPU only in the
 * kernels for implicit batches.) */
/* Implicit Euler's room (integrators/implicit.rs, jacobian.rs): per
 * particle, the right-hand side's h^2 (df/dx) v0 (3), the particle's own
 * block of S (9), then b, x, r, z, p, q of the conjugate gradients (3
 * each) and the preconditioner's inverse block (9); per spring, its
 * central interaction as Jacobian::central stores it (1 if it has one,
 * its unit vector, alpha, beta); per angle joint, its six off-diagonal
 * blocks of S as Jacobian::block stores them (1 if it has them, then the
 * blocks). A 3x3 block is stored by columns, as glam's DMat3. */
#define AN_IMPLICIT_ROOM 39
#define AN_IMPLICIT_SPRING 6
#define AN_IMPLICIT_JOINT 55

/* glam's DMat3::mul_vec3: (x_axis v.x + y_axis v.y) + z_axis v.z. */
AN_FN void an_m3_mul(const double *m, const double *v, double *out) {
    for (int k = 0; k < 3; k++) {
        out[k] = (m[k] * v[0] + m[3 + k] * v[1]) + m[6 + k] * v[2];
    }
}

/* Jacobian::s: -(dfdx h^2 + dfdv h), element by element. */
AN_FN void an_jac_s(const double *dfdx, const double *dfdv, double h, double *s) {
    for (int k = 0; k < 9; k++) {
        s[k] = -(dfdx[k] * (h * h) + dfdv[k] * h);
    }
}

/* Jacobian::block (single where i == j) of particles i and j: the
 * right-hand side's term and, on the diagonal, the block added; off it,
 * the block is returned in s for the caller (apply) to use. */
AN_FN void an_jac_block(double *rhs, double *diag, const double *v0, long long i, long long j,
                        const double *dfdx, const double *dfdv, double h, double *s) {
    double mv[3];
    an_jac_s(dfdx, dfdv, h, s);
    an_m3_mul(dfdx, v0 + 3 * j, mv);
    for (int k = 0; k < 3; k++) {
        rhs[3 * i + k] += mv[k] * (h * h);
    }
    if (i == j) {
        for (int k = 0; k < 9; k++) {
            diag[9 * i + k] += s[k];
        }
    }
}

/* Spring s's central interaction at positions x (spring.rs `jacobian`,
 * Jacobian::central): 0 for a spring of no length; else its unit vector
 * n, alpha and beta. */
AN_FN int an_jac_spring(const an_batch *b, an_state st, long long s0, long long s, const double *x,
                        double h, double *n, double *alpha, double *beta, double *along,
                        double *across) {
    long long a = st.sa[s - s0], e = st.sb[s - s0];
    double d[3];
    for (int k = 0; k < 3; k++) {
        d[k] = x[3 * e + k] - x[3 * a + k];
    }
    double l = sqrt(an_dot(d, d));
    if (l == 0.0) {
        return 0;
    }
    double k = st.k[s - s0], c = st.d[s - s0];
    double slack = 1.0 - b->rest_length[s] / l;
    double across0 = k * (slack > 0.0 ? slack : 0.0); /* f64::max(slack, 0.0) */
    for (int q = 0; q < 3; q++) {
        n[q] = d[q] / l;
    }
    *along = k;
    *across = across0;
    *alpha = h * h * (k - across0) + h * c;
    *beta = h * h * across0;
    return 1;
}

/* Angle joint q's gradient of its angle at positions x (angle_joint.rs
 * `jacobian`): 0 where it has no plane of bending; else g[0..9]: the
 * gradients at its first end, its joint and its second end. */
AN_FN int an_jac_joint(const an_batch *b, long long q, const double *x, double *g) {
    double ra[3], rb[3], normal[3], pa[3], pb[3], la2, lb2, nl;
    if (!an_bend(b, q, x, ra, rb, &la2, &lb2, normal, &nl)) {
        return 0;
    }
    an_cross(normal, ra, pa);
    an_cross(normal, rb, pb);
    double wa = -1.0 / (nl * la2), wb = 1.0 / (nl * lb2);
    for (int k = 0; k < 3; k++) {
        g[k] = pa[k] * wa;
        g[6 + k] = pb[k] * wb;
        g[3 + k] = -(g[k] + g[6 + k]);
    }
    return 1;
}

/* The block of angle joint q between its particles u and w (0 its first
 * end, 1 its joint, 2 its second end), from its gradients g: dfdx =
 * outer (-k), dfdv = outer (-c), outer = g_u g_w^T. */
AN_FN void an_jac_joint_block(const an_batch *b, long long q, const double *g, int u, int w,
                              double *dfdx, double *dfdv) {
    double k = -b->joint_stiffness[q], c = -b->joint_damping[q];
    for (int col = 0; col < 3; col++) {
        for (int r = 0; r < 3; r++) {
            double o = g[3 * u + r] * g[3 * w + col];
            dfdx[3 * col + r] = o * k;
            dfdv[3 * col + r] = o * c;
        }
    }
}

/* The conjugate gradients' dot product (implicit.rs `dot`): four lanes,
 * particle k into lane k mod 4 up to the last whole four, the rest into
 * lane 0, then (s0 + s1) + (s2 + s3). */
AN_FN double an_cg_dot(const double *a, const double *b, long long n) {
    double s[4] = {0.0, 0.0, 0.0, 0.0};
    long long whole = n - n % 4;
    for (long long i = 0; i < whole; i++) {
        s[i % 4] += an_dot(a + 3 * i, b + 3 * i);
    }
    for (long long i = whole; i < n; i++) {
        s[0] += an_dot(a + 3 * i, b + 3 * i);
    }
    return (s[0] + s[1]) + (s[2] + s[3]);
}

/* (M + S) p into out (Jacobian::apply): each particle's own block, then
 * each spring's central interaction in order, then each angle joint's
 * off-diagonal blocks in order, as the step stored them (sr: the
 * springs' room, jr: the joints'). */
AN_FN void an_cg_apply(const an_batch *b, an_state st, long long c, long long n, long long ns,
                       const double *sr, const double *jr, const double *diag, const double *p,
                       double *out) {
    for (long long i = 0; i < n; i++) {
        double mv[3];
        an_m3_mul(diag + 9 * i, p + 3 * i, mv);
        for (int k = 0; k < 3; k++) {
            out[3 * i + k] = p[3 * i + k] * st.m[i] + mv[k];
        }
    }
    for (long long s = 0; s < ns; s++) {
        const double *e = sr + AN_IMPLICIT_SPRING * s, *nv = e + 1;
        if (e[0] == 0.0) {
            continue;
        }
        double alpha = e[4], beta = e[5];
        long long a = st.sa[s], z = st.sb[s];
        double nb = alpha * an_dot(nv, p + 3 * z), na = alpha * an_dot(nv, p + 3 * a);
        for (int k = 0; k < 3; k++) {
            out[3 * a + k] -= nv[k] * nb + p[3 * z + k] * beta;
        }
        for (int k = 0; k < 3; k++) {
            out[3 * z + k] -= nv[k] * na + p[3 * a + k] * beta;
        }
    }
    long long j0 = b->first_joint[c];
    for (long long q = j0; q < b->first_joint[c + 1]; q++) {
        const double *e = jr + AN_IMPLICIT_JOINT * (q - j0);
        if (e[0] == 0.0) {
            continue;
        }
        long long ids[3] = {b->joint_a[q], b->joint_j[q], b->joint_b[q]};
        int k = 0;
        for (int u = 0; u < 3; u++) {
            for (int w = 0; w < 3; w++) {
                if (u == w) {
                    continue;
                }
                double mv[3];
                an_m3_mul(e + 1 + 9 * k++, p + 3 * ids[w], mv);
                for (int d = 0; d < 3; d++) {
                    out[3 * ids[u] + d] += mv[d];
                }
            }
        }
    }
}

/* One implicit Euler step of size h from (x0, v0) at time t into (x1, v1)
 * (integrators/implicit.rs `step`): the forces at the start, their
 * Jacobian (springs, angle joints, fluids' drag, in the engine's order),
 * then (M + S) dv = h f0 + h^2 (df/dx) v0 solved by conjugate gradients
 * preconditioned by each particle's inverse block, to the batch's
 * tolerance or iterations; v1 = v0 + dv, x1 = x0 + h v1. Out of line on a
 * GPU (AN_COLD). */
AN_COLD void an_implicit(const an_batch *b, an_state st, long long c, long long p0, long long n,
                         long long s0, long long ns, double h, double t, const double *x0,
                         const double *v0, double *x1, double *v1, double *f) {
    long long j0 = b->first_joint[c], nj = b->first_joint[c + 1] - j0;
    double *room = b->implicit + AN_IMPLICIT_ROOM * p0 + AN_IMPLICIT_SPRING * s0 +
                   AN_IMPLICIT_JOINT * j0;
    double *rhs = room, *diag = room + 3 * n, *bv = room + 12 * n, *xs = room + 15 * n;
    double *r = room + 18 * n, *z = room + 21 * n, *p = room + 24 * n, *q = room + 27 * n;
    double *pre = room + 30 * n, *sr = room + AN_IMPLICIT_ROOM * n;
    double *jr = sr + AN_IMPLICIT_SPRING * ns;
    an_forces(b, st, c, p0, n, s0, ns, x0, v0, f, h, t);
    for (long long k = 0; k < AN_IMPLICIT_ROOM * n + AN_IMPLICIT_SPRING * ns + AN_IMPLICIT_JOINT * nj;
         k++) {
        room[k] = 0.0;
    }
    /* Springs: Jacobian::central. */
    for (long long s = s0; s < s0 + ns; s++) {
        double nv[3], alpha, beta, along, across;
        if (!an_jac_spring(b, st, s0, s, x0, h, nv, &alpha, &beta, &along, &across)) {
            continue;
        }
        long long a = st.sa[s - s0], e = st.sb[s - s0];
        double u[3], kv[3], sm[9], *stored = sr + AN_IMPLICIT_SPRING * (s - s0);
        stored[0] = 1.0;
        for (int k = 0; k < 3; k++) {
            stored[1 + k] = nv[k];
        }
        stored[4] = alpha;
        stored[5] = beta;
        for (int k = 0; k < 3; k++) {
            u[k] = v0[3 * a + k] - v0[3 * e + k];
        }
        double nu = an_dot(nv, u);
        for (int k = 0; k < 3; k++) {
            kv[k] = -(nv[k] * (nu * (along - across)) + u[k] * across) * (h * h);
            rhs[3 * a + k] += kv[k];
            rhs[3 * e + k] -= kv[k];
        }
        for (int col = 0; col < 3; col++) {
            for (int row = 0; row < 3; row++) {
                sm[3 * col + row] = nv[row] * (nv[col] * alpha) + (row == col ? beta : 0.0);
            }
        }
        for (int k = 0; k < 9; k++) {
            diag[9 * a + k] += sm[k];
            diag[9 * e + k] += sm[k];
        }
    }
    /* Angle joints: Jacobian::block over their three particles. */
    for (long long qj = j0; qj < j0 + nj; qj++) {
        double g[9], *stored = jr + AN_IMPLICIT_JOINT * (qj - j0);
        if (!an_jac_joint(b, qj, x0, g)) {
            continue;
        }
        stored[0] = 1.0;
        long long ids[3] = {b->joint_a[qj], b->joint_j[qj], b->joint_b[qj]};
        int k = 0;
        for (int u = 0; u < 3; u++) {
            for (int w = 0; w < 3; w++) {
                double dfdx[9], dfdv[9], sb[9];
                an_jac_joint_block(b, qj, g, u, w, dfdx, dfdv);
                an_jac_block(rhs, diag, v0, ids[u], ids[w], dfdx, dfdv, h, sb);
                if (u != w) {
                    for (int d = 0; d < 9; d++) {
                        stored[1 + 9 * k + d] = sb[d];
                    }
                    k++;
                }
            }
        }
    }
    /* Fluids: their drag's df/dv about every particle (fluid.rs). */
    for (long long qf = b->first_fluid[c]; qf < b->first_fluid[c + 1]; qf++) {
        double drag = b->fluid_drag[qf];
        const double *cur = b->fluid_current + AN_CURRENT * qf;
        for (long long i = 0; i < n; i++) {
            double uc[3], vr[3];
            an_current(b, cur, x0 + 3 * i, t, uc);
            for (int k = 0; k < 3; k++) {
                vr[k] = v0[3 * i + k] - uc[k];
            }
            double speed = sqrt(an_dot(vr, vr));
            if (speed > 0.0) {
                double r0 = st.r[i], uu[3], dfdx[9], dfdv[9], sb[9];
                for (int k = 0; k < 3; k++) {
                    uu[k] = vr[k] / speed;
                }
                double scale = drag * r0 * r0 * speed;
                for (int col = 0; col < 3; col++) {
                    for (int row = 0; row < 3; row++) {
                        dfdx[3 * col + row] = 0.0;
                        dfdv[3 * col + row] =
                            (uu[row] * uu[col] + (row == col ? 1.0 : 0.0)) * scale;
                    }
                }
                an_jac_block(rhs, diag, v0, i, i, dfdx, dfdv, h, sb);
            }
        }
    }
    for (long long i = 0; i < n; i++) {
        if (b->fixed[p0 + i]) {
            continue;
        }
        for (int k = 0; k < 3; k++) {
            bv[3 * i + k] = f[3 * i + k] * h + rhs[3 * i + k];
        }
        /* (M + S_ii).inverse(), as glam inverts: the columns' cross
         * products over the determinant, transposed. */
        double m[9], t0[3], t1[3], t2[3];
        for (int col = 0; col < 3; col++) {
            for (int row = 0; row < 3; row++) {
                m[3 * col + row] = (row == col ? st.m[i] : 0.0) + diag[9 * i + 3 * col + row];
            }
        }
        an_cross(m + 3, m + 6, t0);
        an_cross(m + 6, m, t1);
        an_cross(m, m + 3, t2);
        double inv_det = 1.0 / an_dot(m, t0);
        for (int col = 0; col < 3; col++) {
            pre[9 * i + 3 * col] = t0[col] * inv_det;
            pre[9 * i + 3 * col + 1] = t1[col] * inv_det;
            pre[9 * i + 3 * col + 2] = t2[col] * inv_det;
        }
    }
    /* conjugate_gradients */
    for (long long k = 0; k < 3 * n; k++) {
        r[k] = bv[k];
    }
    for (long long i = 0; i < n; i++) {
        an_m3_mul(pre + 9 * i, r + 3 * i, z + 3 * i);
    }
    for (long long k = 0; k < 3 * n; k++) {
        p[k] = z[k];
    }
    double rz = an_cg_dot(r, z, n);
    double stop = rz * b->solver_tolerance * b->solver_tolerance;
    if (rz == rz && rz > 0.0) {
        for (long long it = 1; it <= b->solver_iterations; it++) {
            an_cg_apply(b, st, c, n, ns, sr, jr, diag, p, q);
            for (long long i = 0; i < n; i++) {
                if (b->fixed[p0 + i]) {
                    q[3 * i] = 0.0;
                    q[3 * i + 1] = 0.0;
                    q[3 * i + 2] = 0.0;
                }
            }
            double pq = an_cg_dot(p, q, n);
            if (pq != pq || pq <= 0.0) {
                break;
            }
            double alpha = rz / pq;
            for (long long k = 0; k < 3 * n; k++) {
                xs[k] += alpha * p[k];
                r[k] -= alpha * q[k];
            }
            for (long long i = 0; i < n; i++) {
                an_m3_mul(pre + 9 * i, r + 3 * i, z + 3 * i);
            }
            double rz_new = an_cg_dot(r, z, n);
            if (rz_new <= stop) {
                break;
            }
            double beta = rz_new / rz;
            rz = rz_new;
            for (long long k = 0; k < 3 * n; k++) {
                p[k] = z[k] + beta * p[k];
            }
        }
    }
    for (long long k = 0; k < 3 * n; k++) {
        double v = v0[k] + xs[k];
        v1[k] = v;
        x1[k] = x0[k] + h * v;
    }
}
#endif

/* One integrator step of size h from (x0, v0) at time t into (x1, v1)
 * (the files of integrators/, each stage's forces at their times); f,
 * dx, dv: scratch. */
AN_FN void an_integrate(const an_batch *b, an_state st, long long c, long long p0, long long n,
                        long long s0, long long ns, double h, double t, const double *x0,
                        const double *v0, double *x1, double *v1, double *f, double *dx,
                        double *dv) {
    long long m3 = 3 * n;
    const double *w = st.w;
    switch (AN_INTEGRATOR(b)) {
    case AN_EULER:
        an_forces(b, st, c, p0, n, s0, ns, x0, v0, f, h, t);
        for (long long k = 0; k < m3; k++) {
            x1[k] = x0[k] + h * v0[k];
            v1[k] = v0[k] + (h * w[k / 3]) * f[k];
        }
        break;
    case AN_MIDPOINT: {
        double half = 0.5 * h;
        an_forces(b, st, c, p0, n, s0, ns, x0, v0, f, h, t);
        for (long long k = 0; k < m3; k++) {
            x1[k] = x0[k] + half * v0[k];
            v1[k] = v0[k] + (half * w[k / 3]) * f[k];
        }
        an_forces(b, st, c, p0, n, s0, ns, x1, v1, f, h, t + half);
        for (long long k = 0; k < m3; k++) {
            double vm = v1[k];
            x1[k] = x0[k] + h * vm;
            v1[k] = v0[k] + (h * w[k / 3]) * f[k];
        }
        break;
    }
    case AN_RK4: {
        double half = 0.5 * h;
        an_forces(b, st, c, p0, n, s0, ns, x0, v0, f, h, t);
        for (long long k = 0; k < m3; k++) {
            double a = f[k] * w[k / 3];
            dx[k] = v0[k];
            dv[k] = a;
            x1[k] = x0[k] + v0[k] * half;
            v1[k] = v0[k] + a * half;
        }
        for (int stage = 0; stage < 2; stage++) {
            double to = stage == 0 ? half : h;
            an_forces(b, st, c, p0, n, s0, ns, x1, v1, f, h, t + half);
            for (long long k = 0; k < m3; k++) {
                double a = f[k] * w[k / 3];
                double vi = v1[k];
                dx[k] += vi * 2.0;
                dv[k] += a * 2.0;
                x1[k] = x0[k] + vi * to;
                v1[k] = v0[k] + a * to;
            }
        }
        an_forces(b, st, c, p0, n, s0, ns, x1, v1, f, h, t + h);
        double sixth = h / 6.0;
        for (long long k = 0; k < m3; k++) {
            double a = f[k] * w[k / 3];
            double xe = x0[k] + (dx[k] + v1[k]) * sixth;
            double ve = v0[k] + (dv[k] + a) * sixth;
            x1[k] = xe;
            v1[k] = ve;
        }
        break;
    }
#if !defined(__CUDACC_RTC__) || defined(AN_WITH_IMPLICIT)
    /* On a GPU only in the kernels compiled for implicit batches: its
     * call alone spills every kernel's registers. */
    case AN_IMPLICIT:
        an_implicit(b, st, c, p0, n, s0, ns, h, t, x0, v0, x1, v1, f);
        break;
#endif
    default: /* AN_SYMPLECTIC */
        an_forces(b, st, c, p0, n, s0, ns, x0, v0, f, h, t);
        for (long long k = 0; k < m3; k++) {
            double vk = v0[k] + f[k] * (h * w[k / 3]);
            v1[k] = vk;
            x1[k] = x0[k] + vk * h;
        }
        break;
    }
}

/* What the floor makes of a trial (events/floor_collision.rs, `state`). */
enum { AN_NONE = 0, AN_OCCURRING = 1, AN_MISSED = 2 };

/* The flat floor's check of a trial: the deepest sphere below the plane. */
AN_FN int an_floor_check(const an_batch *b, an_state st, long long n, const double *x1) {
    double deepest = 0.0;
    int any = 0;
    for (long long i = 0; i < n; i++) {
        double gap = x1[3 * i + 1] - st.r[i];
        if (gap < 0.0 && st.w[i] != 0.0) {
            any = 1;
            deepest = deepest < gap ? deepest : gap;
        }
    }
    if (!any) {
        return AN_NONE;
    }
    return deepest < -b->envelope ? AN_MISSED : AN_OCCURRING;
}

/* The flat floor's check's records of a trial of step h (`Hit`): for
 * each sphere below the plane its mean normal acceleration over the
 * trial, NaN for the others, in rec[3 i]. An event handled before the
 * floor (a plane constraint) may move the trial after the check: the
 * floor then handles the spheres its check found, with their
 * accelerations as found. */
AN_FN void an_floor_note(an_state st, long long n, double h, const double *v0, const double *x1,
                         const double *v1, double *rec) {
    for (long long i = 0; i < n; i++) {
        double gap = x1[3 * i + 1] - st.r[i];
        int hit = gap < 0.0 && st.w[i] != 0.0;
        rec[3 * i] = hit ? (v1[3 * i + 1] - v0[3 * i + 1]) / h : an_from_bits(0x7ff8000000000000ULL);
    }
}

/* The flat floor's handling of a trial of step h (part of the step
 * `step`): each sphere below the plane moved up onto it and its impact
 * resolved (`resolve` and `normal_speed`); the spheres and accelerations
 * of `rec` (an_floor_note) where it is not NULL. */
AN_FN void an_floor_handle(const an_batch *b, an_state st, long long p0, long long n, double h,
                           double step, const double *v0, double *x1, double *v1,
                           const double *rec) {
    for (long long i = 0; i < n; i++) {
        long long p = p0 + i;
        double r = st.r[i];
        double accel;
        if (rec) {
            accel = rec[3 * i];
            if (accel != accel) {
                continue;
            }
        } else {
            double gap = x1[3 * i + 1] - r;
            if (!(gap < 0.0) || st.w[i] == 0.0) {
                continue;
            }
            accel = (v1[3 * i + 1] - v0[3 * i + 1]) / h;
        }
        double shift = b->flight_shift * accel * step;
        double e = b->restitution[p];
        double depth = r - x1[3 * i + 1];
        x1[3 * i + 1] = r;
        double vn = v1[3 * i + 1];
        double under = vn * vn + 2.0 * accel * depth;
        double at_plane = sqrt(under > 0.0 ? under : 0.0);
        if (vn >= 0.0) {
            v1[3 * i + 1] = at_plane;
            continue;
        }
        double wv = vn + shift;
        double wunder = wv * wv + 2.0 * accel * depth;
        double w_at_plane = sqrt(wunder > 0.0 ? wunder : 0.0);
        double r1 = e * at_plane, r2 = e * w_at_plane - shift;
        double rebound = r1 < r2 ? r1 : r2;
        /* (+inf as bits: NVRTC has no math.h, hence no INFINITY) */
        double flight = accel < 0.0 ? 2.0 * rebound / -accel : an_from_bits(0x7ff0000000000000ULL);
        v1[3 * i + 1] = (at_plane < b->rest_speed || flight <= step) ? 0.0 : rebound;
    }
}

/* The floor's check of a trial on terrain (events/floor_collision.rs,
 * `check_terrain`): the deepest sphere below the surface. */
AN_COLD int an_terrain_check(const an_batch *b, an_state st, long long n, const double *x1) {
    double deepest = 0.0;
    int any = 0;
    for (long long i = 0; i < n; i++) {
        double d, nrm[3];
        if (st.w[i] == 0.0 ||
            !an_probe(b->terrain, b->terrain_param, b->terrain_height, x1 + 3 * i, st.r[i], &d,
                      nrm)) {
            continue;
        }
        double gap = d - st.r[i];
        if (gap < 0.0) {
            any = 1;
            deepest = deepest < gap ? deepest : gap;
        }
    }
    if (!any) {
        return AN_NONE;
    }
    return deepest < -b->envelope ? AN_MISSED : AN_OCCURRING;
}

/* The floor's handling of a trial of step h on terrain (`resolve` off
 * the flat floor): each sphere below the surface moved out along the
 * normal at its nearest point, its normal speed resolved as on the flat
 * floor (`normal_speed`), and a sphere that the move lifts against
 * gravity, or whose rebound gains speed, slowed along the surface so
 * that it gains no energy. */
AN_COLD void an_terrain_handle(const an_batch *b, an_state st, long long p0, long long n, double h,
                             double step, const double *v0, double *x1, double *v1) {
    double g[3] = {0.0, 0.0, 0.0};
    if (b->gravity) {
        g[0] = b->gx;
        g[1] = b->gy;
        g[2] = b->gz;
    }
    for (long long i = 0; i < n; i++) {
        long long p = p0 + i;
        double r = st.r[i], d, nrm[3];
        double *x = x1 + 3 * i, *v = v1 + 3 * i;
        if (st.w[i] == 0.0 ||
            !an_probe(b->terrain, b->terrain_param, b->terrain_height, x, r, &d, nrm)) {
            continue;
        }
        double gap = d - r;
        if (!(gap < 0.0)) {
            continue;
        }
        double dv[3];
        for (int e = 0; e < 3; e++) {
            dv[e] = v[e] - v0[3 * i + e];
        }
        double accel = an_dot(dv, nrm) / h;
        double shift = b->flight_shift * accel * step;
        double e = b->restitution[p];
        double depth = -gap;
        for (int q = 0; q < 3; q++) {
            x[q] = x[q] + nrm[q] * depth;
        }
        double vn = an_dot(v, nrm);
        /* normal_speed */
        double under = vn * vn + 2.0 * accel * depth;
        double at_plane = sqrt(under > 0.0 ? under : 0.0);
        double after;
        if (vn >= 0.0) {
            after = at_plane;
        } else {
            double wv = vn + shift;
            double wunder = wv * wv + 2.0 * accel * depth;
            double w_at_plane = sqrt(wunder > 0.0 ? wunder : 0.0);
            double r1 = e * at_plane, r2 = e * w_at_plane - shift;
            double rebound = r1 < r2 ? r1 : r2;
            double flight = accel < 0.0 ? 2.0 * rebound / -accel : an_inf();
            after = (at_plane < b->rest_speed || flight <= step) ? 0.0 : rebound;
        }
        double change = after - vn;
        for (int q = 0; q < 3; q++) {
            v[q] = v[q] + nrm[q] * change;
        }
        double climb = -2.0 * an_dot(g, nrm) * depth;
        double excess = after * after - vn * vn + climb;
        if (excess > 0.0) {
            double slide[3];
            for (int q = 0; q < 3; q++) {
                slide[q] = v[q] - nrm[q] * after;
            }
            double slide2 = an_dot(slide, slide);
            if (slide2 > 0.0) {
                double keep = 1.0 - sqrt(an_max(slide2 - excess, 0.0) / slide2);
                for (int q = 0; q < 3; q++) {
                    v[q] = v[q] - slide[q] * keep;
                }
            }
        }
    }
}

/* Which of creature c's planes a trial leaves (events/plane_constraint.rs
 * `check`: a particle whose offset from the plane, or whose velocity,
 * along its normal is not 0), bit k for its k-th plane. */
AN_FN unsigned long long an_planes_check(const an_batch *b, long long c, const double *x1,
                                         const double *v1) {
    unsigned long long off = 0;
    long long k0 = b->first_plane[c];
    for (long long k = k0; AN_HAS(b, AN_P_PLANES) && k < b->first_plane[c + 1]; k++) {
        const double *pt = b->plane_param + 7 * k, *nrm = pt + 3;
        for (long long j = b->plane_first_particle[k]; j < b->plane_first_particle[k + 1]; j++) {
            long long i = b->plane_particle[j];
            double d[3];
            for (int e = 0; e < 3; e++) {
                d[e] = x1[3 * i + e] - pt[e];
            }
            if (an_dot(d, nrm) != 0.0 || an_dot(v1 + 3 * i, nrm) != 0.0) {
                off |= 1ULL << (k - k0);
                break;
            }
        }
    }
    return off;
}

/* Whether any of creature c's planes in `off` comes before the floor's
 * collisions. */
AN_FN int an_planes_before(const an_batch *b, long long c, unsigned long long off) {
    long long k0 = b->first_plane[c];
    for (long long k = k0; off != 0 && k < b->first_plane[c + 1]; k++) {
        if (((off >> (k - k0)) & 1ULL) && b->plane_param[7 * k + 6] != 0.0) {
            return 1;
        }
    }
    return 0;
}

/* `handle` of creature c's planes in `off` that come before the floor's
 * collisions (before = 1) or after them (0): each particle's position and
 * velocity projected onto the plane, x -= n ((x - point) . n), v -= n (v . n). */
AN_FN void an_planes_handle(const an_batch *b, long long c, unsigned long long off, int before,
                            double *x1, double *v1) {
    long long k0 = b->first_plane[c];
    for (long long k = k0; k < b->first_plane[c + 1]; k++) {
        const double *pt = b->plane_param + 7 * k, *nrm = pt + 3;
        if (!((off >> (k - k0)) & 1ULL) || (pt[6] != 0.0) != (before != 0)) {
            continue;
        }
        for (long long j = b->plane_first_particle[k]; j < b->plane_first_particle[k + 1]; j++) {
            long long i = b->plane_particle[j];
            double *x = x1 + 3 * i, *v = v1 + 3 * i, d[3];
            for (int e = 0; e < 3; e++) {
                d[e] = x[e] - pt[e];
            }
            double along = an_dot(d, nrm);
            for (int e = 0; e < 3; e++) {
                x[e] = x[e] - nrm[e] * along;
            }
            double speed = an_dot(v, nrm);
            for (int e = 0; e < 3; e++) {
                v[e] = v[e] - nrm[e] * speed;
            }
        }
    }
}

/* Whether every coordinate is finite. */
AN_FN int an_finite(const double *x, long long m3) {
    for (long long k = 0; k < m3; k++) {
        if (!(x[k] - x[k] == 0.0)) {
            return 0;
        }
    }
    return 1;
}

/* Whether a creature with these contact numbers has sphere contact. On a
 * GPU its code is in a kernel of its own, compiled with AN_SPHERES for
 * the batches that have it (src/cuda.rs): in the others it took the flat
 * floor's evaluation from 168 registers to 224 (bench/nvrtc.py). The C
 * compiled for the CPU always has it. */
#if defined(__CUDACC_RTC__) && !defined(AN_SPHERES)
#define AN_HAS_SPHERES(cp) 0
#else
#define AN_HAS_SPHERES(cp) ((cp)[0] != 0.0)
#endif

/* One step of creature c (world/step.rs: a trial of the whole step;
 * after a missed collision, the step again in pieces, halved while one is
 * missed down to 1/1024 of the step, and grown back once they line up).
 * Returns 1; or 0 where the state would stop being finite, leaving it at
 * its last finite state, as the engine's step refuses it. */
AN_FN int an_step_once(const an_batch *b, an_state st, long long c, double t0) {
    long long p0 = b->first_particle[c], n = b->first_particle[c + 1] - p0;
    long long s0 = b->first_spring[c], ns = b->first_spring[c + 1] - s0;
    long long m3 = 3 * n;
    double *x = st.x, *v = st.v;
    double *sc = st.sc;
    double *f = sc, *x1 = sc + m3, *v1 = sc + 2 * m3, *dx = sc + 3 * m3, *dv = sc + 4 * m3;
    double dt = b->dt;
    const long long total = 1LL << 10; /* MAX_BACKTRACK_DEPTH */
    long long done = 0, piece = total;
    /* Sphere contact (spheres.h), after the floor among the world's events. */
    const double *cp = b->contact_param + 4 * c;
    int contact = AN_HAS_SPHERES(cp);
    an_spheres sp = {0};
    if (contact) {
        long long e0 = b->first_excluded[c];
        sp.r = st.r;
        sp.w = st.w;
        sp.e = b->restitution + p0;
        sp.mu_s = b->mu_s + p0;
        sp.mu_k = b->mu_k + p0;
        sp.excluded = b->excluded + e0;
        sp.n_excluded = b->first_excluded[c + 1] - e0;
        sp.envelope = cp[1];
        sp.rest_speed = cp[2];
        sp.restitution = cp[3];
        sp.step = dt;
        sp.held = b->floor != 0;
        sp.slots = b->contact_slot + b->first_slot[c];
        sp.pair = sp.slots + 4 * n;
        sp.pairs = 0;
    }
    while (done < total) {
        double h = piece == total ? dt : dt * ((double)piece / (double)total);
        /* (World::step: the whole step from t0, a piece from its start.) */
        double t = piece == total ? t0 : t0 + dt * ((double)done / (double)total);
        an_integrate(b, st, c, p0, n, s0, ns, h, t, x, v, x1, v1, f, dx, dv);
        int state = !b->floor                  ? AN_NONE
                    : AN_ON_TERRAIN(b) ? an_terrain_check(b, st, n, x1)
                                              : an_floor_check(b, st, n, x1);
        /* (A trial the floor missed is taken again in pieces whatever the
         * spheres say, unless it cannot be split.) */
        int spheres = AN_NONE;
        if (contact && (state != AN_MISSED || piece == 1)) {
            spheres = an_spheres_check(&sp, n, x, x1);
        }
        if (state == AN_MISSED || spheres == AN_MISSED) {
            if (piece == total) {
                piece = total / 2; /* the step again, in pieces */
                continue;
            }
            if (piece > 1) {
                piece /= 2;
                continue;
            }
            /* Cannot split further: each handled as if occurring. */
            state = state == AN_MISSED ? AN_OCCURRING : state;
        }
        /* Every event checks the trial before any handles it, then each
         * handles it in the world's order. */
        unsigned long long off = an_planes_check(b, c, x1, v1);
        const double *rec = 0;
        if (an_planes_before(b, c, off)) {
            if (state != AN_NONE) {
                an_floor_note(st, n, h, v, x1, v1, f);
                rec = f; /* (the forces are spent) */
            }
            an_planes_handle(b, c, off, 1, x1, v1);
        }
        if (state != AN_NONE && AN_ON_TERRAIN(b)) {
            an_terrain_handle(b, st, p0, n, h, dt, v, x1, v1); /* (no planes on terrain) */
        } else if (state != AN_NONE) {
            an_floor_handle(b, st, p0, n, h, dt, v, x1, v1, rec);
        }
        if (spheres != AN_NONE) {
            an_spheres_handle(&sp, x1, v1); /* (no planes with sphere contact) */
        }
        an_planes_handle(b, c, off, 0, x1, v1);
        if (!an_finite(x1, m3) || !an_finite(v1, m3)) {
            return 0;
        }
        for (long long k = 0; k < m3; k++) {
            x[k] = x1[k];
            v[k] = v1[k];
        }
        if (piece == total) {
            break;
        }
        done += piece;
        if (piece < total && done % (2 * piece) == 0) {
            piece *= 2;
        }
    }
    return 1;
}

/* `steps` steps of creature c, from its clock's time. A non-finite state stops the creature at
 * its last finite state; `failed[c]` records the step (1-based, counted
 * over every run of the batch). */
AN_FN void an_step_creature(const an_batch *b, an_state st, long long c, long long steps) {
    if (b->failed[c] != 0) {
        return;
    }
    double *clock = b->clock + 2 * c;
    for (long long step = 0; step < steps; step++) {
        /* Each step from the world's time (a reef's currents ask it). */
        if (!an_step_once(b, st, c, clock[0])) {
            b->failed[c] = b->steps_before + step + 1;
            return;
        }
        /* The clock advanced as the engine's: compensated summation. */
        double y = b->dt - clock[1];
        double t = clock[0] + y;
        clock[1] = (t - clock[0]) - y;
        clock[0] = t;
    }
}

/* The most particles, and springs, a creature may have for one thread to
 * hold its state (positions, velocities, the step's scratch, inverse mass,
 * mass and radius: 24 doubles a particle; each spring's ends, stiffness
 * and damping) in arrays of its own, an_local_store (9 KiB). On a GPU
 * these live in the thread's local memory, which the hardware interleaves
 * thread by thread: a warp's 32 creatures read and write their k-th
 * coordinate (or spring) in one transaction, where in the batch's arrays
 * (each creature's run contiguous) a warp touches 32 scattered places. (A
 * spring's rest length, which muscles move, stays in the batch's arrays.) */
#define AN_LOCAL 32
#define AN_LOCAL_SPRINGS 128

typedef struct {
    double x[3 * AN_LOCAL], v[3 * AN_LOCAL], sc[15 * AN_LOCAL];
    double w[AN_LOCAL], m[AN_LOCAL], r[AN_LOCAL];
    int sa[AN_LOCAL_SPRINGS], sb[AN_LOCAL_SPRINGS];
    double k[AN_LOCAL_SPRINGS], d[AN_LOCAL_SPRINGS];
} an_local_store;

/* Creature c's state: copied into m and held there where the creature has
 * at most AN_LOCAL particles and AN_LOCAL_SPRINGS springs (*fits 1), else
 * in the batch's arrays (*fits 0, nothing copied). */
AN_FN an_state an_local(const an_batch *b, long long c, an_local_store *m, int *fits) {
    long long p0 = b->first_particle[c], m3 = 3 * (b->first_particle[c + 1] - p0);
    long long s0 = b->first_spring[c], ns = b->first_spring[c + 1] - s0;
    *fits = m3 <= 3 * AN_LOCAL && ns <= AN_LOCAL_SPRINGS;
    if (!*fits) {
        return an_batch_state(b, c);
    }
    for (long long k = 0; k < m3; k++) {
        m->x[k] = b->pos[3 * p0 + k];
        m->v[k] = b->vel[3 * p0 + k];
    }
    for (long long i = 0; i < m3 / 3; i++) {
        m->w[i] = b->inv_mass[p0 + i];
        m->m[i] = b->mass[p0 + i];
        m->r[i] = b->radius[p0 + i];
    }
    for (long long s = 0; s < ns; s++) {
        m->sa[s] = b->spring_a[s0 + s];
        m->sb[s] = b->spring_b[s0 + s];
        m->k[s] = b->stiffness[s0 + s];
        m->d[s] = b->damping[s0 + s];
    }
    an_state st = {m->x, m->v, m->sc, m->sa, m->sb, m->k, m->d, m->w, m->m, m->r};
    return st;
}

/* The positions and velocities held by an_local copied back into the
 * batch's arrays (the constants were only read). */
AN_FN void an_local_done(const an_batch *b, long long c, an_state st) {
    long long p0 = b->first_particle[c], m3 = 3 * (b->first_particle[c + 1] - p0);
    for (long long k = 0; k < m3; k++) {
        b->pos[3 * p0 + k] = st.x[k];
        b->vel[3 * p0 + k] = st.v[k];
    }
}

/* Creature c stepped `steps` times, its state held in the batch's arrays
 * (local 0) or, where it fits, in the thread's own (local 1): the same
 * operations on the same numbers either way, so the same bits. */
AN_FN void an_step_in(const an_batch *b, long long c, long long steps, int local) {
    an_local_store m;
    int fits = 0;
    an_state st = local ? an_local(b, c, &m, &fits) : an_batch_state(b, c);
    an_step_creature(b, st, c, steps);
    if (fits) {
        an_local_done(b, c, st);
    }
}

#endif
