// The kernels compiled for the host executor (src/engine/cuda/host.rs): the
// thread-local built-ins, the kernels themselves, and for each kernel a trampoline
// that takes its parameters as cuLaunchKernel does (an array of pointers to each
// argument), so the executor launches a kernel as the driver would.
#include "host.h"

thread_local dim3 threadIdx, blockIdx, blockDim, gridDim;

#include "integrate.cu"

// Sets the built-ins of the calling thread before it runs one kernel thread.
extern "C" void talus_host_at(unsigned block, unsigned thread, unsigned block_dim,
                              unsigned grid_dim) {
    blockIdx.x = block;
    threadIdx.x = thread;
    blockDim.x = block_dim;
    gridDim.x = grid_dim;
    blockIdx.y = blockIdx.z = threadIdx.y = threadIdx.z = 0;
    blockDim.y = blockDim.z = gridDim.y = gridDim.z = 1;
}

template <typename T>
static T arg(void** p, int k) {
    return *static_cast<T*>(p[k]);
}

extern "C" void talus_host_closing_kick(void** p) {
    closing_kick(arg<unsigned>(p, 0), arg<double>(p, 1), arg<double*>(p, 2), arg<double*>(p, 3),
                 arg<const double*>(p, 4), arg<const double*>(p, 5), arg<const unsigned*>(p, 6),
                 arg<const unsigned char*>(p, 7), arg<const double*>(p, 8));
}

extern "C" void talus_host_kick_drift(void** p) {
    kick_drift(arg<unsigned>(p, 0), arg<double>(p, 1), arg<double*>(p, 2), arg<double*>(p, 3),
               arg<double*>(p, 4), arg<double*>(p, 5), arg<const double*>(p, 6),
               arg<const double*>(p, 7), arg<const unsigned*>(p, 8),
               arg<const unsigned char*>(p, 9), arg<const double*>(p, 10),
               arg<const double*>(p, 11));
}
