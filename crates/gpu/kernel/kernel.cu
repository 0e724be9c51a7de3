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

/* One thread evaluates one creature of the batch whole (eval.h). */
extern "C" __global__ void animats_evaluate_kernel(const __grid_constant__ an_batch b,
                                                   long long creatures, int local) {
    long long c = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (c < creatures) {
        an_evaluate_in(&b, c, local);
    }
}
