// Deterministic sums of records (rows of `width` doubles) in passes of many
// threads (engine/cuda/device_sums.rs). A pass folds `count` records into
// `groups`: thread (t, c) sums column c of records t, t + groups, t + 2 groups, …
// in that order (neighbouring threads read neighbouring doubles). The passes repeat
// until one record is left. The order of the additions is fixed by the count of
// records and the width alone, so every run and every block size gives the same
// bits; they differ from a serial sum of the same terms by round-off.

extern "C" __global__ void sum_records(unsigned count, unsigned width, const double* in,
                                       unsigned groups, double* out) {
    unsigned g = blockIdx.x * blockDim.x + threadIdx.x;
    if (g >= groups * width) {
        return;
    }
    unsigned t = g / width, c = g % width;
    double sum = 0.0;
    for (unsigned r = t; r < count; r += groups) {
        sum += in[(size_t)width * r + c];
    }
    out[(size_t)width * t + c] = sum;
}

// The first pass over the pairs' results (contact.cuh): thread t of `groups` sums
// the elastic energy and the dissipation of pairs t, t + groups, … into record t
// of `records` (ENERGY_RECORD doubles: energy, dissipated, wall contacts = 0).
extern "C" __global__ void pair_energy_partials(unsigned pair_count, const double* results,
                                                unsigned groups, double* records) {
    unsigned t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= groups) {
        return;
    }
    double energy = 0.0, dissipated = 0.0;
    for (unsigned e = t; e < pair_count; e += groups) {
        energy += results[RESULT_DOUBLES * e + 9];
        dissipated += results[RESULT_DOUBLES * e + 10];
    }
    records[ENERGY_RECORD * t] = energy;
    records[ENERGY_RECORD * t + 1] = dissipated;
    records[ENERGY_RECORD * t + 2] = 0.0;
}
