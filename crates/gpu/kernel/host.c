/* The C step on the CPU: every creature of a batch, one after another. */
#include "step.h"

void animats_step_batch(const an_batch *b, long long creatures, long long steps) {
    for (long long c = 0; c < creatures; c++) {
        an_step_creature(b, c, steps);
    }
}

/* The ported functions, for their tests against the `libm` crate. */
#include "libm.h"

double animats_atan(double x) { return an_atan(x); }
double animats_atan2(double y, double x) { return an_atan2(y, x); }

#include "trig.h"

double animats_sin(double x) { return an_sin(x); }
double animats_cos(double x) { return an_cos(x); }
