// The candidate list of a world of spheres (engine/neighbours.rs, broad_phase.rs):
// every pair (i, j), i < j, whose centres are closer than r_i + r_j + skin, in one
// flat array of pairs sorted by (i, j), and for every particle the pairs that hold
// it in the order of its partners' space keys (cell code, then id). With particles
// stored in the order of their ids (the device stepper requires it) that is the
// CPU backend's list: the same pairs, each particle's in the same order.
//
// Particles are binned on a hashed grid of cells at least as wide as the largest
// reach (so a particle's partners lie in the 27 cells about its own): the hash
// needs no bounding box, hence no reduction before the binning. Two of the 27
// cells may share a bucket; a bucket is visited once. Binning scatters with
// atomics, in an order that changes from run to run; each particle sorts the
// partners it found, so the list does not.
//
// Layouts: pairs as 2 unsigned (i, j); an incidence as the pair's index with the
// top bit set where the particle is the pair's first; pair keys as 2 unsigned long
// long (the ids of i and j at the build).

#define FIRST_ROLE 0x80000000u

// A cell coordinate, clamped so that a particle far away (or not finite) still
// gets a cell.
static __device__ __forceinline__ long long cell_coord(double x, double cell) {
    double c = floor(x / cell);
    if (!(c >= -1e15)) {
        c = -1e15;
    }
    if (c > 1e15) {
        c = 1e15;
    }
    return (long long)c;
}

static __device__ __forceinline__ unsigned cell_bucket(long long x, long long y, long long z,
                                                       unsigned mask) {
    unsigned long long h = (unsigned long long)x * 73856093ull ^
                           (unsigned long long)y * 19349663ull ^
                           (unsigned long long)z * 83492791ull;
    return (unsigned)(h ^ (h >> 29)) & mask;
}

// The grid: cells of edge `cell`, `mask + 1` buckets (a power of two);
// sorted[starts[b]..starts[b + 1]] are the particles of bucket b.
struct Grid {
    double cell;
    unsigned mask;
    const unsigned* starts;
    const unsigned* sorted;
};

// Calls found(j) for every partner j > i of particle i, in the order of the cells
// and buckets (not sorted).
template <typename Found>
static __device__ void for_partners(unsigned i, const double* position, const unsigned* body_type,
                                    const double* type_radius, double skin, Grid grid,
                                    Found found) {
    Vec3 p = load3(position, i);
    long long cx = cell_coord(p.x, grid.cell);
    long long cy = cell_coord(p.y, grid.cell);
    long long cz = cell_coord(p.z, grid.cell);
    double ri = type_radius[body_type[i]];
    unsigned seen[27];
    int visited = 0;
    for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                unsigned b = cell_bucket(cx + dx, cy + dy, cz + dz, grid.mask);
                bool again = false;
                for (int k = 0; k < visited; ++k) {
                    again = again || seen[k] == b;
                }
                if (again) {
                    continue;
                }
                seen[visited++] = b;
                for (unsigned s = grid.starts[b]; s < grid.starts[b + 1]; ++s) {
                    unsigned j = grid.sorted[s];
                    if (j <= i) {
                        continue;
                    }
                    double reach = ri + type_radius[body_type[j]] + skin;
                    if (norm_squared(sub(load3(position, j), p)) < reach * reach) {
                        found(j);
                    }
                }
            }
        }
    }
}

// One thread per particle: its bucket, counted (counts zeroed before).
extern "C" __global__ void bin_particles(unsigned n, const double* position, double cell,
                                         unsigned mask, unsigned* bucket, unsigned* counts) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    Vec3 p = load3(position, i);
    unsigned b = cell_bucket(cell_coord(p.x, cell), cell_coord(p.y, cell), cell_coord(p.z, cell),
                             mask);
    bucket[i] = b;
    atomicAdd(&counts[b], 1u);
}

// One thread per particle: into its bucket's slice (fill: a copy of the starts).
extern "C" __global__ void scatter_particles(unsigned n, const unsigned* bucket, unsigned* fill,
                                             unsigned* sorted) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    sorted[atomicAdd(&fill[bucket[i]], 1u)] = i;
}

// One thread per particle: how many partners j > i it has.
extern "C" __global__ void count_partners(unsigned n, const double* position,
                                          const unsigned* body_type, const double* type_radius,
                                          double skin, double cell, unsigned mask,
                                          const unsigned* starts, const unsigned* sorted,
                                          unsigned* counts) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    unsigned k = 0;
    for_partners(i, position, body_type, type_radius, skin, Grid{cell, mask, starts, sorted},
                 [&](unsigned) { ++k; });
    counts[i] = k;
}

// One thread per particle: its pairs (i, j) at offsets[i].., sorted by j.
extern "C" __global__ void write_partners(unsigned n, const double* position,
                                          const unsigned* body_type, const double* type_radius,
                                          double skin, double cell, unsigned mask,
                                          const unsigned* starts, const unsigned* sorted,
                                          const unsigned* offsets, unsigned* pairs) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    unsigned begin = offsets[i];
    unsigned end = begin;
    for_partners(i, position, body_type, type_radius, skin, Grid{cell, mask, starts, sorted},
                 [&](unsigned j) {
                     pairs[2 * end] = i;
                     pairs[2 * end + 1] = j;
                     ++end;
                 });
    for (unsigned a = begin + 1; a < end; ++a) {
        unsigned j = pairs[2 * a + 1];
        unsigned b = a;
        for (; b > begin && pairs[2 * (b - 1) + 1] > j; --b) {
            pairs[2 * b + 1] = pairs[2 * (b - 1) + 1];
        }
        pairs[2 * b + 1] = j;
    }
}

// One thread per pair: counts it for both its particles (counts zeroed before).
extern "C" __global__ void count_incident(unsigned pair_count, const unsigned* pairs,
                                          unsigned* counts) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    atomicAdd(&counts[pairs[2 * e]], 1u);
    atomicAdd(&counts[pairs[2 * e + 1]], 1u);
}

// One thread per pair: into both particles' incidence slices (fill: a copy of the
// starts), unsorted.
extern "C" __global__ void fill_incident(unsigned pair_count, const unsigned* pairs,
                                         unsigned* fill, unsigned* incident) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    incident[atomicAdd(&fill[pairs[2 * e]], 1u)] = e | FIRST_ROLE;
    incident[atomicAdd(&fill[pairs[2 * e + 1]], 1u)] = e;
}

// Whether particle k's incidence `a` comes after `b`: by the partners' space keys
// (cell code, then id; the slots are in id order), the CPU backend's order.
static __device__ __forceinline__ bool partner_after(unsigned a, unsigned b, const unsigned* pairs,
                                                     const unsigned long long* cell_code) {
    unsigned pa = pairs[2 * (a & ~FIRST_ROLE) + ((a & FIRST_ROLE) ? 1 : 0)];
    unsigned pb = pairs[2 * (b & ~FIRST_ROLE) + ((b & FIRST_ROLE) ? 1 : 0)];
    return cell_code[pa] > cell_code[pb] || (cell_code[pa] == cell_code[pb] && pa > pb);
}

// One thread per particle: its incidences sorted by its partners' space keys.
extern "C" __global__ void sort_incident(unsigned n, const unsigned* pairs,
                                         const unsigned long long* cell_code,
                                         const unsigned* starts, unsigned* incident) {
    unsigned k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= n) {
        return;
    }
    unsigned begin = starts[k];
    for (unsigned a = begin + 1; a < starts[k + 1]; ++a) {
        unsigned entry = incident[a];
        unsigned b = a;
        for (; b > begin && partner_after(incident[b - 1], entry, pairs, cell_code); --b) {
            incident[b] = incident[b - 1];
        }
        incident[b] = entry;
    }
}

// One thread per pair: its key, the ids of its particles.
extern "C" __global__ void pair_keys(unsigned pair_count, const unsigned* pairs,
                                     const unsigned long long* id, unsigned long long* keys) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    keys[2 * e] = id[pairs[2 * e]];
    keys[2 * e + 1] = id[pairs[2 * e + 1]];
}

// One thread per pair of the new list: the tangential history (`width` doubles)
// the same two particles held in the old list (found by their ids among the old
// list's sorted keys), or none.
extern "C" __global__ void carry_history(unsigned pair_count, unsigned width,
                                         const unsigned long long* keys,
                                         unsigned old_count, const unsigned long long* old_keys,
                                         const double* old_history, double* history) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    unsigned long long a = keys[2 * e], b = keys[2 * e + 1];
    unsigned lo = 0, hi = old_count;
    while (lo < hi) {
        unsigned mid = lo + (hi - lo) / 2;
        unsigned long long ma = old_keys[2 * mid], mb = old_keys[2 * mid + 1];
        if (ma < a || (ma == a && mb < b)) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    bool found = lo < old_count && old_keys[2 * lo] == a && old_keys[2 * lo + 1] == b;
    for (unsigned k = 0; k < width; ++k) {
        history[width * e + k] = found ? old_history[width * lo + k] : 0.0;
    }
}

// One thread per particle: flags (sets *moved to 1) when it has moved by
// sqrt(limit) or more since the build, from anchors (3 doubles each).
extern "C" __global__ void moved_too_far(unsigned n, const double* position,
                                         const double* anchors, double limit, unsigned* moved) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    if (norm_squared(sub(load3(position, i), load3(anchors, i))) >= limit) {
        atomicOr(moved, 1u);
    }
}

// Copies n doubles.
extern "C" __global__ void copy_doubles(unsigned n, const double* from, double* to) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) {
        to[i] = from[i];
    }
}
