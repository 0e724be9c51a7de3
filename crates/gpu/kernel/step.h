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
 * (their atan2 ported from the `libm` crate, libm.h), torque joints, still
 * fluids on every particle, and the explicit integrators (Euler, midpoint, RK4, symplectic Euler), in
 * worlds without events. Everything else is refused when a world is packed
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

/* Integrators, as IntegratorKind's order in the engine. */
enum { AN_EULER = 0, AN_MIDPOINT = 1, AN_RK4 = 2, AN_SYMPLECTIC = 3 };

/*
 * A batch of creatures of any mix of sizes, as structures of arrays with
 * per-creature offsets: creature c owns particles first_particle[c] ..
 * first_particle[c + 1] - 1 and springs first_spring[c] ..
 * first_spring[c + 1] - 1, whose ends are indices within the creature.
 * Angle joints (first_joint, ends a and b, joint j), torque joints
 * (first_motor, end and joint, unit axis, torque) and still fluids on
 * every particle (first_fluid) likewise. Vectors are
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
    const double *rest_length;
    double *scratch;
    const long long *first_joint;
    const int *joint_a;
    const int *joint_j;
    const int *joint_b;
    const double *joint_stiffness;
    const double *joint_damping;
    const double *joint_rest;
    const long long *first_motor;
    const int *motor_end;
    const int *motor_joint;
    const double *motor_axis; /* 3 per motor */
    const double *motor_torque;
    const long long *first_fluid;
    const double *fluid_drag;    /* -0.5 C rho pi, as the engine forms it */
    const double *fluid_density;
    const double *radius;
    const double *volume;
    double gx, gy, gz;
    int gravity; /* 1: gravity pulls every particle; 0: none */
    int integrator;
    double dt;
} an_batch;

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
AN_FN void an_angle_joints(const an_batch *b, long long j0, long long nj, const double *x,
                           const double *v, double *f) {
    for (long long q = j0; q < j0 + nj; q++) {
        long long a = b->joint_a[q], j = b->joint_j[q], e = b->joint_b[q];
        double ra[3], rb[3], normal[3], pa[3], pb[3], va[3], vb[3];
        for (int k = 0; k < 3; k++) {
            ra[k] = x[3 * a + k] - x[3 * j + k];
            rb[k] = x[3 * e + k] - x[3 * j + k];
        }
        double la2 = an_dot(ra, ra), lb2 = an_dot(rb, rb);
        an_cross(ra, rb, normal);
        double n2 = an_dot(normal, normal);
        if (n2 <= 1e-24 * la2 * lb2 || la2 == 0.0 || lb2 == 0.0) {
            continue; /* collinear or degenerate: no plane of bending */
        }
        double nl = sqrt(n2);
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

/* Torque joints m0 .. m0 + nm - 1 (forces/torque_joint.rs, `apply`). */
AN_FN void an_motors(const an_batch *b, long long m0, long long nm, const double *x, double *f) {
    for (long long q = m0; q < m0 + nm; q++) {
        double torque = b->motor_torque[q];
        if (torque == 0.0) {
            continue;
        }
        long long e = b->motor_end[q], j = b->motor_joint[q];
        const double *axis = b->motor_axis + 3 * q;
        double r[3], perp[3], c[3];
        for (int k = 0; k < 3; k++) {
            r[k] = x[3 * e + k] - x[3 * j + k];
        }
        double along = an_dot(r, axis);
        for (int k = 0; k < 3; k++) {
            perp[k] = r[k] - axis[k] * along;
        }
        double l2 = an_dot(perp, perp);
        if (l2 == 0.0) {
            continue; /* the end sits on the axis: no lever arm */
        }
        an_cross(axis, perp, c);
        double s = torque / l2;
        for (int k = 0; k < 3; k++) {
            double fk = c[k] * s;
            f[3 * e + k] += fk;
            f[3 * j + k] -= fk;
        }
    }
}

/* Still fluids q0 .. q0 + nq - 1 on every particle of the creature
 * (forces/fluid.rs, `force_on`): quadratic drag and buoyancy. */
AN_FN void an_fluids(const an_batch *b, long long p0, long long n, long long q0, long long nq,
                     const double *v, double *f) {
    double g[3] = {b->gx, b->gy, b->gz};
    if (!b->gravity) {
        g[0] = 0.0;
        g[1] = 0.0;
        g[2] = 0.0;
    }
    for (long long q = q0; q < q0 + nq; q++) {
        double drag = b->fluid_drag[q], density = b->fluid_density[q];
        for (long long i = 0; i < n; i++) {
            double r = b->radius[p0 + i];
            const double *vr = v + 3 * i;
            double speed = sqrt(an_dot(vr, vr));
            double s = drag * r * r * speed;
            double lift = -b->volume[p0 + i] * density;
            for (int k = 0; k < 3; k++) {
                f[3 * i + k] += vr[k] * s + g[k] * lift;
            }
        }
    }
}

/* The forces on a creature's particles at positions x, velocities v, in
 * the engine's order (force_set.rs, `evaluate`): gravity, springs, angle
 * joints, torque joints, fluids. */
AN_FN void an_forces(const an_batch *b, long long c, long long p0, long long n, long long s0,
                     long long ns, const double *x, const double *v, double *f) {
    for (long long i = 0; i < n; i++) {
        if (b->gravity) {
            double m = b->mass[p0 + i];
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
        long long a = b->spring_a[s], e = b->spring_b[s];
        double dx = x[3 * e] - x[3 * a];
        double dy = x[3 * e + 1] - x[3 * a + 1];
        double dz = x[3 * e + 2] - x[3 * a + 2];
        double len = sqrt((dx * dx + dy * dy) + dz * dz);
        double inv = len > 0.0 ? 1.0 / len : 0.0;
        double nx = dx * inv, ny = dy * inv, nz = dz * inv;
        double wx = v[3 * e] - v[3 * a];
        double wy = v[3 * e + 1] - v[3 * a + 1];
        double wz = v[3 * e + 2] - v[3 * a + 2];
        double t = b->stiffness[s] * (len - b->rest_length[s])
                 + b->damping[s] * ((wx * nx + wy * ny) + wz * nz);
        double fx = nx * t, fy = ny * t, fz = nz * t;
        f[3 * a] += fx;
        f[3 * a + 1] += fy;
        f[3 * a + 2] += fz;
        f[3 * e] -= fx;
        f[3 * e + 1] -= fy;
        f[3 * e + 2] -= fz;
    }
    long long j0 = b->first_joint[c], m0 = b->first_motor[c];
    an_angle_joints(b, j0, b->first_joint[c + 1] - j0, x, v, f);
    an_motors(b, m0, b->first_motor[c + 1] - m0, x, f);
    long long q0 = b->first_fluid[c];
    an_fluids(b, p0, n, q0, b->first_fluid[c + 1] - q0, v, f);
}

/* `steps` steps of creature c. */
AN_FN void an_step_creature(const an_batch *b, long long c, long long steps) {
    long long p0 = b->first_particle[c], n = b->first_particle[c + 1] - p0;
    long long s0 = b->first_spring[c], ns = b->first_spring[c + 1] - s0;
    long long m3 = 3 * n;
    double *x = b->pos + 3 * p0, *v = b->vel + 3 * p0;
    const double *w = b->inv_mass + p0;
    double *sc = b->scratch + 15 * p0;
    double *f = sc, *x0 = sc + m3, *v0 = sc + 2 * m3, *dx = sc + 3 * m3, *dv = sc + 4 * m3;
    double h = b->dt;
    for (long long step = 0; step < steps; step++) {
        switch (b->integrator) {
        case AN_EULER:
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double wk = w[k / 3];
                double vk = v[k];
                x[k] = x[k] + h * vk;
                v[k] = vk + (h * wk) * f[k];
            }
            break;
        case AN_MIDPOINT: {
            double half = 0.5 * h;
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                x0[k] = x[k];
                v0[k] = v[k];
                x[k] = x0[k] + half * v0[k];
                v[k] = v0[k] + (half * w[k / 3]) * f[k];
            }
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double vm = v[k];
                x[k] = x0[k] + h * vm;
                v[k] = v0[k] + (h * w[k / 3]) * f[k];
            }
            break;
        }
        case AN_RK4: {
            double half = 0.5 * h;
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double a = f[k] * w[k / 3];
                x0[k] = x[k];
                v0[k] = v[k];
                dx[k] = v0[k];
                dv[k] = a;
                x[k] = x0[k] + v0[k] * half;
                v[k] = v0[k] + a * half;
            }
            for (int stage = 0; stage < 2; stage++) {
                double to = stage == 0 ? half : h;
                an_forces(b, c, p0, n, s0, ns, x, v, f);
                for (long long k = 0; k < m3; k++) {
                    double a = f[k] * w[k / 3];
                    double vi = v[k];
                    dx[k] += vi * 2.0;
                    dv[k] += a * 2.0;
                    x[k] = x0[k] + vi * to;
                    v[k] = v0[k] + a * to;
                }
            }
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            double sixth = h / 6.0;
            for (long long k = 0; k < m3; k++) {
                double a = f[k] * w[k / 3];
                double x1 = x0[k] + (dx[k] + v[k]) * sixth;
                double v1 = v0[k] + (dv[k] + a) * sixth;
                x[k] = x1;
                v[k] = v1;
            }
            break;
        }
        default: /* AN_SYMPLECTIC */
            an_forces(b, c, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double vk = v[k] + f[k] * (h * w[k / 3]);
                v[k] = vk;
                x[k] = x[k] + vk * h;
            }
            break;
        }
    }
}

#endif
