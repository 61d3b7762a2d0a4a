// Compiles the CUDA kernels of kernels/*.cu as C++ on the host, for the host
// executor (src/engine/cuda/host.rs): the built-ins a kernel reads (its thread's
// and block's indices and the launch's dimensions, thread-local and set by the
// executor before each thread's call), and the qualifiers and math functions CUDA
// provides without includes. Kernels use nothing else of CUDA yet (no shared
// memory, no atomics, no synchronisation within a block).
#pragma once

#include <cmath>

struct dim3 {
    unsigned x = 0, y = 0, z = 0;
};

extern thread_local dim3 threadIdx, blockIdx, blockDim, gridDim;

#define __global__
#define __device__
#define __forceinline__ inline

using std::fmax;
using std::fmin;
using std::sqrt;
