/*
 * A scene's whole evaluation in C, after the step (step.h): what
 * crates/scene/src/evaluate.rs `evaluate_with` does, operation by
 * operation. Each step: the actuators' state is noted where their work
 * counts (scene/src/work.rs), the nervous system acts
 * (creatures/src/nervous_system.rs `act`: every sensor read, then every
 * controller — oscillator, neural network, CTRNN, FSM — in the scene's
 * order, each output slewed by its actuator's rate and clamped to [0, 1]
 * and its target set; then the gates), the jellyfish act (their pulses
 * and steering, creatures/src/jellyfish), the world steps, its clock
 * advances (Kahan), the divergence guard checks every 64th step
 * (engine/src/guard.rs: a driven world's speed limit), the actuators'
 * positive work is summed, the measures record the step
 * (scene/src/archive.rs, Recorder), the centre of the particles that
 * count is taken and the end rules (fail_on_touch, then fail_on_stretch)
 * are tried. The fitness is the [evolve] table's: time, distance, energy,
 * target and terms. What this file does not cover is refused when a scene
 * is packed (crates/gpu/src/scenes.rs).
 */
#ifndef ANIMATS_EVAL_H
#define ANIMATS_EVAL_H

#include "step.h"
#include "trig.h"
#include "exp.h"

/* Numbers of eval_param per creature (step.h says which). */
#define AN_PARAMS 16

/* Why an evaluation ended, as scene::evaluate::Ended. */
enum { AN_TIMEOUT = 0, AN_TOUCH = 1, AN_STRETCH = 2, AN_BLOWUP = 3 };

/* sensor::unit: x clamped to [0, 1], NaN to 0. */
AN_FN double an_unit(double x) {
    if (x >= 1.0) {
        return 1.0;
    }
    if (x > 0.0) {
        return x;
    }
    return 0.0;
}

/* Pushes first .. first + count - 1 of creature c's constant forces set
 * to axis times value (ForceScale::set, ForceMagnitude::set). */
AN_FN void an_set_pushes(const an_batch *b, long long c, long long first, long long count,
                         const double *axis, double value) {
    long long k0 = b->first_push[c] + first;
    for (long long k = k0; k < k0 + count; k++) {
        for (int d = 0; d < 3; d++) {
            b->push_force[3 * k + d] = axis[d] * value;
        }
    }
}

/* Actuated::set of muscle q (over the batch) of creature c: its target
 * given `value` (actuators/: a spring's rest length, an angle joint's rest
 * angle, a torque joint's torque, a constant force's vector scaled). */
AN_FN void an_set_target(const an_batch *b, long long c, long long q, double value) {
    long long i = b->muscle_spring[q];
    switch (b->muscle_kind[q]) {
    case 0:
        b->rest_length[b->first_spring[c] + i] = value;
        break;
    case 1:
        b->joint_rest[b->first_joint[c] + i] = value;
        break;
    case 2:
        b->motor_torque[b->first_motor[c] + i] = value;
        break;
    default:
        an_set_pushes(b, c, b->muscle_push[2 * q], b->muscle_push[2 * q + 1], b->muscle_base + 3 * q,
                      value);
        break;
    }
}

/* The value muscle q's level gives: min + level (max - min). */
AN_FN double an_muscle_value(const an_batch *b, long long q) {
    double lo = b->muscle_param[3 * q], hi = b->muscle_param[3 * q + 1];
    return lo + b->muscle_level[q] * (hi - lo);
}

/* nervous_system.rs `slew` of muscle q (index over the batch) of
 * creature c, towards level l over dt. */
AN_FN void an_slew(const an_batch *b, long long c, long long q, double l, double dt) {
    if (l != l) {
        return;
    }
    double level = an_unit(l);
    double rate = b->muscle_param[3 * q + 2];
    if (rate >= 0.0) {
        double now = b->muscle_level[q];
        double lo = -rate * dt, hi = rate * dt, d = level - now;
        if (d < lo) {
            d = lo;
        }
        if (d > hi) {
            d = hi;
        }
        level = now + d;
    }
    level = an_unit(level); /* Actuator::set_level */
    b->muscle_level[q] = level;
    an_set_target(b, c, q, an_muscle_value(b, q));
}

/* NervousSystem::apply_gates: a gated torque joint or force holds its
 * value while its sensor's level is above (or at or below) the threshold,
 * else zero. */
AN_FN void an_gates(const an_batch *b, long long c) {
    long long q0 = b->first_sensor[c];
    for (long long q = b->first_muscle[c]; q < b->first_muscle[c + 1]; q++) {
        const double *g = b->muscle_gate + 3 * q;
        if (g[0] < 0.0) {
            continue;
        }
        double l = b->sensor_level[q0 + (long long)g[0]];
        int open = g[2] != 0.0 ? l > g[1] : l <= g[1];
        an_set_target(b, c, q, open ? an_muscle_value(b, q) : 0.0);
    }
}

/* angle_joint::angle_at: the angle at j between a and b, atan2(|ra x rb|,
 * ra . rb). */
AN_FN double an_angle_at(const double *a, const double *j, const double *b) {
    double ra[3], rb[3], n[3];
    for (int d = 0; d < 3; d++) {
        ra[d] = a[d] - j[d];
        rb[d] = b[d] - j[d];
    }
    an_cross(ra, rb, n);
    return an_atan2(sqrt(an_dot(n, n)), an_dot(ra, rb));
}

/* World::clearance: how far particle p's surface is from the ground
 * (the floor's terrain; the plane y = 0 on the flat floor or without a
 * floor), m. */
AN_FN double an_clearance(const an_batch *b, an_state st, long long p) {
    const double *x = st.x + 3 * p;
    if (b->floor && AN_ON_TERRAIN(b)) {
        double d, n[3];
        if (an_probe(b->terrain, b->terrain_param, b->terrain_height, x, an_inf(), &d, n)) {
            return d - st.r[p];
        }
    }
    return x[1] - st.r[p];
}

/* World::touches_ground: whether an_clearance(b, st, p) <= tolerance, a
 * particle certainly farther told so without the terrain's search (the
 * probe's reach a billionth above r + tolerance). */
AN_FN int an_touches(const an_batch *b, an_state st, long long p, double tolerance) {
    const double *x = st.x + 3 * p;
    double r = st.r[p];
    if (b->floor && AN_ON_TERRAIN(b)) {
        double d, n[3], reach = r + tolerance;
        /* glam's abs().max_element(): max(x, max(y, z)), max(a, b) = a > b ? a : b */
        double ax = an_fabs(x[0]), ay = an_fabs(x[1]), az = an_fabs(x[2]);
        double yz = ay > az ? ay : az, most = ax > yz ? ax : yz;
        double margin = 1e-9 * (an_fabs(reach) + 1.0 + most);
        if (an_probe(b->terrain, b->terrain_param, b->terrain_height, x, reach + margin, &d, n)) {
            return d - r <= tolerance;
        }
        return 0;
    }
    return x[1] - r <= tolerance;
}

/* Sensor kinds (creatures/src/sensors/probe.rs, `Probe`; then the
 * roobot's own: sensors/height.rs, tilt.rs, touchdown.rs; its speed
 * sensor is AN_S_SPEED mapped from [0, 1]). */
enum {
    AN_S_HEIGHT = 0,
    AN_S_SPEED = 1,
    AN_S_TOUCH = 2,
    AN_S_LENGTH = 3,
    AN_S_ANGLE = 4,
    AN_S_TILT = 5,
    AN_S_CLEARANCE = 6, /* HeightSensor: the clearance above the floor (World::clearance) */
    AN_S_LEG_ANGLE = 7, /* TiltSensor: 0.5 + gain atan2(d . forward, d.y), d = b - a */
    AN_S_TOUCHDOWN = 8  /* TouchdownSensor: (v + sqrt(v^2 + 2 g h)) / g */
};

/* ScaledSensor::level of sensor q (over the batch) of the creature whose
 * state is st: the probe's reading mapped from [min, max] onto [0, 1]. */
AN_FN double an_sensor(const an_batch *b, an_state st, long long q) {
    const int *ids = b->sensor_particle + 3 * q;
    const double *param = b->sensor_param + 5 * q;
    const double *x = st.x, *v = st.v;
    const double *pa = x + 3 * ids[0], *pb = x + 3 * ids[1], *pc = x + 3 * ids[2];
    double reading, d[3];
    switch (b->sensor_kind[q]) {
    case AN_S_CLEARANCE:
        return an_unit(an_clearance(b, st, ids[0]));
    case AN_S_LEG_ANGLE:
        for (int k = 0; k < 3; k++) {
            d[k] = pb[k] - pa[k];
        }
        return an_unit(0.5 + param[3] * an_atan2(an_dot(d, param), d[1]));
    case AN_S_TOUCHDOWN: {
        double h = an_unit(an_clearance(b, st, ids[0])), vy = v[3 * ids[0] + 1], g = param[3];
        return an_unit((vy + sqrt(vy * vy + 2.0 * g * h)) / g);
    }
    case AN_S_HEIGHT:
        reading = pa[1];
        break;
    case AN_S_SPEED:
        reading = an_dot(v + 3 * ids[0], param);
        break;
    case AN_S_TOUCH: /* TOUCH_TOLERANCE */
        reading = an_touches(b, st, ids[0], 1e-3) ? 1.0 : 0.0;
        break;
    case AN_S_LENGTH: /* glam's distance: (a - b).length() */
        for (int k = 0; k < 3; k++) {
            d[k] = pa[k] - pb[k];
        }
        reading = sqrt(an_dot(d, d));
        break;
    case AN_S_ANGLE: /* at the second particle, between the first and third */
        reading = an_angle_at(pa, pb, pc);
        break;
    default: /* AN_S_TILT: a -> b from the vertical */
        for (int k = 0; k < 3; k++) {
            d[k] = pb[k] - pa[k];
        }
        reading = an_atan2(sqrt(d[0] * d[0] + d[2] * d[2]), d[1]);
        break;
    }
    return an_unit((reading - param[3]) / (param[4] - param[3]));
}

/* The phase of a skewed wave u cycles past its trough, rising for the
 * share duty of a cycle (brains/oscillator.rs `skewed_angle`). */
AN_FN double an_skewed_angle(double u, double duty) {
    if (u < duty) {
        return -1.5707963267948966 + 3.141592653589793 * (u / duty);
    }
    return 1.5707963267948966 + 3.141592653589793 * ((u - duty) / (1.0 - duty));
}

/* Oscillator o (over the batch) of creature c at time t
 * (brains/oscillator.rs: level = offset + amplitude sin(2 pi f t + phase),
 * or with a duty, offset + amplitude sin(psi), psi the skewed angle of
 * frac(f t + (phase + pi/2) / 2 pi)). */
AN_FN void an_oscillator(const an_batch *b, long long c, long long o, double t, double dt) {
    long long u0 = b->first_muscle[c];
    double f = b->osc_frequency[o];
    double w = (6.283185307179586 * f) * t;
    double ft = f * t;
    for (long long k = b->first_output[o]; k < b->first_output[o + 1]; k++) {
        const double *g = b->output_gene + 5 * k;
        double l;
        if (g[4] == g[4]) {
            double cy = ft + (g[1] + 0.5 * 3.141592653589793) / 6.283185307179586;
            l = g[2] + g[0] * an_sin(an_skewed_angle(cy - floor(cy), g[4]));
        } else {
            l = g[2] + g[0] * an_sin(w + g[1]);
        }
        if (g[3] == g[3]) {
            l = l + g[3];
        }
        an_slew(b, c, u0 + b->output_muscle[k], l, dt);
    }
}

/* brain.rs `network_inputs` of network m, whose creature's sensors begin
 * at q0, at time t, into x: each input level as 2 level - 1, then the
 * clock's sine and cosine if it has one. */
AN_FN void an_net_inputs(const an_batch *b, long long q0, long long m, double t, double *x) {
    long long ni = 0;
    for (long long i = b->net_first_input[m]; i < b->net_first_input[m + 1]; i++) {
        x[ni++] = 2.0 * b->sensor_level[q0 + b->net_input[i]] - 1.0;
    }
    double f = b->net_clock[m];
    if (f == f) {
        double w = (6.283185307179586 * f) * t;
        x[ni++] = an_sin(w);
        x[ni++] = an_cos(w);
    }
}

/* The levels of network m's outputs (a trial's offsets added) to its
 * muscles, each slewed (creature c's muscles begin at u0). */
AN_FN void an_net_outputs(const an_batch *b, long long c, long long u0, long long m,
                          const double *levels, double dt) {
    long long o0 = b->net_first_output[m];
    for (long long o = o0; o < b->net_first_output[m + 1]; o++) {
        double l = levels[o - o0];
        double shift = b->net_output_shift[o];
        if (shift == shift) {
            l = l + shift;
        }
        an_slew(b, c, u0 + b->net_output_muscle[o], l, dt);
    }
}

/* Network m (over the batch) of creature c at time t (brains/neural.rs:
 * inputs 2 level - 1, the clock's sine and cosine, tanh layers, a
 * logistic output layer). */
AN_FN void an_network(const an_batch *b, long long c, long long m, double t, double dt) {
    long long u0 = b->first_muscle[c], q0 = b->first_sensor[c];
    long long r0 = b->net_first_scratch[m];
    long long width = (b->net_first_scratch[m + 1] - r0) / 2;
    double *x = b->net_scratch + r0, *y = x + width;
    an_net_inputs(b, q0, m, t, x);
    const int *sizes = b->layer_size + b->net_first_layer[m];
    long long layers = b->net_first_layer[m + 1] - b->net_first_layer[m] - 1;
    const double *wt = b->net_weight;
    long long k = b->net_first_weight[m];
    for (long long l = 0; l < layers; l++) {
        long long n_in = sizes[l], n_out = sizes[l + 1];
        long long biases = k + n_out * n_in;
        for (long long j = 0; j < n_out; j++) {
            double a = wt[biases + j];
            for (long long i = 0; i < n_in; i++) {
                a = a + wt[k + j * n_in + i] * x[i];
            }
            y[j] = l + 1 == layers ? 1.0 / (1.0 + an_exp(-a)) : an_tanh(a);
        }
        k = biases + n_out;
        double *swap = x;
        x = y;
        y = swap;
    }
    an_net_outputs(b, c, u0, m, x, dt);
}

/* brains/ctrnn.rs `sigma`: the logistic function. */
AN_FN double an_sigma(double z) { return 1.0 / (1.0 + an_exp(-z)); }

/* CTRNN m (a network entry, over the batch) of creature c at time t
 * (brains/ctrnn.rs: every neuron's rate from its state, then each state
 * a semi-implicit Euler step, y <- (y + h drive) / (1 + h), h = dt / tau;
 * neuron i drives output i). */
AN_FN void an_ctrnn(const an_batch *b, long long c, long long m, double t, double dt) {
    long long u0 = b->first_muscle[c], q0 = b->first_sensor[c];
    const int *sizes = b->layer_size + b->net_first_layer[m];
    long long n = sizes[0], mi = sizes[1];
    double *x = b->net_scratch + b->net_first_scratch[m], *rates = x + mi;
    an_net_inputs(b, q0, m, t, x);
    const double *np = b->neuron_param + 3 * b->net_first_neuron[m];
    double *state = b->neuron_state + b->net_first_neuron[m];
    for (long long i = 0; i < n; i++) {
        rates[i] = an_sigma(np[3 * i + 2] * (state[i] + np[3 * i + 1]));
    }
    const double *w = b->net_weight + b->net_first_weight[m], *v = w + n * n;
    for (long long i = 0; i < n; i++) {
        double drive = 0.0;
        for (long long j = 0; j < n; j++) {
            drive = drive + w[i * n + j] * rates[j];
        }
        for (long long k = 0; k < mi; k++) {
            drive = drive + v[i * mi + k] * x[k];
        }
        double tau = np[3 * i];
        double h = dt / (tau > 1e-4 ? tau : 1e-4); /* tau.max(MIN_TAU) */
        state[i] = (state[i] + h * drive) / (1.0 + h);
    }
    /* Neuron i drives output i, at its rate after the step. */
    long long outputs = b->net_first_output[m + 1] - b->net_first_output[m];
    for (long long i = 0; i < outputs; i++) {
        rates[i] = an_sigma(np[3 * i + 2] * (state[i] + np[3 * i + 1]));
    }
    an_net_outputs(b, c, u0, m, rates, dt);
}

/* FSM m (a network entry, over the batch) of creature c at time t
 * (brains/fsm.rs `think`): the first transition of the current state that
 * fires (its sensor above or below a threshold, and `after` seconds in the
 * state) moves it; each output moves towards the state's level at its
 * rate. Its states are numbers in net_weight (scenes.rs says how); its
 * inputs, levels, current state, entry time and start in net_scratch. */
AN_FN void an_fsm(const an_batch *b, long long c, long long m, double t, double dt) {
    long long u0 = b->first_muscle[c], q0 = b->first_sensor[c];
    long long i0 = b->net_first_input[m], ni = b->net_first_input[m + 1] - i0;
    long long o0 = b->net_first_output[m], no = b->net_first_output[m + 1] - o0;
    double *x = b->net_scratch + b->net_first_scratch[m], *levels = x + ni, *own = levels + no;
    for (long long i = 0; i < ni; i++) {
        x[i] = b->sensor_level[q0 + b->net_input[i0 + i]];
    }
    const double *w = b->net_weight + b->net_first_weight[m];
    if (own[2] == 0.0) { /* started */
        own[2] = 1.0;
        own[1] = t;
    }
    double in_state = t - own[1];
    const double *st = w + (long long)w[1 + (long long)own[0]];
    long long transitions = (long long)st[1];
    const double *tr = st + 2 + no;
    for (long long k = 0; k < transitions; k++, tr += 5) {
        int kind = (int)tr[1];
        double sensed = kind == 0 ? 1.0 : x[(long long)tr[2]];
        int fires = kind == 0 || (kind == 1 ? sensed > tr[3] : sensed < tr[3]);
        if (fires && (tr[4] != tr[4] || in_state >= tr[4])) {
            own[0] = tr[0];
            own[1] = t;
            break;
        }
    }
    st = w + (long long)w[1 + (long long)own[0]];
    double rate = st[0];
    for (long long o = 0; o < no; o++) {
        double target = st[2 + o];
        if (rate != rate) {
            levels[o] = target;
        } else {
            double step = rate * dt, lo = -step, d = target - levels[o];
            if (d < lo) {
                d = lo;
            }
            if (d > step) {
                d = step;
            }
            levels[o] = levels[o] + d;
        }
    }
    an_net_outputs(b, c, u0, m, levels, dt);
}

/* f64::max and f64::min: a NaN operand gives the other; of equal ones
 * (zeros of either sign) the second, as on x86-64. */
AN_FN double an_maxnum(double a, double b) {
    if (a != a) {
        return b;
    }
    if (b != b) {
        return a;
    }
    return a > b ? a : b;
}
AN_FN double an_minnum(double a, double b) {
    if (a != a) {
        return b;
    }
    if (b != b) {
        return a;
    }
    return a < b ? a : b;
}

/* The roobot's hopping FSM m (a network entry of kind 4) of creature c,
 * whose state is st (roobot/fsm.rs `HopFsm::step`, Appendix B's
 * HopBehaviour): reads its four sensors, the hip's velocity along the
 * forward direction and the leg's level; orders each of leg, hip and ankle
 * to keep its level (NaN), return to its initial level, or take a level;
 * the state changes take effect on the next step. Its numbers: the 14
 * parameters, forward x, y, z, the hip, the three initial levels; its
 * scratch: the state (0 stance, 1 leap, 2 launch, 3 flight). */
AN_FN void an_hop(const an_batch *b, an_state st, long long c, long long m, double dt) {
    long long u0 = b->first_muscle[c], q0 = b->first_sensor[c];
    const double *p = b->net_weight + b->net_first_weight[m];
    const double *fwd = p + 14, *init = p + 18;
    long long hip = (long long)p[17];
    const int *in = b->net_input + b->net_first_input[m];
    double height = b->sensor_level[q0 + in[0]], angle = b->sensor_level[q0 + in[1]];
    double speed = b->sensor_level[q0 + in[2]], touchdown = b->sensor_level[q0 + in[3]];
    double hip_velocity = an_dot(st.v + 3 * hip, fwd);
    long long o0 = b->net_first_output[m];
    double leg_level = b->muscle_level[u0 + b->net_output_muscle[o0]];
    double *state = b->net_scratch + b->net_first_scratch[m];
    const double keep = an_from_bits(0x7ff8000000000000ULL);
    double out[3] = {keep, keep, keep};
    switch ((int)state[0]) {
    case 0: /* stance */
        if (angle < p[1]) {
            double rate = p[3] * (leg_level - p[0]) / (p[1] - angle);
            double leg = an_maxnum(p[0], leg_level - rate * dt);
            double ankle = 0.5 + p[4] * (p[1] - angle) + p[5] * (p[2] - speed);
            out[0] = an_unit(leg);
            out[1] = init[1];
            out[2] = an_unit(ankle);
        } else {
            state[0] = 1.0;
            out[1] = init[1];
            out[2] = init[2];
        }
        break;
    case 1: /* leap */
        if (leg_level < p[6]) {
            out[0] = an_unit(an_minnum(p[6], leg_level + p[7] * dt));
        } else {
            state[0] = 2.0;
        }
        break;
    case 2: /* launch */
        if (height < p[9]) {
            out[0] = an_unit(an_maxnum(p[10], leg_level - p[8] * dt));
        } else {
            state[0] = 3.0;
        }
        break;
    default: /* flight */
        if (height > 0.0) {
            double target = 0.5 + an_unit(-p[12] * hip_velocity);
            double to = 0.5 + p[13] * (target - angle) / (touchdown + 0.05);
            out[0] = an_unit(an_maxnum(p[10], leg_level - p[11] * dt));
            out[1] = an_unit(to);
            out[2] = init[2];
        } else {
            state[0] = 0.0;
        }
        break;
    }
    an_net_outputs(b, c, u0, m, out, dt);
}

/* Actuator::set_level of a jellyfish's actuator `a` (its numbers: range,
 * initial level, pushes) to level l, along `axis` (ForceMagnitude::set:
 * every push of its constant force is axis times the value). */
AN_FN void an_jelly_force(const an_batch *b, long long c, const double *a, const double *axis, double l) {
    double level = an_unit(l);
    an_set_pushes(b, c, (long long)a[3], (long long)a[4], axis, a[0] + level * (a[1] - a[0]));
}

/* JellyfishFsm::advance_phase: the phase moved on by dt; 1 when the pulse
 * is over (the phase back to 0). */
AN_FN int an_jelly_phase(double *s, double dt, double period) {
    s[3] = s[3] + 6.283185307179586 * dt / period;
    if (s[3] >= 6.283185307179586) {
        s[3] = 0.0;
        return 1;
    }
    return 0;
}

/* f64::clamp to [0, 1] (a NaN stays NaN). */
AN_FN double an_clamp01(double x) {
    if (x < 0.0) {
        x = 0.0;
    }
    if (x > 1.0) {
        x = 1.0;
    }
    return x;
}

/* Jellyfish m (a network entry of kind 5) of creature c acts at time t
 * (creatures/src/jellyfish/mod.rs `act`): the dome's normal (Body::normal)
 * becomes every force's axis; the FSM (jellyfish/fsm.rs `step`, through
 * its Brain::think) reads the food at each dome mass, the depth and each
 * mass's lean, and orders the pulse's and the steering forces' levels, or
 * their initial levels to rest. scenes.rs `add_jellyfish` says how its
 * numbers and state are laid out. Out of line on a GPU (AN_COLD), so that
 * creatures without one keep their registers. */
AN_COLD void an_jellyfish(const an_batch *b, an_state st, long long c, long long m, double t, double dt) {
    const double *w = b->net_weight + b->net_first_weight[m];
    double *s = b->net_scratch + b->net_first_scratch[m];
    long long n = (long long)w[0];
    const double *dome = w + 7, *acts = w + 7 + 3 * n;
    double *food = s + 5, *lean = food + n;
    const double *x = st.x;
    const double *p0 = x + 3 * (long long)dome[0], *p1 = x + 3 * (long long)dome[3],
                 *p2 = x + 3 * (long long)dome[6];
    double u[3], v[3], normal[3], axis[3] = {0.0, 0.0, 0.0};
    for (int d = 0; d < 3; d++) {
        u[d] = p0[d] - p1[d];
        v[d] = p2[d] - p0[d];
    }
    an_cross(u, v, normal);
    double rcp = 1.0 / sqrt(an_dot(normal, normal)); /* normalize_or_zero */
    if (rcp - rcp == 0.0 && rcp > 0.0) {
        for (int d = 0; d < 3; d++) {
            axis[d] = normal[d] * rcp;
        }
    }
    double cy = 0.0; /* the dome's centre's height: the sum from zero */
    for (long long i = 0; i < n; i++) {
        cy = cy + x[3 * (long long)dome[3 * i] + 1];
    }
    cy = cy / (double)n;
    for (long long i = 0; i < n; i++) {
        const double *sensor = x + 3 * (long long)dome[3 * i + 1], *at = x + 3 * (long long)dome[3 * i + 2];
        food[i] = an_unit(0.1 / an_hypot(at[0] - sensor[0], at[2] - sensor[2]));
        lean[i] = (x[3 * (long long)dome[3 * i] + 1] - cy) / w[2];
    }
    double depth = an_unit(x[3 * (long long)w[6] + 1] / w[1]);
    /* JellyfishFsm::step */
    int order = 0; /* 0 rest, 1 track, 2 hover */
    double pulse = 0.0;
    if (s[0] == 0.0) { /* idle */
        s[2] = an_clamp01(s[2] + 0.4 * dt);
        if (!(depth >= 1.0 || s[2] < 0.2)) {
            if (s[2] > 0.9 || (s[2] > 0.5 && s[1] == 1.0)) {
                s[1] = 1.0;
                s[0] = 1.0;
                s[4] = an_from_bits(0x7ff8000000000000ULL);
            } else {
                if (s[4] != s[4]) {
                    s[4] = depth;
                }
                s[1] = 2.0;
                s[0] = 2.0;
            }
        }
    } else if (s[0] == 1.0) { /* track */
        s[2] = an_clamp01(s[2] - 0.1 * dt);
        if (an_jelly_phase(s, dt, w[3])) {
            s[0] = 0.0;
        } else {
            order = 1;
        }
    } else { /* hover */
        int reached = s[4] == s[4] && depth >= s[4];
        if (an_jelly_phase(s, dt, w[3]) || reached) {
            s[3] = 0.0;
            s[0] = 0.0;
        } else {
            order = 2;
        }
    }
    if (order != 0) { /* pulse_level */
        double p = 0.5 * an_sin(s[3]);
        pulse = 0.5 + (p < 0.0 ? 0.1 * p : p);
    }
    long long least = 0;
    int gradient = 0;
    for (long long i = 1; i < n; i++) {
        if (food[i] < food[least]) {
            least = i;
        }
        if (food[i] != food[0]) {
            gradient = 1;
        }
    }
    an_jelly_force(b, c, acts, axis, order != 0 ? pulse : acts[2]);
    for (long long i = 0; i < n; i++) {
        const double *a = acts + 5 * (i + 1);
        double level = a[2];
        if (order != 0) { /* balanced */
            level = 0.5 - w[4] * lean[i] * an_fabs(pulse);
        }
        if (order == 1) {
            if (gradient && i == least) {
                level = level + (an_fabs(pulse) - 0.5);
            } else {
                double wobble = 0.5 * an_sin((double)i * 5.0 * t + depth);
                level = level + w[5] * wobble * an_fabs(pulse);
            }
        }
        an_jelly_force(b, c, a, axis, level);
    }
}

/* Raibert's controller m (a network entry of kind 6) of a roobot, creature
 * c, whose state is st, at time t (roobot/raibert.rs: RaibertSenses::read,
 * then Raibert::think): thrust in stance once the hip stops falling, the
 * body's pitch servoed by the ankle in stance, the foot placed by the hip
 * in flight; its levels to the leg, hip and ankle. scenes.rs
 * `add_raibert` says how its numbers and state are laid out. */
AN_COLD void an_raibert(const an_batch *b, an_state st, long long c, long long m, double t, double dt) {
    const double *g = b->net_weight + b->net_first_weight[m];
    double *s = b->net_scratch + b->net_first_scratch[m];
    const double *x = st.x;
    const double *tilt_fwd = g + 13, *fwd = g + 20;
    const double *base = x + 3 * (long long)g[11], *tip = x + 3 * (long long)g[12];
    const double *hip = x + 3 * (long long)g[16], *foot = x + 3 * (long long)g[17];
    const double *head = x + 3 * (long long)g[18], *tail = x + 3 * (long long)g[19];
    const double *hv = st.v + 3 * (long long)g[16];
    double lean[3], body[3], leg[3];
    for (int d = 0; d < 3; d++) {
        lean[d] = tip[d] - base[d];
        body[d] = head[d] - tail[d];
        leg[d] = hip[d] - foot[d];
    }
    double foot_height = b->sensor_level[b->first_sensor[c] + (long long)g[10]];
    double angle = an_atan2(an_dot(lean, tilt_fwd), lean[1]);
    double pitch = an_atan2(body[1], an_dot(body, fwd));
    double climb = hv[1], v = an_dot(hv, fwd), length = sqrt(an_dot(leg, leg));
    /* Raibert::think */
    int down = foot_height <= 0.0;
    if (down && s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = 0.0;
        s[2] = t;
    } else if (!down && s[0] != 0.0) {
        s[0] = 0.0;
        if (t > s[2]) {
            s[3] = an_minnum(t - s[2], 1.0);
        }
    }
    double rate = s[4] == s[4] ? (angle - s[4]) / dt : 0.0;
    s[4] = angle;
    double pitch_rate = s[5] == s[5] ? (pitch - s[5]) / dt : 0.0;
    s[5] = pitch;
    double out[3];
    if (s[0] != 0.0) {
        if (climb >= 0.0) {
            s[1] = 1.0;
        }
        out[0] = g[1] + (s[1] != 0.0 ? g[0] : 0.0);
        double tau = -g[6] * pitch - g[7] * pitch_rate;
        out[2] = 0.5 + tau / (2.0 * g[9]);
        out[1] = 0.5;
    } else {
        out[0] = g[1];
        double ahead = v * s[3] / 2.0 + g[2] * (v - g[3]);
        double q = ahead / an_maxnum(length, 1e-3);
        if (q < -0.9) { /* f64::clamp */
            q = -0.9;
        }
        if (q > 0.9) {
            q = 0.9;
        }
        double target = -an_asin(q);
        double tau = -g[4] * (angle - target) - g[5] * rate;
        out[1] = 0.5 + tau / (2.0 * g[8]);
        out[2] = 0.5;
    }
    an_net_outputs(b, c, b->first_muscle[c], m, out, dt);
}

/* The nervous system of creature c acts at time t (nervous_system.rs
 * `act`): every sensor read, then every controller in the scene's order;
 * then the jellyfish (Scene::step: the actors after the nervous system). */
AN_FN void an_act(const an_batch *b, an_state st, long long c, double t, double dt) {
    long long k0 = b->first_ctrl[c], k1 = b->first_ctrl[c + 1];
    int gated = b->eval_param[AN_PARAMS * c + 15] != 0.0;
    if (k0 == k1 && !gated) {
        return;
    }
    for (long long q = b->first_sensor[c]; q < b->first_sensor[c + 1]; q++) {
        b->sensor_level[q] = an_sensor(b, st, q);
    }
    for (long long k = k0; k < k1; k++) {
        if (AN_HAS(b, AN_P_CONTROL << 0) && b->ctrl_kind[k] == 0) {
            an_oscillator(b, c, b->ctrl_index[k], t, dt);
        } else if (AN_HAS(b, AN_P_CONTROL << 1) && b->ctrl_kind[k] == 1) {
            an_network(b, c, b->ctrl_index[k], t, dt);
        } else if (AN_HAS(b, AN_P_CONTROL << 2) && b->ctrl_kind[k] == 2) {
            an_ctrnn(b, c, b->ctrl_index[k], t, dt);
        } else if (AN_HAS(b, AN_P_CONTROL << 4) && b->ctrl_kind[k] == 4) {
            an_hop(b, st, c, b->ctrl_index[k], dt);
        } else if (AN_HAS(b, AN_P_CONTROL << 3) && b->ctrl_kind[k] == 3) {
            an_fsm(b, c, b->ctrl_index[k], t, dt);
        } else if (AN_HAS(b, AN_P_CONTROL << 6) && b->ctrl_kind[k] == 6) {
            an_raibert(b, st, c, b->ctrl_index[k], t, dt);
        }
    }
    an_gates(b, c);
    for (long long k = k0; k < k1; k++) {
        if (AN_HAS(b, AN_P_CONTROL << 5) && b->ctrl_kind[k] == 5) {
            an_jellyfish(b, st, c, b->ctrl_index[k], t, dt);
        }
    }
}

/* scene::evaluate::centre_at: the centre of mass of particles ids[0 ..
 * nk - 1] of the creature whose state is st (of one: its position; of
 * massless ones: their mean). */
AN_FN void an_centre_of(an_state st, const int *ids, long long nk, double *out) {
    const double *x = st.x;
    if (nk == 1) {
        long long p = ids[0];
        for (int d = 0; d < 3; d++) {
            out[d] = x[3 * p + d];
        }
        return;
    }
    double sum[3] = {0.0, 0.0, 0.0}, m = 0.0;
    for (long long k = 0; k < nk; k++) {
        long long p = ids[k];
        double mp = st.m[p];
        for (int d = 0; d < 3; d++) {
            sum[d] = sum[d] + x[3 * p + d] * mp;
        }
        m = m + mp;
    }
    double by = m > 0.0 ? m : (double)(nk > 1 ? nk : 1);
    for (int d = 0; d < 3; d++) {
        out[d] = sum[d] / by;
    }
}

/* The centre of the particles of [evolve] that count. */
AN_FN void an_centre(const an_batch *b, an_state st, long long c, double *out) {
    long long k0 = b->first_centre[c];
    an_centre_of(st, b->centre_particle + k0, b->first_centre[c + 1] - k0, out);
}

/* Measures (scene/src/archive.rs, `Measure`), as packed. */
enum {
    AN_M_CONTACT = 0,      /* contact_fraction: one particle's steps on the floor */
    AN_M_FEET = 1,         /* feet: particles on the floor, a step */
    AN_M_DISPLACEMENT = 2, /* the centre's final offset along an axis */
    AN_M_MEAN_HEIGHT = 3,  /* the centre's height, a step */
    AN_M_SPEED = 4,        /* the displacement over the time survived */
    AN_M_FIXED = 5,        /* particles, muscles, mass, size: fixed when built */
    AN_M_ENERGY = 6        /* the muscles' positive work, J */
};

/* Measure q's particles and their number. */
AN_FN const int *an_measure_ids(const an_batch *b, long long q, long long *nk) {
    long long k0 = b->measure_first_id[q];
    *nk = b->measure_first_id[q + 1] - k0;
    return b->measure_id + k0;
}

/* Whether particle p of the creature whose state is st touches the
 * floor within `tolerance` (World::touches_ground). */
AN_FN int an_on_floor(const an_batch *b, an_state st, long long p, double tolerance) {
    return an_touches(b, st, p, tolerance);
}

/* Recorder::new: the centres that displacements and speeds start from. */
AN_FN void an_measures_begin(const an_batch *b, an_state st, long long c) {
    for (long long q = b->first_measure[c]; q < b->first_measure[c + 1]; q++) {
        long long nk;
        const int *ids = an_measure_ids(b, q, &nk);
        b->measure_sum[q] = 0.0;
        int kind = b->measure_kind[q];
        if (kind == AN_M_DISPLACEMENT || kind == AN_M_SPEED) {
            an_centre_of(st, ids, nk, b->measure_start + 3 * q);
        }
    }
}

/* Recorder::step: after each step. */
AN_FN void an_measures_step(const an_batch *b, an_state st, long long c) {
    long long p0 = b->first_particle[c], n = b->first_particle[c + 1] - p0;
    double tolerance = b->eval_param[AN_PARAMS * c + 5];
    for (long long q = b->first_measure[c]; q < b->first_measure[c + 1]; q++) {
        long long nk;
        const int *ids = an_measure_ids(b, q, &nk);
        int kind = b->measure_kind[q];
        if (kind == AN_M_CONTACT) {
            if (an_on_floor(b, st, ids[0], tolerance)) {
                b->measure_sum[q] = b->measure_sum[q] + 1.0;
            }
        } else if (kind == AN_M_FEET) {
            long long count = 0;
            for (long long i = 0; i < n; i++) {
                if (st.w[i] > 0.0 && an_on_floor(b, st, i, tolerance)) {
                    count++;
                }
            }
            b->measure_sum[q] = b->measure_sum[q] + (double)count;
        } else if (kind == AN_M_MEAN_HEIGHT) {
            double at[3];
            an_centre_of(st, ids, nk, at);
            b->measure_sum[q] = b->measure_sum[q] + at[1];
        }
    }
}

/* Recorder::finish: each measure's value, after `steps` steps and `time`
 * survived, into measure_sum. */
AN_FN void an_measures_finish(const an_batch *b, an_state st, long long c, long long steps, double time,
                               double work) {
    for (long long q = b->first_measure[c]; q < b->first_measure[c + 1]; q++) {
        long long nk;
        const int *ids = an_measure_ids(b, q, &nk);
        int kind = b->measure_kind[q];
        double value;
        if (kind == AN_M_CONTACT || kind == AN_M_FEET || kind == AN_M_MEAN_HEIGHT) {
            value = steps == 0 ? 0.0 : b->measure_sum[q] / (double)steps;
        } else if (kind == AN_M_DISPLACEMENT || kind == AN_M_SPEED) {
            double at[3], moved[3];
            an_centre_of(st, ids, nk, at);
            for (int d = 0; d < 3; d++) {
                moved[d] = at[d] - b->measure_start[3 * q + d];
            }
            value = an_dot(moved, b->measure_axis + 3 * q);
            if (kind == AN_M_SPEED) {
                value = time > 0.0 ? value / time : 0.0;
            }
        } else if (kind == AN_M_ENERGY) {
            value = work;
        } else {
            value = b->measure_fixed[q];
        }
        b->measure_sum[q] = value;
    }
}

/* EvolveSpec::ending: the first fail_on_touch particle within the
 * tolerance of the floor, else the first fail_on_stretch pair
 * stretched; AN_TIMEOUT where none holds. `which` gets the rule. */
AN_FN int an_ending(const an_batch *b, an_state st, long long c, long long *which) {
    const double *x = st.x;
    double tolerance = b->eval_param[AN_PARAMS * c + 5];
    for (long long k = b->first_touch[c]; k < b->first_touch[c + 1]; k++) {
        long long p = b->touch_particle[k];
        if (an_on_floor(b, st, p, tolerance)) {
            *which = k - b->first_touch[c];
            return AN_TOUCH;
        }
    }
    for (long long k = b->first_stretch[c]; k < b->first_stretch[c + 1]; k++) {
        long long pa = b->stretch_pair[2 * k], pb = b->stretch_pair[2 * k + 1];
        double d[3];
        for (int e = 0; e < 3; e++) {
            d[e] = x[3 * pa + e] - x[3 * pb + e];
        }
        if (sqrt(an_dot(d, d)) >= b->stretch_length[k]) {
            *which = k - b->first_stretch[c];
            return AN_STRETCH;
        }
    }
    return AN_TIMEOUT;
}

/* DivergenceGuard::check of a driven world: 0 where a particle that is
 * not fixed moves faster than 1000 m/s. */
AN_FN int an_guard(const an_batch *b, an_state st, long long c) {
    long long p0 = b->first_particle[c], n = b->first_particle[c + 1] - p0;
    const double *v = st.v;
    for (long long i = 0; i < n; i++) {
        if (!b->fixed[p0 + i] && an_dot(v + 3 * i, v + 3 * i) > 1000.0 * 1000.0) {
            return 0;
        }
    }
    return 1;
}

/* work.rs `omega`: the angular speed of torque joint k's end about its
 * axis (0 with the end on the axis). */
AN_FN double an_omega(const an_batch *b, an_state st, long long k) {
    const double *v = st.v;
    long long e = b->motor_end[k], j = b->motor_joint[k];
    double rp[3], n[3], dv[3];
    double l2 = an_lever(b, k, st.x, rp);
    if (l2 == 0.0) {
        return 0.0;
    }
    an_cross(b->motor_axis + 3 * k, rp, n);
    for (int d = 0; d < 3; d++) {
        dv[d] = v[3 * e + d] - v[3 * j + d];
    }
    return an_dot(n, dv) / l2;
}

/* work.rs `velocity_sum` of constant force q's pushed particles. */
AN_FN void an_push_velocity(const an_batch *b, an_state st, long long c, long long q, double *out) {
    long long k0 = b->first_push[c] + b->muscle_push[2 * q];
    out[0] = 0.0;
    out[1] = 0.0;
    out[2] = 0.0;
    for (long long k = k0; k < k0 + b->muscle_push[2 * q + 1]; k++) {
        const double *v = st.v + 3 * b->push_particle[k];
        for (int d = 0; d < 3; d++) {
            out[d] = out[d] + v[d];
        }
    }
}

/* The angle at angle joint k. */
AN_FN double an_joint_angle(const an_batch *b, an_state st, long long k) {
    const double *x = st.x;
    return an_angle_at(x + 3 * b->joint_a[k], x + 3 * b->joint_j[k], x + 3 * b->joint_b[k]);
}

/* work.rs `Work::before` for creature c's muscles: each one's state
 * before the step (a spring's length and rest length, an angle joint's
 * angle and rest angle, a motor's angular speed, a force's particles'
 * summed velocity), into muscle_work. */
AN_FN void an_work_before(const an_batch *b, an_state st, long long c) {
    const double *x = st.x;
    for (long long q = b->first_muscle[c]; q < b->first_muscle[c + 1]; q++) {
        double *w = b->muscle_work + 3 * q;
        long long i = b->muscle_spring[q];
        switch (b->muscle_kind[q]) {
        case 0: {
            long long s = b->first_spring[c] + i;
            double d[3];
            for (int k = 0; k < 3; k++) {
                d[k] = x[3 * b->spring_a[s] + k] - x[3 * b->spring_b[s] + k];
            }
            w[0] = sqrt(an_dot(d, d));
            w[1] = b->rest_length[s];
            break;
        }
        case 1: {
            long long k = b->first_joint[c] + i;
            w[0] = an_joint_angle(b, st, k);
            w[1] = b->joint_rest[k];
            break;
        }
        case 2:
            w[0] = an_omega(b, st, b->first_motor[c] + i);
            break;
        default:
            an_push_velocity(b, st, c, q, w);
            break;
        }
    }
}

/* work.rs `Work::after`: the positive work creature c's muscles did in
 * the step of length h, added to `positive` muscle by muscle. */
AN_FN double an_work_after(const an_batch *b, an_state st, long long c, double h, double positive) {
    for (long long q = b->first_muscle[c]; q < b->first_muscle[c + 1]; q++) {
        const double *w = b->muscle_work + 3 * q;
        long long i = b->muscle_spring[q];
        double done;
        switch (b->muscle_kind[q]) {
        case 0: {
            long long s = b->first_spring[c] + i;
            double now = w[0], rest = w[1], r = b->rest_length[s], k = b->stiffness[s];
            done = 0.5 * k * ((now - r) * (now - r) - (now - rest) * (now - rest));
            break;
        }
        case 1: {
            long long j = b->first_joint[c] + i;
            double now = w[0], rest = w[1], r = b->joint_rest[j], k = b->joint_stiffness[j];
            done = 0.5 * k * ((now - r) * (now - r) - (now - rest) * (now - rest));
            break;
        }
        case 2: {
            long long k = b->first_motor[c] + i;
            double end = an_omega(b, st, k);
            done = b->motor_torque[k] * 0.5 * (w[0] + end) * h;
            break;
        }
        default: {
            double after[3], mid[3], f[3];
            an_push_velocity(b, st, c, q, after);
            for (int d = 0; d < 3; d++) {
                mid[d] = 0.5 * (w[d] + after[d]);
            }
            /* The force now: its first push's vector (every push of a
             * force carries the same; a force on no particle does none). */
            long long k0 = b->first_push[c] + b->muscle_push[2 * q];
            if (b->muscle_push[2 * q + 1] == 0) {
                done = 0.0;
                break;
            }
            for (int d = 0; d < 3; d++) {
                f[d] = b->push_force[3 * k0 + d];
            }
            done = an_dot(f, mid) * h;
            break;
        }
        }
        if (done > 0.0) {
            positive = positive + done;
        }
    }
    return positive;
}

/* The evaluation of creature c (scene::evaluate::evaluate_with). */
AN_FN void an_evaluate_creature(const an_batch *b, an_state st, long long c) {
    const double *param = b->eval_param + AN_PARAMS * c;
    int work = param[8] != 0.0;
    double positive = 0.0;
    double dt = b->dt, t = param[6], carry = param[7];
    long long steps = b->eval_count[3 * c], taken = b->eval_count[3 * c + 1];
    long long done = 0, which = 0;
    double start[3], last[3], now[3];
    an_centre(b, st, c, start);
    for (int d = 0; d < 3; d++) {
        last[d] = start[d];
    }
    an_measures_begin(b, st, c);
    int why = an_ending(b, st, c, &which);
    if (why == AN_TIMEOUT) {
        while (done < steps) {
            if (work) {
                an_work_before(b, st, c);
            }
            an_act(b, st, c, t, dt); /* Scene::step: the nervous system first */
            if (!an_step_once(b, st, c, t)) {
                why = AN_BLOWUP;
                break;
            }
            /* World::advance_clock */
            double y = dt - carry;
            double t1 = t + y;
            carry = (t1 - t) - y;
            t = t1;
            taken++;
            if (taken % 64 == 0 && !an_guard(b, st, c)) {
                why = AN_BLOWUP;
                break;
            }
            if (work) {
                positive = an_work_after(b, st, c, dt, positive);
            }
            done++;
            an_measures_step(b, st, c);
            an_centre(b, st, c, now);
            if (!(now[0] - now[0] == 0.0 && now[1] - now[1] == 0.0 && now[2] - now[2] == 0.0)) {
                why = AN_BLOWUP;
                break;
            }
            for (int d = 0; d < 3; d++) {
                last[d] = now[d];
            }
            why = an_ending(b, st, c, &which);
            if (why != AN_TIMEOUT) {
                break;
            }
        }
    }
    double time = (double)done * dt;
    double moved[3];
    for (int d = 0; d < 3; d++) {
        moved[d] = last[d] - start[d];
    }
    double distance = an_dot(moved, param);
    if (why == AN_BLOWUP) {
        distance = distance < 0.0 ? distance : 0.0;
    }
    an_measures_finish(b, st, c, done, time, positive);
    double fitness = param[3] * time + param[4] * distance;
    if (param[9] != 0.0) { /* energy_weight */
        fitness -= param[9] * positive;
    }
    double off[3];
    for (int d = 0; d < 3; d++) {
        off[d] = last[d] - param[11 + d];
    }
    double target = sqrt(an_dot(off, off));
    if (param[10] != 0.0) { /* target, its weight */
        fitness -= param[14] * target;
    }
    /* The terms, after the archive's measures: each times its weight. */
    for (long long q = b->first_measure[c] + b->eval_count[3 * c + 2]; q < b->first_measure[c + 1];
         q++) {
        fitness = fitness + b->measure_weight[q] * b->measure_sum[q];
    }
    b->result[5 * c] = fitness;
    b->result[5 * c + 1] = distance;
    b->result[5 * c + 2] = time;
    b->result[5 * c + 3] = positive;
    b->result[5 * c + 4] = target;
    b->ended[2 * c] = why;
    b->ended[2 * c + 1] = which;
}

/* Creature c evaluated, its state held as an_step_in holds it. */
AN_FN void an_evaluate_in(const an_batch *b, long long c, int local) {
    an_local_store m;
    int fits = 0;
    an_state st = local ? an_local(b, c, &m, &fits) : an_batch_state(b, c);
    an_evaluate_creature(b, st, c);
    if (fits) {
        an_local_done(b, c, st);
    }
}

#endif
