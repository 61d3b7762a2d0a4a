// Figures of the owned particles (world/figures.rs, RunFigures) as records that
// sums.cu folds: one thread per particle writes a record of sums (1, frozen,
// m, m x, m y, m z, kinetic energy, potential energy: FIGURE_SUMS doubles) and a
// record of extrema, folded by their largest (speed, x, y, z, -x, -y, -z, and
// -id where the particle's state is not finite: FIGURE_EXTREMA doubles). A ghost
// writes zeros and the lowest double, as does a finite state for its -id. The terms are the CPU's; their sums are in a tree
// (round-off apart from the CPU's serial sums), the extrema exact.

#define FIGURE_SUMS 8u
#define FIGURE_EXTREMA 8u
// The lowest finite double: no extremum (no infinity constant needs a header).
#define LOWEST_DOUBLE (-1.7976931348623157e308)

// Whether every component is finite (x - x is NaN for an infinity or a NaN).
static __device__ __forceinline__ bool finite3(Vec3 v) {
    return v.x - v.x == 0.0 && v.y - v.y == 0.0 && v.z - v.z == 0.0;
}

extern "C" __global__ void particle_figures(
    unsigned n, const unsigned char* role, const unsigned* body_type, const double* type_mass,
    const double* type_inertia, double gx, double gy, double gz, const double* position,
    const double* orientation, const double* velocity, const double* angular_momentum, const double* force,
    const double* torque, const unsigned long long* id, double* sums, double* extrema) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    double* s = sums + FIGURE_SUMS * i;
    double* e = extrema + FIGURE_EXTREMA * i;
    if (role[i] & GHOST_ROLE) {
        for (unsigned c = 0; c < FIGURE_SUMS; ++c) {
            s[c] = 0.0;
        }
        for (unsigned c = 0; c < FIGURE_EXTREMA; ++c) {
            e[c] = LOWEST_DOUBLE;
        }
        return;
    }
    unsigned kind = body_type[i];
    double m = type_mass[kind];
    Vec3 inertia = load3(type_inertia, kind);
    Vec3 x = load3(position, i), v = load3(velocity, i), l = load3(angular_momentum, i);
    s[0] = 1.0;
    s[1] = (role[i] & FROZEN_ROLE) ? 1.0 : 0.0;
    s[2] = m;
    s[3] = x.x * m;
    s[4] = x.y * m;
    s[5] = x.z * m;
    // World::particle_kinetic_energy: L in the body frame, over the principal moments.
    Vec3 lb = rotate(conjugate(load_orientation(orientation, i)), l);
    s[6] = 0.5 * m * norm_squared(v) + 0.5 * dot(lb, div3(lb, inertia));
    s[7] = -(m * dot(Vec3{gx, gy, gz}, x));
    e[0] = sqrt(norm_squared(v));
    e[1] = x.x;
    e[2] = x.y;
    e[3] = x.z;
    e[4] = -x.x;
    e[5] = -x.y;
    e[6] = -x.z;
    bool finite = finite3(x) && finite3(v) && finite3(l) && finite3(load3(force, i)) &&
                  finite3(load3(torque, i));
    e[7] = finite ? LOWEST_DOUBLE : -(double)id[i];
}
