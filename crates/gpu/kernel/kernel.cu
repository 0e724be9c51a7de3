/* The GPU's entry: one thread steps one creature of the batch. The
 * headers are prepended to this file when it is compiled (src/cuda.rs). */
extern "C" __global__ void animats_step_kernel(an_batch b, long long creatures, long long steps) {
    long long c = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (c < creatures) {
        an_step_creature(&b, c, steps);
    }
}

/* One thread evaluates one creature of the batch whole (eval.h). */
extern "C" __global__ void animats_evaluate_kernel(an_batch b, long long creatures) {
    long long c = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (c < creatures) {
        an_evaluate_creature(&b, c);
    }
}
