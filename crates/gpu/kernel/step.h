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
 * Covered today: particles, uniform gravity, damped springs, and the
 * explicit integrators (Euler, midpoint, RK4, symplectic Euler), in worlds
 * without events. Everything else is refused when a world is packed
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

/* Integrators, as IntegratorKind's order in the engine. */
enum { AN_EULER = 0, AN_MIDPOINT = 1, AN_RK4 = 2, AN_SYMPLECTIC = 3 };

/*
 * A batch of creatures of any mix of sizes, as structures of arrays with
 * per-creature offsets: creature c owns particles first_particle[c] ..
 * first_particle[c + 1] - 1 and springs first_spring[c] ..
 * first_spring[c + 1] - 1, whose ends are indices within the creature.
 * Vectors are stored x, y, z per particle. `scratch` holds 15 doubles per
 * particle (force, and RK4's start and sums).
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
    double gx, gy, gz;
    int gravity; /* 1: gravity pulls every particle; 0: none */
    int integrator;
    double dt;
} an_batch;

/* The forces on a creature's particles at positions x, velocities v. */
AN_FN void an_forces(const an_batch *b, long long p0, long long n, long long s0, long long ns,
                     const double *x, const double *v, double *f) {
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
        long long a = b->spring_a[s], c = b->spring_b[s];
        double dx = x[3 * c] - x[3 * a];
        double dy = x[3 * c + 1] - x[3 * a + 1];
        double dz = x[3 * c + 2] - x[3 * a + 2];
        double len = sqrt((dx * dx + dy * dy) + dz * dz);
        double inv = len > 0.0 ? 1.0 / len : 0.0;
        double nx = dx * inv, ny = dy * inv, nz = dz * inv;
        double wx = v[3 * c] - v[3 * a];
        double wy = v[3 * c + 1] - v[3 * a + 1];
        double wz = v[3 * c + 2] - v[3 * a + 2];
        double t = b->stiffness[s] * (len - b->rest_length[s])
                 + b->damping[s] * ((wx * nx + wy * ny) + wz * nz);
        double fx = nx * t, fy = ny * t, fz = nz * t;
        f[3 * a] += fx;
        f[3 * a + 1] += fy;
        f[3 * a + 2] += fz;
        f[3 * c] -= fx;
        f[3 * c + 1] -= fy;
        f[3 * c + 2] -= fz;
    }
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
            an_forces(b, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double wk = w[k / 3];
                double vk = v[k];
                x[k] = x[k] + h * vk;
                v[k] = vk + (h * wk) * f[k];
            }
            break;
        case AN_MIDPOINT: {
            double half = 0.5 * h;
            an_forces(b, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                x0[k] = x[k];
                v0[k] = v[k];
                x[k] = x0[k] + half * v0[k];
                v[k] = v0[k] + (half * w[k / 3]) * f[k];
            }
            an_forces(b, p0, n, s0, ns, x, v, f);
            for (long long k = 0; k < m3; k++) {
                double vm = v[k];
                x[k] = x0[k] + h * vm;
                v[k] = v0[k] + (h * w[k / 3]) * f[k];
            }
            break;
        }
        case AN_RK4: {
            double half = 0.5 * h;
            an_forces(b, p0, n, s0, ns, x, v, f);
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
                an_forces(b, p0, n, s0, ns, x, v, f);
                for (long long k = 0; k < m3; k++) {
                    double a = f[k] * w[k / 3];
                    double vi = v[k];
                    dx[k] += vi * 2.0;
                    dv[k] += a * 2.0;
                    x[k] = x0[k] + vi * to;
                    v[k] = v0[k] + a * to;
                }
            }
            an_forces(b, p0, n, s0, ns, x, v, f);
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
            an_forces(b, p0, n, s0, ns, x, v, f);
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
