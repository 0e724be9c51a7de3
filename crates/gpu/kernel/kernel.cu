/* The GPU's entries: one thread steps (or evaluates) one creature of the
 * batch; `local` 1 holds each creature's state in the thread's local
 * memory where it fits (an_step_in), 0 in the batch's arrays. The headers
 * are prepended to this file when it is compiled (src/cuda.rs). The batch
 * is a __grid_constant__ parameter, so that taking its address reads it
 * where it was passed instead of copying it into each thread's memory. */
extern "C" __global__ void animats_step_kernel(const __grid_constant__ an_batch b,
                                               long long creatures, long long steps, int local) {
    long long c = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (c < creatures) {
        an_step_in(&b, c, steps, local);
    }
}

/* One thread evaluates one creature of the batch whole (eval.h): the
 * creature of its own index (queue 0), or (queue 1) the next creature not
 * yet taken, from the shared counter *next, until none is left. */
extern "C" __global__ void animats_evaluate_kernel(const __grid_constant__ an_batch b,
                                                   long long creatures, int local,
                                                   unsigned long long *next, int queue) {
    unsigned long long c = (unsigned long long)blockIdx.x * blockDim.x + threadIdx.x;
    for (;;) { /* (one call site: one copy of the evaluation's code) */
        if (queue) {
            c = atomicAdd(next, 1ULL);
        }
        if (c >= (unsigned long long)creatures) {
            return;
        }
        an_evaluate_in(&b, (long long)c, local);
        if (!queue) {
            return;
        }
    }
}
