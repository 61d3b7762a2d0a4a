// Deterministic sums of records (rows of `width` doubles) in passes of many
// threads (engine/cuda/device_sums.rs). A pass folds `count` records into
// `groups`: thread (t, c) sums column c of records t, t + groups, t + 2 groups, …
// (neighbouring threads read neighbouring doubles) into four partial sums in turn,
// so that four loads are in flight, then adds them pairwise. The passes repeat
// until one record is left. The order of the additions is fixed by the count of
// records and the width alone, so every run and every block size gives the same
// bits; they differ from a serial sum of the same terms by round-off.

// The terms at[0], at[step], at[2 step], … below `end` (as offsets), summed into
// four partial sums in turn and those added pairwise.
static __device__ __forceinline__ double strided_sum(const double* at, size_t end,
                                                     size_t step) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    size_t k = 0;
    for (; k + 3 * step < end; k += 4 * step) {
        a0 += at[k];
        a1 += at[k + step];
        a2 += at[k + 2 * step];
        a3 += at[k + 3 * step];
    }
    for (; k < end; k += step) {
        a0 += at[k];
    }
    return (a0 + a1) + (a2 + a3);
}

// Thread g's share of a pass over `count` records of `width` doubles folded into
// `groups`: column c of record t, whose terms are at `first`, `first + step`, …
// below `end` (offsets into the records; none where t ≥ count). False for a thread
// beyond the pass.
static __device__ __forceinline__ bool record_column(unsigned count, unsigned width,
                                                     unsigned groups, size_t* first,
                                                     size_t* end, size_t* step) {
    unsigned g = blockIdx.x * blockDim.x + threadIdx.x;
    if (g >= groups * width) {
        return false;
    }
    unsigned t = g / width, c = g % width;
    *first = (size_t)width * t + c;
    *end = count > t ? (size_t)width * (count - t) : 0;
    *step = (size_t)width * groups;
    return true;
}

// The records are written from double `offset` of `out`.
extern "C" __global__ void sum_records(unsigned count, unsigned width, const double* in,
                                       unsigned groups, double* out, unsigned offset) {
    size_t first, end, step;
    if (record_column(count, width, groups, &first, &end, &step)) {
        // No term (end 0) sums to +0.
        out[offset + first] = strided_sum(in + first, end, step);
    }
}

// The largest of the terms at[0], at[step], at[2 step], … below `end`.
static __device__ __forceinline__ double strided_max(const double* at, size_t end, size_t step,
                                                     double lowest) {
    double m = lowest;
    for (size_t k = 0; k < end; k += step) {
        m = fmax(m, at[k]);
    }
    return m;
}

// As sum_records, each column's largest instead of its sum (`lowest` where a group
// has no record).
extern "C" __global__ void max_records(unsigned count, unsigned width, const double* in,
                                       unsigned groups, double* out, unsigned offset,
                                       double lowest) {
    size_t first, end, step;
    if (record_column(count, width, groups, &first, &end, &step)) {
        out[offset + first] = strided_max(in + first, end, step, lowest);
    }
}

// The first pass over the pairs' energy terms (spheres.cu): thread t of `groups`
// sums the elastic energy and the dissipation of pairs t, t + groups, … into record
// t of `records` (ENERGY_RECORD doubles: energy, dissipated, wall contacts = 0, the
// pairs that touch and the candidate pairs, both of those this world counts,
// counted exactly).
extern "C" __global__ void pair_energy_partials(unsigned pair_count, const double* energies,
                                                const unsigned char* touching,
                                                unsigned groups, double* records) {
    unsigned t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= groups) {
        return;
    }
    size_t first = (size_t)PAIR_ENERGY_DOUBLES * t;
    size_t end = pair_count > t ? (size_t)PAIR_ENERGY_DOUBLES * (pair_count - t) : 0;
    size_t step = (size_t)PAIR_ENERGY_DOUBLES * groups;
    records[ENERGY_RECORD * t] = strided_sum(energies + first, end, step);
    records[ENERGY_RECORD * t + 1] = strided_sum(energies + first + 1, end, step);
    records[ENERGY_RECORD * t + 2] = 0.0;
    unsigned touches = 0, counted = 0;
    for (unsigned e = t; e < pair_count; e += groups) {
        touches += touching[e] == (PAIR_TOUCHES | PAIR_COUNTED);
        counted += (touching[e] & PAIR_COUNTED) != 0;
    }
    records[ENERGY_RECORD * t + 3] = (double)touches;
    records[ENERGY_RECORD * t + 4] = (double)counted;
}
