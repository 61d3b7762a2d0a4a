// Wall facets as the contacts of spheres (walls.cu) and of polyhedra
// (facet.cuh, wall_patches.cuh) read them: the point of a triangle closest to a
// point (geometry/sphere.rs, closest_point_on_triangle: Ericson's Voronoi-region
// tests), the key of a facet's plane that patches are merged by, the slots of a
// particle's wall contacts (a key, a spring and a record each) and what a
// contact pushes on its wall. Compiled after vec.cuh.

// Wall contacts (patches) a particle may have at once.
#define WALL_SLOTS 4u
// Words of a wall contact's key: the wall, its plane's four numbers.
#define KEY_WORDS 5u
// Doubles of a wall contact's record for the sums: the force on the particle, the
// torque about its centroid, the facets' total share, the elastic energy held and
// the energy dissipated.
#define WALL_RECORD_DOUBLES 9u

static __device__ __forceinline__ Vec3 closest_on_triangle(Vec3 a, Vec3 b, Vec3 c, Vec3 p) {
    Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return a;
    }
    Vec3 bp = sub(p, b);
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return b;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        return add(a, scale(ab, d1 / (d1 - d3)));
    }
    Vec3 cp = sub(p, c);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return c;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        return add(a, scale(ac, d2 / (d2 - d6)));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    double denom = 1.0 / (va + vb + vc);
    return add(add(a, scale(ab, vb * denom)), scale(ac, vc * denom));
}

// The key of a facet's plane for a particle of bounding radius `radius`
// (engine/cpu/patch.rs, FacetPlane::key).
static __device__ __forceinline__ void plane_key(Vec3 n, Vec3 point, double radius,
                                                 long long* key) {
    key[0] = (long long)round(n.x * 1e9);
    key[1] = (long long)round(n.y * 1e9);
    key[2] = (long long)round(n.z * 1e9);
    key[3] = (long long)round(dot(n, point) / radius * 1e9);
}

// The slot among `count` keys (KEY_WORDS each, from `keys`) that equals `key`: the
// last such, or `count` where none does.
static __device__ __forceinline__ unsigned held_slot(const long long* keys, unsigned count,
                                                     const long long* key) {
    unsigned held = count;
    for (unsigned s = 0; s < count; ++s) {
        const long long* k = keys + KEY_WORDS * s;
        if (k[0] == key[0] && k[1] == key[1] && k[2] == key[2] && k[3] == key[3] &&
            k[4] == key[4]) {
            held = s;
        }
    }
    return held;
}

// Adds to a row of the walls' sums (per wall its force and torque about its
// reference point, 2 vectors, from vector 0) what a contact of force `f` and
// torque `torque` on a particle at `x` pushes on wall `w` (engine/cpu/walls.rs:
// the opposite force, ContactForce::reaction_torque).
static __device__ __forceinline__ void add_wall_reaction(double* row, unsigned w, Vec3 x,
                                                         Vec3 reference, Vec3 f, Vec3 torque) {
    store3(row, 2 * w, sub(load3(row, 2 * w), f));
    Vec3 reaction = scale(add(torque, cross(sub(x, reference), f)), -1.0);
    store3(row, 2 * w + 1, add(load3(row, 2 * w + 1), reaction));
}

// Row t of the walls' sums (per wall its force and torque, then per facet its
// force: 6 doubles a wall, 3 a facet), zeroed.
static __device__ __forceinline__ double* zeroed_wall_row(double* rows, unsigned t, unsigned walls,
                                                          const unsigned* wall_facets) {
    unsigned width = 6 * walls + 3 * wall_facets[walls];
    double* row = rows + (size_t)width * t;
    for (unsigned k = 0; k < width; ++k) {
        row[k] = 0.0;
    }
    return row;
}
