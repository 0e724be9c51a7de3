/* Sphere-sphere contact, the discrete event (engine: events/sphere_contact/,
 * its mod.rs says what it does and why), for one creature: the check of a
 * trial (the pairs in the engine's order, the deepest overlap, the swept
 * test of spheres that moved further than their radius) and the handling
 * of the pairs found, in the engine's passes, with its friction and its
 * floor that holds spheres up. Without sleeping and for every particle:
 * anything else is refused when a world is packed (src/pack.rs).
 *
 * The engine finds the pairs through a grid of cells twice the largest
 * radius, cell by cell: the cells in the order of their coordinates (x,
 * then y, then z; a dense grid's linear index and a sparse grid's packed
 * key both order them so), the spheres of a cell by index, each cell
 * against itself and then its 13 forward neighbours. Here the spheres are
 * sorted by (cell, index); on a dense grid each is tested against those
 * after it in its own and its forward neighbours' cells and each cell's
 * pairs put in the grid's order, on a sparse one each neighbour's run is
 * searched for: the same pairs in the same order, with no grid. */

#ifndef ANIMATS_SPHERES_H
#define ANIMATS_SPHERES_H

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define AN_FN __device__ static inline
#else
#include <math.h>
#define AN_FN static inline
#endif
#include "terrain.h"

/* One creature's sphere contact: its particles' radii, inverse masses,
 * restitutions and friction coefficients (particle 0 its first), its
 * excluded pairs as sorted keys (min << 32 | max), the event's settings,
 * room for sorting its spheres (slots: 4 n numbers) and the pairs a check
 * finds, as keys, in the engine's order (pair: n (n - 1) / 2). */
typedef struct {
    const double *r, *w, *e, *mu_s, *mu_k;
    const long long *excluded;
    long long n_excluded;
    double envelope, rest_speed;
    double restitution; /* NaN: the product of the two spheres' */
    double step;        /* the whole step, s (a piece's check keeps it) */
    int held;           /* 1: a flat floor holds every sphere up */
    long long *slots, *pair;
    long long pairs;    /* how many pairs the last check found */
} an_spheres;

/* The engine's excluded pair key. */
AN_FN long long an_pair_key(long long a, long long b) {
    long long lo = a < b ? a : b, hi = a < b ? b : a;
    return (long long)(((unsigned long long)lo << 32) | (unsigned long long)hi);
}

AN_FN int an_excluded(const an_spheres *s, long long a, long long b) {
    long long key = an_pair_key(a, b), lo = 0, hi = s->n_excluded;
    while (lo < hi) {
        long long mid = lo + (hi - lo) / 2;
        if (s->excluded[mid] < key) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    return lo < s->n_excluded && s->excluded[lo] == key;
}

/* grid.rs `floor_i64` of a coordinate clamped to ±limit (`Grid::cell`). */
AN_FN long long an_sphere_cell(double x, double size, double limit) {
    double c = an_min(an_max(x / size, -limit), limit);
    long long t = (long long)c;
    return (double)t > c ? t - 1 : t;
}

/* The bits of v (grid.rs `Grid::bits`: a sparse key's coordinate). */
AN_FN int an_key_bits(unsigned long long v) {
    int b = 0;
    while (v) {
        b++;
        v >>= 1;
    }
    return b;
}

/* Whether (cell ka, sphere wa) comes before (cell kb, sphere wb). */
AN_FN int an_slot_before(const long long *ka, long long wa, const long long *kb, long long wb) {
    for (int k = 0; k < 3; k++) {
        if (ka[k] != kb[k]) {
            return ka[k] < kb[k];
        }
    }
    return wa < wb;
}

/* The run of slots whose key is `want` (3 numbers): [*s, *e); 0 if none. */
AN_FN int an_run_of(const long long *key, long long count, const long long *want, long long *s,
                    long long *e) {
    long long lo = 0, hi = count;
    while (lo < hi) {
        long long mid = lo + (hi - lo) / 2;
        int less = 0;
        for (int k = 0; k < 3; k++) {
            if (key[3 * mid + k] != want[k]) {
                less = key[3 * mid + k] < want[k];
                break;
            }
        }
        if (less) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    long long end = lo;
    while (end < count && key[3 * end] == want[0] && key[3 * end + 1] == want[1] &&
           key[3 * end + 2] == want[2]) {
        end++;
    }
    *s = lo;
    *e = end;
    return end > lo;
}

/* grid.rs `test` of spheres a and b at x: whether they are a pair (both
 * not fixed, within reach and the margin, not excluded), deepening
 * *deepest by their overlap where they are. */
AN_FN int an_sphere_test(const an_spheres *s, const double *x, long long a, long long b,
                         double margin, double *deepest) {
    if (s->w[a] == 0.0 && s->w[b] == 0.0) {
        return 0;
    }
    double reach = s->r[a] + s->r[b];
    double dx = x[3 * b] - x[3 * a], dy = x[3 * b + 1] - x[3 * a + 1],
           dz = x[3 * b + 2] - x[3 * a + 2];
    double d2 = dx * dx + dy * dy + dz * dz;
    double outer = reach + margin;
    if (d2 >= outer * outer) {
        return 0;
    }
    if (s->n_excluded > 0 && an_excluded(s, a, b)) {
        return 0;
    }
    *deepest = an_max(*deepest, reach - sqrt(d2));
    return 1;
}

/* The deepest overlap of the trial's spheres at x (grid.rs `find`), the
 * pairs found kept in s->pair. */
AN_FN double an_spheres_find(an_spheres *s, long long n, const double *x) {
    s->pairs = 0;
    double largest = 0.0;
    for (long long i = 0; i < n; i++) {
        if (s->r[i] > 0.0) {
            largest = an_max(largest, s->r[i]);
        }
    }
    if (largest <= 0.0) {
        return 0.0;
    }
    double size = 2.0 * largest;
    long long *who = s->slots, *key = s->slots + n, *pair = s->pair;
    long long count = 0, lo[3], hi[3];
    int dense = 0;
    /* grid.rs `bin`: cells clamped to ±1e12 (FAR), or to ±(2^20 - 2)
     * (NEAR) where a sparse grid's key would need more than 64 bits. */
    for (double limit = 1e12;; limit = (double)((1LL << 20) - 2)) {
        count = 0;
        for (long long i = 0; i < n; i++) {
            const double *p = x + 3 * i;
            int finite = p[0] - p[0] == 0.0 && p[1] - p[1] == 0.0 && p[2] - p[2] == 0.0;
            if (!(s->r[i] > 0.0) || !finite) {
                continue;
            }
            for (int k = 0; k < 3; k++) {
                long long c = an_sphere_cell(p[k], size, limit);
                key[3 * count + k] = c;
                if (count == 0 || c < lo[k]) {
                    lo[k] = c;
                }
                if (count == 0 || c > hi[k]) {
                    hi[k] = c;
                }
            }
            who[count++] = i;
        }
        if (count == 0) {
            return 0.0;
        }
        double total = (double)(hi[0] - lo[0] + 1) * (double)(hi[1] - lo[1] + 1) *
                       (double)(hi[2] - lo[2] + 1);
        dense = total <= (double)(4 * count + 4096);
        int bits = 0;
        for (int k = 0; k < 3; k++) {
            bits += an_key_bits((unsigned long long)(hi[k] - lo[k] + 2));
        }
        if (dense || bits <= 64 || limit < 1e12) {
            break;
        }
    }
    /* Sorted by (cell, index): insertion sort (they come in index order). */
    for (long long q = 1; q < count; q++) {
        long long kw[3] = {key[3 * q], key[3 * q + 1], key[3 * q + 2]}, wq = who[q];
        long long at = q;
        while (at > 0 && an_slot_before(kw, wq, key + 3 * (at - 1), who[at - 1])) {
            key[3 * at] = key[3 * (at - 1)];
            key[3 * at + 1] = key[3 * (at - 1) + 1];
            key[3 * at + 2] = key[3 * (at - 1) + 2];
            who[at] = who[at - 1];
            at--;
        }
        key[3 * at] = kw[0];
        key[3 * at + 1] = kw[1];
        key[3 * at + 2] = kw[2];
        who[at] = wq;
    }
    double margin = s->rest_speed * s->step;
    double deepest = 0.0;
    if (dense) {
        /* Each sphere against those after it whose cell is its own or one
         * of its 13 forward neighbours (the slots are in cell order, so
         * the scan ends at the first two cells further along x); the pairs
         * of each run of one cell then put in the grid's order: by
         * neighbour (its own cell first), then sphere, then sphere. The
         * test of a pair does not depend on when it is made, so these are
         * the engine's pairs in the engine's order. */
        long long start = 0;
        while (start < count) {
            long long end = start + 1;
            while (end < count && key[3 * end] == key[3 * start] &&
                   key[3 * end + 1] == key[3 * start + 1] &&
                   key[3 * end + 2] == key[3 * start + 2]) {
                end++;
            }
            long long first = s->pairs;
            for (long long qa = start; qa < end; qa++) {
                const long long *ka = key + 3 * qa;
                for (long long qb = qa + 1; qb < count; qb++) {
                    const long long *kb = key + 3 * qb;
                    long long d0 = kb[0] - ka[0], d1 = kb[1] - ka[1], d2 = kb[2] - ka[2];
                    if (d0 > 1) {
                        break;
                    }
                    if (d1 < -1 || d1 > 1 || d2 < -1 || d2 > 1) {
                        continue;
                    }
                    /* The neighbour's place in grid.rs FORWARD: 0 its own
                     * cell, then 1 .. 13. */
                    long long o = (d0 + 1) * 9 + (d1 + 1) * 3 + (d2 + 1) - 13;
                    if (an_sphere_test(s, x, who[qa], who[qb], margin, &deepest)) {
                        long long k = (o << 40) | (qa << 20) | qb;
                        long long at = s->pairs++;
                        while (at > first && pair[at - 1] > k) {
                            pair[at] = pair[at - 1];
                            at--;
                        }
                        pair[at] = k;
                    }
                }
            }
            for (long long q = first; q < s->pairs; q++) {
                long long qa = (pair[q] >> 20) & 0xfffff, qb = pair[q] & 0xfffff;
                pair[q] = an_pair_key(who[qa], who[qb]);
            }
            start = end;
        }
        return deepest;
    }
    long long start = 0;
    while (start < count) {
        const long long *c = key + 3 * start;
        long long end = start + 1;
        while (end < count && key[3 * end] == key[3 * start] &&
               key[3 * end + 1] == key[3 * start + 1] && key[3 * end + 2] == key[3 * start + 2]) {
            end++;
        }
        for (int o = -1; o < 13; o++) {
            long long rs = start, re = end;
            if (o >= 0) {
                /* grid.rs FORWARD[1..]: the offsets after (0, 0, 0) in
                 * the order of (dx, dy, dz), 27 cells numbered from
                 * (-1, -1, -1). */
                int cell = 14 + o;
                int off[3] = {cell / 9 - 1, (cell / 3) % 3 - 1, cell % 3 - 1};
                long long want[3];
                for (int k = 0; k < 3; k++) {
                    want[k] = c[k] + off[k];
                }
                if (!an_run_of(key, count, want, &rs, &re)) {
                    continue;
                }
            }
            for (long long qa = start; qa < end; qa++) {
                for (long long qb = o < 0 ? qa + 1 : rs; qb < re; qb++) {
                    if (an_sphere_test(s, x, who[qa], who[qb], margin, &deepest)) {
                        pair[s->pairs++] = an_pair_key(who[qa], who[qb]);
                    }
                }
            }
        }
        start = end;
    }
    return deepest;
}

/* The deepest overlap of a sphere that moved further than its radius from
 * x0 to x1 with any other on the way (grid.rs `swept`). */
AN_FN double an_spheres_swept(const an_spheres *s, long long n, const double *x0,
                              const double *x1) {
    double deepest = 0.0;
    for (long long i = 0; i < n; i++) {
        double r = s->r[i];
        const double *a0 = x0 + 3 * i, *a1 = x1 + 3 * i;
        int usable = r > 0.0 && a0[0] - a0[0] == 0.0 && a0[1] - a0[1] == 0.0 &&
                     a0[2] - a0[2] == 0.0 && a1[0] - a1[0] == 0.0 && a1[1] - a1[1] == 0.0 &&
                     a1[2] - a1[2] == 0.0;
        double mx = a1[0] - a0[0], my = a1[1] - a0[1], mz = a1[2] - a0[2];
        if (!usable || !(mx * mx + my * my + mz * mz > r * r)) {
            continue;
        }
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = an_min(a0[k], a1[k]) - r;
            hi[k] = an_max(a0[k], a1[k]) + r;
        }
        for (long long j = 0; j < n; j++) {
            double rj = s->r[j];
            const double *b0 = x0 + 3 * j, *b1 = x1 + 3 * j;
            int usable_j = rj > 0.0 && b0[0] - b0[0] == 0.0 && b0[1] - b0[1] == 0.0 &&
                           b0[2] - b0[2] == 0.0 && b1[0] - b1[0] == 0.0 &&
                           b1[1] - b1[1] == 0.0 && b1[2] - b1[2] == 0.0;
            if (!usable_j || j == i) {
                continue;
            }
            int apart = 0;
            for (int k = 0; k < 3; k++) {
                double jlo = an_min(b0[k], b1[k]) - rj, jhi = an_max(b0[k], b1[k]) + rj;
                apart |= jlo > hi[k] || jhi < lo[k];
            }
            if (apart || (s->w[i] == 0.0 && s->w[j] == 0.0)) {
                continue;
            }
            if (s->n_excluded > 0 && an_excluded(s, i, j)) {
                continue;
            }
            double d0[3], m[3];
            for (int k = 0; k < 3; k++) {
                d0[k] = b0[k] - a0[k];
                m[k] = (b1[k] - a1[k]) - d0[k];
            }
            double mm = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
            double t = 0.0;
            if (mm > 0.0) {
                t = -(d0[0] * m[0] + d0[1] * m[1] + d0[2] * m[2]) / mm;
                t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
            }
            double px = d0[0] + m[0] * t, py = d0[1] + m[1] * t, pz = d0[2] + m[2] * t;
            deepest = an_max(deepest, r + rj - sqrt(px * px + py * py + pz * pz));
        }
    }
    return deepest;
}

/* The check of a trial from x0 to x1 (mod.rs `check`): AN_NONE (0), AN_OCCURRING
 * (1) or AN_MISSED (2). */
AN_FN int an_spheres_check(an_spheres *s, long long n, const double *x0, const double *x1) {
    double deepest = an_spheres_find(s, n, x1);
    if (deepest <= s->envelope) {
        deepest = an_max(deepest, an_spheres_swept(s, n, x0, x1));
    }
    if (deepest > s->envelope) {
        return 2;
    }
    return s->pairs == 0 ? 0 : 1;
}

/* Whether the floor holds sphere i up, resting on it (resolve.rs `weights`). */
AN_FN int an_sphere_held(const an_spheres *s, const double *x, long long i) {
    return s->held && x[3 * i + 1] <= s->r[i] + 1e-6;
}

/* Pair q's handling in one pass (resolve.rs `contact`); returns the
 * overlap it corrected. */
AN_FN double an_sphere_pair(const an_spheres *s, long long a, long long b, double *x, double *v) {
    double *pa = x + 3 * a, *pb = x + 3 * b, *va = v + 3 * a, *vb = v + 3 * b;
    double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double reach = s->r[a] + s->r[b];
    double overlap = reach - dist;
    double margin = s->rest_speed * s->step;
    if (overlap <= -margin || dist == 0.0) {
        return 0.0;
    }
    double nrm[3] = {d[0] / dist, d[1] / dist, d[2] / dist};
    double wa = nrm[1] > 0.0 && an_sphere_held(s, x, a) ? 0.0 : s->w[a];
    double wb = nrm[1] < 0.0 && an_sphere_held(s, x, b) ? 0.0 : s->w[b];
    double w = wa + wb;
    if (w == 0.0) {
        return 0.0;
    }
    double u[3] = {vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]};
    double un = u[0] * nrm[0] + u[1] * nrm[1] + u[2] * nrm[2];
    double allowed = an_min(overlap, 0.0) / s->step;
    int resting = -un < s->rest_speed;
    if (un < allowed && (overlap >= 0.0 || resting)) {
        double e = 0.0;
        if (!(resting || overlap < 0.0)) {
            e = s->restitution == s->restitution ? s->restitution : s->e[a] * s->e[b];
        }
        double ut[3] = {u[0] - nrm[0] * un, u[1] - nrm[1] * un, u[2] - nrm[2] * un};
        double slide = sqrt(ut[0] * ut[0] + ut[1] * ut[1] + ut[2] * ut[2]);
        double target = overlap < 0.0 ? allowed - un : -(1.0 + e) * un;
        double jn = target / w, stop = slide / w;
        double imp[3] = {nrm[0] * jn, nrm[1] * jn, nrm[2] * jn};
        if (slide > 0.0) {
            double mu_s = sqrt(s->mu_s[a] * s->mu_s[b]), mu_k = sqrt(s->mu_k[a] * s->mu_k[b]);
            double jt = stop <= mu_s * jn ? stop : mu_k * jn;
            double f = jt / slide;
            for (int k = 0; k < 3; k++) {
                imp[k] = imp[k] - ut[k] * f;
            }
        }
        for (int k = 0; k < 3; k++) {
            va[k] = va[k] - imp[k] * wa;
            vb[k] = vb[k] + imp[k] * wb;
        }
    }
    if (overlap > 0.0) {
        double ka = (overlap * wa) / w, kb = (overlap * wb) / w;
        for (int k = 0; k < 3; k++) {
            pa[k] = pa[k] - nrm[k] * ka;
            pb[k] = pb[k] + nrm[k] * kb;
        }
    }
    long long ends[2] = {a, b};
    for (int q = 0; q < 2; q++) {
        long long i = ends[q];
        if (s->held && x[3 * i + 1] < s->r[i] && s->w[i] != 0.0) {
            x[3 * i + 1] = s->r[i];
            v[3 * i + 1] = an_max(v[3 * i + 1], 0.0);
        }
    }
    return an_max(overlap, 0.0);
}

/* The handling of the pairs the last check found (resolve.rs `resolve`):
 * up to 8 passes (PASSES), until one corrects no overlap deeper than
 * 1e-6 m (SETTLED). */
AN_FN void an_spheres_handle(const an_spheres *s, double *x, double *v) {
    for (int pass = 0; pass < 8; pass++) {
        double largest = 0.0;
        for (long long q = 0; q < s->pairs; q++) {
            long long key = s->pair[q];
            long long a = (long long)((unsigned long long)key >> 32), b = key & 0xffffffffLL;
            largest = an_max(largest, an_sphere_pair(s, a, b, x, v));
        }
        if (largest <= 1e-6) {
            break;
        }
    }
}

#endif
