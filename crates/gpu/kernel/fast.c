/* The C evaluation on the CPU in fast mode: contraction into fused
 * multiply-adds allowed (build.rs compiles this file with
 * -ffp-contract=fast and, on x86-64, -mfma), what a GPU's opt-in fast mode
 * (`--fmad=true`, src/cuda.rs) does, on the CPU. Not the engine's bits:
 * tests/evaluate.rs checks it by tolerance and by the ranking of a population.
 * Called only where the CPU has FMA (src/scenes.rs). */
#include "step.h"
#include "libm.h"
#include "trig.h"
#include "exp.h"
#include "eval.h"

/* Creatures first .. last - 1 of a batch evaluated whole, in fast mode. */
void animats_evaluate_range_fast(const an_batch *b, long long first, long long last, int local) {
    for (long long c = first; c < last; c++) {
        an_evaluate_in(b, c, local);
    }
}
