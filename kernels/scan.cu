// Exclusive prefix sums of 32-bit counts, in place, in three launches over chunks
// of SCAN_CHUNK entries: each chunk's total (one thread per chunk), the totals'
// prefix sums (one thread, serially), and each chunk's entries offset by its
// prefix (one thread per chunk). An array of n counts has n + 1 entries; the last
// receives the sum of all. The chunk count is n / SCAN_CHUNK + 1 (the last chunk
// may be empty, so an empty array gets its total too). The serial middle pass is
// n / 256 additions: 4 000 for a million particles, against the chunks' million.

#define SCAN_CHUNK 256u

static __device__ __forceinline__ unsigned scan_chunks(unsigned n) {
    return n / SCAN_CHUNK + 1;
}

extern "C" __global__ void scan_chunk_totals(unsigned n, const unsigned* values,
                                             unsigned* totals) {
    unsigned c = blockIdx.x * blockDim.x + threadIdx.x;
    if (c >= scan_chunks(n)) {
        return;
    }
    unsigned begin = c * SCAN_CHUNK;
    unsigned end = begin + SCAN_CHUNK < n ? begin + SCAN_CHUNK : n;
    unsigned sum = 0;
    for (unsigned i = begin; i < end; ++i) {
        sum += values[i];
    }
    totals[c] = sum;
}

extern "C" __global__ void scan_chunk_offsets(unsigned n, unsigned* totals) {
    if (blockIdx.x * blockDim.x + threadIdx.x != 0) {
        return;
    }
    unsigned sum = 0;
    for (unsigned c = 0; c < scan_chunks(n); ++c) {
        unsigned t = totals[c];
        totals[c] = sum;
        sum += t;
    }
}

extern "C" __global__ void scan_apply(unsigned n, unsigned* values, const unsigned* offsets) {
    unsigned c = blockIdx.x * blockDim.x + threadIdx.x;
    unsigned chunks = scan_chunks(n);
    if (c >= chunks) {
        return;
    }
    unsigned begin = c * SCAN_CHUNK;
    unsigned end = begin + SCAN_CHUNK < n ? begin + SCAN_CHUNK : n;
    unsigned sum = offsets[c];
    for (unsigned i = begin; i < end; ++i) {
        unsigned v = values[i];
        values[i] = sum;
        sum += v;
    }
    if (c + 1 == chunks) {
        values[n] = sum;
    }
}

// Sets n 32-bit words to zero.
extern "C" __global__ void zero_words(unsigned n, unsigned* values) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) {
        values[i] = 0;
    }
}

// Copies n 32-bit words.
extern "C" __global__ void copy_words(unsigned n, const unsigned* from, unsigned* to) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) {
        to[i] = from[i];
    }
}
