/* The C step on the CPU: every creature of a batch, one after another. */
#include "step.h"

void animats_step_batch(const an_batch *b, long long creatures, long long steps) {
    for (long long c = 0; c < creatures; c++) {
        an_step_creature(b, c, steps);
    }
}
