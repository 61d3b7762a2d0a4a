// Compiles the CUDA kernels of kernels/*.cu as C++ on the host, for the host
// executor (src/engine/cuda/host.rs): the built-ins a kernel reads (its thread's
// and block's indices and the launch's dimensions, thread-local and set by the
// executor before each thread's call), the qualifiers, the math functions CUDA
// provides without includes, and the atomics the kernels use (relaxed, as CUDA's).
// Kernels use no shared memory and no synchronisation within a block.
#pragma once

#include <cmath>

struct dim3 {
    unsigned x = 0, y = 0, z = 0;
};

extern thread_local dim3 threadIdx, blockIdx, blockDim, gridDim;

#define __global__
#define __device__
#define __forceinline__ inline

using std::cbrt;
using std::copysign;
using std::fabs;
using std::floor;
using std::isfinite;
using std::round;
using std::fmax;
using std::fmin;
using std::sqrt;

// One more than the index of the lowest set bit; 0 for none.
static inline int __ffsll(long long x) {
    return __builtin_ffsll(x);
}

static inline unsigned atomicAdd(unsigned* address, unsigned value) {
    return __atomic_fetch_add(address, value, __ATOMIC_RELAXED);
}

static inline unsigned atomicOr(unsigned* address, unsigned value) {
    return __atomic_fetch_or(address, value, __ATOMIC_RELAXED);
}
