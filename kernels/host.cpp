// The kernels compiled for the host executor (src/engine/cuda/host.rs): the
// thread-local built-ins, vec.cuh and the kernels themselves, and for each kernel a
// trampoline that takes its parameters as cuLaunchKernel does (an array of pointers
// to each argument), so the executor launches a kernel as the driver would. The
// trampolines are found by the kernel's name (`talus_host_kernel`).
#include <cstring>
#include <utility>

#include "host.h"

thread_local dim3 threadIdx, blockIdx, blockDim, gridDim;

#include "vec.cuh"
#include "contact.cuh"
#include "body.cuh"
#include "triangle.cuh"
#include "overlap.cuh"
#include "round_geometry.cuh"
#include "volume_law.cuh"
#include "facet.cuh"
#include "facet_grid.cuh"
#include "wall_patches.cuh"

#include "integrate.cu"
#include "list.cu"
#include "scan.cu"
#include "spheres.cu"
#include "walls.cu"
#include "sums.cu"
#include "halo.cu"
#include "figures.cu"
#include "polyhedra.cu"
#include "pairs.cu"

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

// Calls `kernel` with the argument each of `p` points to, typed by the kernel's
// own parameter list.
template <typename... A, std::size_t... K>
static void call(void (*kernel)(A...), void** p, std::index_sequence<K...>) {
    kernel(*static_cast<A*>(p[K])...);
}

template <typename... A>
static void call(void (*kernel)(A...), void** p) {
    call(kernel, p, std::index_sequence_for<A...>{});
}

using Trampoline = void (*)(void**);

struct Entry {
    const char* name;
    Trampoline trampoline;
};

#define KERNEL(name) {#name, [](void** p) { call(name, p); }}

static const Entry kernels[] = {
    KERNEL(kick_drift),        KERNEL(closing_kick),     KERNEL(bin_particles),
    KERNEL(scatter_particles), KERNEL(count_partners),   KERNEL(write_partners),
    KERNEL(count_incident),    KERNEL(fill_incident),    KERNEL(sort_incident),
    KERNEL(pair_keys),         KERNEL(carry_history),    KERNEL(moved_too_far),
    KERNEL(copy_doubles),      KERNEL(scan_chunk_totals), KERNEL(scan_chunk_offsets),
    KERNEL(scan_apply),        KERNEL(zero_words),       KERNEL(copy_words),
    KERNEL(sphere_contacts),   KERNEL(gather_forces),
    KERNEL(sphere_walls),      KERNEL(wall_sum_rows),    KERNEL(wall_energy_terms),
    KERNEL(pair_energy_partials), KERNEL(sum_records),
    KERNEL(pack_states),       KERNEL(unpack_ghost_states), KERNEL(max_records),
    KERNEL(particle_figures),  KERNEL(polyhedron_overlaps),
    KERNEL(pair_contacts), KERNEL(polyhedron_facets),
    KERNEL(polyhedron_wall_patches), KERNEL(polyhedron_wall_contacts),
    KERNEL(polyhedron_wall_sum_rows),
};

// The trampoline of the kernel named `name`, or null.
extern "C" Trampoline talus_host_kernel(const char* name) {
    for (const Entry& e : kernels) {
        if (std::strcmp(e.name, name) == 0) {
            return e.trampoline;
        }
    }
    return nullptr;
}
