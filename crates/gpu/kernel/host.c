/* The C step on the CPU. */
#include "step.h"

/* The ported functions, for their tests against the `libm` crate. */
#include "libm.h"

double animats_atan(double x) { return an_atan(x); }
double animats_atan2(double y, double x) { return an_atan2(y, x); }
double animats_hypot(double x, double y) { return an_hypot(x, y); }
double animats_asin(double x) { return an_asin(x); }

#include "trig.h"
#include "exp.h"
#include "eval.h"

double animats_sin(double x) { return an_sin(x); }
double animats_cos(double x) { return an_cos(x); }
double animats_exp(double x) { return an_exp(x); }
double animats_expm1(double x) { return an_expm1(x); }
double animats_tanh(double x) { return an_tanh(x); }

/* Creatures first .. last - 1 of a batch: the CPU's threads each take a
 * range (every creature writes only its own particles and scratch); local:
 * each creature's state in arrays of the thread's own while it is stepped
 * (an_step_in). */
void animats_step_range(const an_batch *b, long long first, long long last, long long steps,
                        int local) {
    for (long long c = first; c < last; c++) {
        an_step_in(b, c, steps, local);
    }
}

/* Creatures first .. last - 1 of a batch evaluated whole (eval.h). */
void animats_evaluate_range(const an_batch *b, long long first, long long last, int local) {
    for (long long c = first; c < last; c++) {
        an_evaluate_in(b, c, local);
    }
}
