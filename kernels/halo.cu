// The halo of an MPI rank's share (engine/rank, engine/cuda/spheres): the states of
// the owned particles other ranks hold as ghosts, packed for the host to send, and
// the ghosts' states the host received, unpacked into their slots. Only these cross
// between device and host in a step without a renewal.
//
// A state record is HALO_DOUBLES doubles: position (3), orientation (i, j, k, w),
// velocity (3), angular momentum (3), and frozen (0 or 1; a ghost's may change
// between steps, by its owner's bed measurement). Layouts of the particles as in
// integrate.cu.

#define HALO_DOUBLES 14u

// One thread per record: the state of particle slots[r] into record r.
extern "C" __global__ void pack_states(unsigned count, const unsigned* slots,
                                       const double* position, const double* orientation,
                                       const double* velocity, const double* angular_momentum,
                                       const unsigned char* role, double* records) {
    unsigned r = blockIdx.x * blockDim.x + threadIdx.x;
    if (r >= count) {
        return;
    }
    unsigned i = slots[r];
    double* out = records + HALO_DOUBLES * r;
    for (unsigned c = 0; c < 3; ++c) {
        out[c] = position[3 * i + c];
        out[7 + c] = velocity[3 * i + c];
        out[10 + c] = angular_momentum[3 * i + c];
    }
    for (unsigned c = 0; c < 4; ++c) {
        out[3 + c] = orientation[4 * i + c];
    }
    out[13] = (role[i] & FROZEN_ROLE) ? 1.0 : 0.0;
}

// One thread per record: record r into particle slots[r], a ghost (its role set
// from the record's frozen flag).
extern "C" __global__ void unpack_ghost_states(unsigned count, const unsigned* slots,
                                               const double* records, double* position,
                                               double* orientation, double* velocity,
                                               double* angular_momentum, unsigned char* role) {
    unsigned r = blockIdx.x * blockDim.x + threadIdx.x;
    if (r >= count) {
        return;
    }
    unsigned i = slots[r];
    const double* in = records + HALO_DOUBLES * r;
    for (unsigned c = 0; c < 3; ++c) {
        position[3 * i + c] = in[c];
        velocity[3 * i + c] = in[7 + c];
        angular_momentum[3 * i + c] = in[10 + c];
    }
    for (unsigned c = 0; c < 4; ++c) {
        orientation[4 * i + c] = in[3 + c];
    }
    role[i] = GHOST_ROLE | (in[13] != 0.0 ? FROZEN_ROLE : 0u);
}
