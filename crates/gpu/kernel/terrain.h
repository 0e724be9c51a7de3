/*
 * The ground's shape in C (crates/engine/src/terrain.rs): a slope, a
 * flight of steps or a heightfield, for the floor's collisions, its
 * contact force and the clearance that sensors, measures and end rules
 * read. One question, as the engine asks it: the signed distance from a
 * sphere's centre to the surface and the surface's outward normal at the
 * nearest point (an_probe). Every operation in the engine's order (glam's
 * vector arithmetic written out), so that it gives the engine's bits.
 *
 * A batch shares one terrain (its floor): `kind` (AN_T_SLOPE ...), its
 * numbers `tp` and a heightfield's heights. The flat floor never comes
 * here: step.h keeps its own loops for it.
 */
#ifndef ANIMATS_TERRAIN_H
#define ANIMATS_TERRAIN_H

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define AN_FN __device__ static inline
#else
#include <math.h>
#define AN_FN static inline
#endif
#include "libm.h"

/* Whether batch b's floor has a shape. A GPU's kernel for batches on
 * the flat floor is compiled with AN_FLAT_ONLY, without terrain: with it
 * the step took 222 registers against 148 and the evaluation 255 (and
 * spilled) against 168, whether a batch has terrain or not
 * (bench/nvrtc.py reports both kernels); src/cuda.rs compiles the other
 * when a batch on terrain comes. */
#ifdef AN_FLAT_ONLY
#define AN_ON_TERRAIN(b) 0
#else
#define AN_ON_TERRAIN(b) ((b)->terrain != AN_T_FLAT)
#endif

/* Terrain's larger functions, called rather than inlined on a GPU. */
#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define AN_COLD __device__ static __noinline__
#else
#define AN_COLD static
#endif

/* The terrain's kinds, as pack.rs numbers them. Their numbers in `tp`:
 * a slope: its outward unit normal (Slope::normal, 3);
 * steps: direction x, y, z, start, height, depth, count (7);
 * a heightfield: origin x, z, cell, the cosine of its steepest slope
 * (Heightfield::steepest_cos), nx, nz (6), its heights apart. */
enum { AN_T_FLAT = 0, AN_T_SLOPE = 1, AN_T_STEPS = 2, AN_T_HEIGHTFIELD = 3 };

/* Rust's `as i64` of a double: NaN gives 0, and out of range the nearest
 * end. */
AN_FN long long an_to_i64(double x) {
    if (x != x) {
        return 0;
    }
    if (x >= 9223372036854775807.0) {
        return 0x7fffffffffffffffLL;
    }
    if (x <= -9223372036854775807.0) {
        return -0x7fffffffffffffffLL - 1;
    }
    return (long long)x;
}

/* f64::min and f64::max (the other where one is NaN). */
AN_FN double an_min(double a, double b) { return (a < b || b != b) ? a : b; }
AN_FN double an_max(double a, double b) { return (a > b || b != b) ? a : b; }

/* f64::clamp: below lo, lo; above hi, hi (NaN stays). */
AN_FN double an_clamp(double x, double lo, double hi) {
    if (x < lo) {
        x = lo;
    }
    if (x > hi) {
        x = hi;
    }
    return x;
}

/* +inf, without math.h's INFINITY (NVRTC has none). */
AN_FN double an_inf(void) { return an_from_bits(0x7ff0000000000000ULL); }

AN_FN double an_dot3(const double *a, const double *b) {
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}

/* Steps::tread: which tread lies under s (0 before the first riser,
 * count on top). */
AN_FN long long an_tread(const double *tp, double s) {
    if (s < tp[3]) {
        return 0;
    }
    long long k = an_to_i64(floor((s - tp[3]) / tp[5]));
    k = k < 0x7fffffffffffffffLL ? k + 1 : k;
    long long n = (long long)tp[6];
    return k < n ? k : n;
}

/* Steps::riser: riser j's place along the direction. */
AN_FN double an_riser(const double *tp, long long j) { return tp[3] + (double)(j - 1) * tp[5]; }

/* Steps::probe. */
AN_COLD int an_steps_probe(const double *tp, const double *p, double reach, double *dist,
                         double *normal) {
    const double *d = tp;
    double height = tp[4];
    double qx = p[0] * d[0] + p[2] * d[2], qy = p[1];
    long long k = an_tread(tp, qx);
    int below = qy < (double)k * height; /* profile(q.x) */
    long long n = (long long)tp[6];
    double best = an_inf(), nx = qx, ny = qy;
    long long lo = k - 2 > 0 ? k - 2 : 0, hi = k + 2 < n ? k + 2 : n;
    for (long long j = lo; j <= hi; j++) {
        double y = (double)j * height;
        double from = j == 0 ? -an_inf() : an_riser(tp, j);
        double to = j == n ? an_inf() : an_riser(tp, j + 1);
        double cx = an_clamp(qx, from, to), cy = y;
        double ex = qx - cx, ey = qy - cy;
        double d2 = ex * ex + ey * ey;
        if (d2 < best) {
            best = d2;
            nx = cx;
            ny = cy;
        }
        if (j >= 1) {
            double y0 = (double)(j - 1) * height, y1 = y;
            cx = an_riser(tp, j);
            cy = an_clamp(qy, an_min(y0, y1), an_max(y0, y1));
            ex = qx - cx;
            ey = qy - cy;
            d2 = ex * ex + ey * ey;
            if (d2 < best) {
                best = d2;
                nx = cx;
                ny = cy;
            }
        }
    }
    double distance = sqrt(best);
    if (!below && distance > reach) {
        return 0;
    }
    double ax = qx - nx, ay = qy - ny, n2x, n2y;
    if (distance > 1e-12) {
        if (below) {
            n2x = -ax / distance;
            n2y = -ay / distance;
        } else {
            n2x = ax / distance;
            n2y = ay / distance;
        }
    } else if (k >= 1 && an_fabs(nx - an_riser(tp, k > 1 ? k : 1)) < 1e-12) {
        /* On a riser's face: it faces down the flight (-signum(height)). */
        double s = height != height ? height : (an_bits(height) >> 63 ? -1.0 : 1.0);
        n2x = -s;
        n2y = 0.0;
    } else {
        n2x = 0.0;
        n2y = 1.0;
    }
    /* d * normal2.x + UP * normal2.y */
    normal[0] = d[0] * n2x + 0.0 * n2y;
    normal[1] = d[1] * n2x + 1.0 * n2y;
    normal[2] = d[2] * n2x + 0.0 * n2y;
    *dist = below ? -distance : distance;
    return 1;
}

/* Heightfield::vertex (i, j), its indices clamped to the grid. */
AN_FN void an_vertex(const double *tp, const double *h, long long i, long long j, double *out) {
    long long nx = (long long)tp[4], nz = (long long)tp[5];
    long long ci = i < 0 ? 0 : (i > nx - 1 ? nx - 1 : i);
    long long cj = j < 0 ? 0 : (j > nz - 1 ? nz - 1 : j);
    out[0] = tp[0] + (double)i * tp[2];
    out[1] = h[cj * nx + ci];
    out[2] = tp[1] + (double)j * tp[2];
}

/* Heightfield::cell_of: the cell under (x, z) and where in it, the index
 * held within ±2^62 cells (FAR_CELLS). */
AN_FN void an_cell_of(const double *tp, double x, double z, long long *i, long long *j,
                      double *fu, double *fv) {
    double u = (x - tp[0]) / tp[2], v = (z - tp[1]) / tp[2];
    double fi = floor(u), fj = floor(v);
    *i = an_to_i64(an_clamp(fi, -4611686018427387904.0, 4611686018427387904.0));
    *j = an_to_i64(an_clamp(fj, -4611686018427387904.0, 4611686018427387904.0));
    *fu = u - fi;
    *fv = v - fj;
}

/* Heightfield::height under (x, z). */
AN_COLD double an_hf_height(const double *tp, const double *h, double x, double z) {
    long long i, j;
    double fu, fv, va[3], vb[3], vc[3], vd[3];
    an_cell_of(tp, x, z, &i, &j, &fu, &fv);
    an_vertex(tp, h, i, j, va);
    an_vertex(tp, h, i + 1, j, vb);
    an_vertex(tp, h, i + 1, j + 1, vc);
    an_vertex(tp, h, i, j + 1, vd);
    double a = va[1], b = vb[1], c = vc[1], d = vd[1];
    if (fu >= fv) {
        return a + fu * (b - a) + fv * (c - b);
    }
    return a + fv * (d - a) + fu * (c - d);
}

/* a + s * u, glam's `a + u * s`. */
AN_FN void an_along(const double *a, const double *u, double s, double *out) {
    for (int e = 0; e < 3; e++) {
        out[e] = a[e] + u[e] * s;
    }
}

/* nearest_on_triangle (Ericson, Real-Time Collision Detection, 5.1.5). */
AN_FN void an_nearest_on_triangle(const double *p, const double *a, const double *b,
                                  const double *c, double *out) {
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int e = 0; e < 3; e++) {
        ab[e] = b[e] - a[e];
        ac[e] = c[e] - a[e];
        ap[e] = p[e] - a[e];
    }
    double d1 = an_dot3(ab, ap), d2 = an_dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        for (int e = 0; e < 3; e++) {
            out[e] = a[e];
        }
        return;
    }
    for (int e = 0; e < 3; e++) {
        bp[e] = p[e] - b[e];
    }
    double d3 = an_dot3(ab, bp), d4 = an_dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        for (int e = 0; e < 3; e++) {
            out[e] = b[e];
        }
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        an_along(a, ab, d1 / (d1 - d3), out);
        return;
    }
    for (int e = 0; e < 3; e++) {
        cp[e] = p[e] - c[e];
    }
    double d5 = an_dot3(ab, cp), d6 = an_dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        for (int e = 0; e < 3; e++) {
            out[e] = c[e];
        }
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        an_along(a, ac, d2 / (d2 - d6), out);
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double bc[3];
        for (int e = 0; e < 3; e++) {
            bc[e] = c[e] - b[e];
        }
        an_along(b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)), out);
        return;
    }
    double denom = 1.0 / (va + vb + vc);
    double s = vb * denom, t = vc * denom;
    for (int e = 0; e < 3; e++) {
        out[e] = (a[e] + ab[e] * s) + ac[e] * t;
    }
}

/* One triangle of Heightfield::probe's search: where it is nearer than
 * `best`, it becomes the nearest and gives the face's normal. */
AN_COLD void an_hf_try(const double *p, const double *a, const double *b, const double *c,
                     double *best, double *nearest, double *face) {
    double q[3], d[3];
    an_nearest_on_triangle(p, a, b, c, q);
    for (int e = 0; e < 3; e++) {
        d[e] = p[e] - q[e];
    }
    double d2 = an_dot3(d, d);
    if (d2 < *best) {
        *best = d2;
        double u[3], v[3], n[3];
        for (int e = 0; e < 3; e++) {
            nearest[e] = q[e];
            u[e] = b[e] - a[e];
            v[e] = c[e] - a[e];
        }
        /* glam's cross, then normalize: n * (1 / |n|) */
        n[0] = u[1] * v[2] - v[1] * u[2];
        n[1] = u[2] * v[0] - v[2] * u[0];
        n[2] = u[0] * v[1] - v[0] * u[1];
        double recip = 1.0 / sqrt(an_dot3(n, n));
        for (int e = 0; e < 3; e++) {
            face[e] = n[e] * recip;
        }
    }
}

/* f64::max and f64::min: a NaN gives way to the other. */
AN_FN double an_max_num(double a, double b) { return a != a ? b : (b != b ? a : (a > b ? a : b)); }
AN_FN double an_min_num(double a, double b) { return a != a ? b : (b != b ? a : (a < b ? a : b)); }

/* Heightfield::nearest_within's radius: how far across from p a cell may
 * lie and still hold a triangle as near as the squared distance d2. */
AN_FN double an_hf_radius(double d2, double tolerance) {
    /* finite: the exponent's bits not all set */
    return (an_bits(d2) & 0x7ff0000000000000ULL) != 0x7ff0000000000000ULL
               ? sqrt(d2) * (1.0 + 1e-9) + tolerance
               : an_inf();
}

/* How far across c lies from the footprint [from, to]. */
AN_FN double an_hf_gap(double c, double from, double to) {
    return an_max_num(an_max_num(from - c, c - to), 0.0);
}

/* Heightfield::nearest_within, pruned: cells farther across from p than
 * the nearest point so far (at first, on the centre cell's triangles)
 * are passed over; the same triangle is found as with every cell visited
 * (the engine's test pruning_changes_no_bit). */
AN_FN double an_hf_nearest(const double *tp, const double *h, const double *p, long long i0,
                             long long j0, long long span, double *nearest, double *face) {
    double cell = tp[2];
    double tolerance = 1e-6 * (cell + an_fabs(p[0]) + an_fabs(p[2]));
    double bound = an_inf();
    {
        double va[3], vb[3], vc[3], vd[3], q[3], d[3];
        an_vertex(tp, h, i0, j0, va);
        an_vertex(tp, h, i0 + 1, j0, vb);
        an_vertex(tp, h, i0 + 1, j0 + 1, vc);
        an_vertex(tp, h, i0, j0 + 1, vd);
        an_nearest_on_triangle(p, va, vc, vb, q);
        for (int e = 0; e < 3; e++) {
            d[e] = p[e] - q[e];
        }
        bound = an_min_num(bound, an_dot3(d, d));
        an_nearest_on_triangle(p, va, vd, vc, q);
        for (int e = 0; e < 3; e++) {
            d[e] = p[e] - q[e];
        }
        bound = an_min_num(bound, an_dot3(d, d));
    }
    double r = an_hf_radius(bound, tolerance);
    double best = an_inf();
    for (int e = 0; e < 3; e++) {
        nearest[e] = p[e];
    }
    face[0] = 0.0;
    face[1] = 1.0;
    face[2] = 0.0;
    for (long long j = j0 - span; j <= j0 + span; j++) {
        double z0 = tp[1] + (double)j * cell;
        double dz = an_hf_gap(p[2], z0, tp[1] + (double)(j + 1) * cell);
        if (dz > r) {
            if (z0 > p[2]) {
                break; /* every later row lies farther still */
            }
            continue;
        }
        for (long long i = i0 - span; i <= i0 + span; i++) {
            double x0 = tp[0] + (double)i * cell;
            double dx = an_hf_gap(p[0], x0, tp[0] + (double)(i + 1) * cell);
            if (dx * dx + dz * dz > r * r) {
                if (x0 > p[0]) {
                    break;
                }
                continue;
            }
            /* Cell (i, j)'s triangles: [a, c, b] and [a, d, c]. */
            double va[3], vb[3], vc[3], vd[3];
            an_vertex(tp, h, i, j, va);
            an_vertex(tp, h, i + 1, j, vb);
            an_vertex(tp, h, i + 1, j + 1, vc);
            an_vertex(tp, h, i, j + 1, vd);
            double was = best;
            an_hf_try(p, va, vc, vb, &best, nearest, face);
            if (best != was) {
                r = an_min_num(r, an_hf_radius(best, tolerance));
                was = best;
            }
            an_hf_try(p, va, vd, vc, &best, nearest, face);
            if (best != was) {
                r = an_min_num(r, an_hf_radius(best, tolerance));
            }
        }
    }
    return best;
}

/* Heightfield::probe. */
AN_COLD int an_hf_probe(const double *tp, const double *h, const double *p, double reach,
                      double *dist, double *normal) {
    double vertical = p[1] - an_hf_height(tp, h, p[0], p[2]);
    if ((vertical >= 0.0 ? vertical * tp[3] : vertical) > reach) {
        return 0;
    }
    long long s = an_to_i64(ceil(an_fabs(vertical) / tp[2]));
    long long span = s < 7 ? s + 1 : 8;
    long long i0, j0;
    double fu, fv;
    an_cell_of(tp, p[0], p[2], &i0, &j0, &fu, &fv);
    double nearest[3], face[3];
    double best = an_hf_nearest(tp, h, p, i0, j0, span, nearest, face);
    int below = vertical < 0.0;
    double distance = sqrt(best);
    if (distance > 1e-12) {
        for (int e = 0; e < 3; e++) {
            double away = (p[e] - nearest[e]) / distance;
            normal[e] = below ? -away : away;
        }
    } else {
        for (int e = 0; e < 3; e++) {
            normal[e] = face[e];
        }
    }
    *dist = below ? -distance : distance;
    return 1;
}

/* Terrain::probe: the signed distance from p to the surface (negative
 * below it) and the outward unit normal at the nearest point; 0 where p
 * is certainly more than `reach` above the surface. */
AN_COLD int an_probe(int kind, const double *tp, const double *h, const double *p, double reach,
                   double *dist, double *normal) {
    switch (kind) {
    case AN_T_SLOPE: {
        double d = an_dot3(p, tp);
        if (!(d <= reach)) {
            return 0;
        }
        for (int e = 0; e < 3; e++) {
            normal[e] = tp[e];
        }
        *dist = d;
        return 1;
    }
    case AN_T_STEPS:
        return an_steps_probe(tp, p, reach, dist, normal);
    case AN_T_HEIGHTFIELD:
        return an_hf_probe(tp, h, p, reach, dist, normal);
    default:
        if (!(p[1] <= reach)) {
            return 0;
        }
        normal[0] = 0.0;
        normal[1] = 1.0;
        normal[2] = 0.0;
        *dist = p[1];
        return 1;
    }
}

#endif
