// The Hertz–Mindlin law of round contacts with Cundall–Strack friction
// (contact/hertz_mindlin.rs, contact/tangential.rs, engine/cpu/hertz.rs), the
// contact of two spheres under it, and a spherical cap's volume and area, shared
// by the pairs (spheres.cu, polyhedra.cu) and the sphere–wall contacts (walls.cu):
// the CPU backend's operations in its order. The particles' roles and the pairs a
// rank counts. Compiled after vec.cuh.

#define HISTORY_DOUBLES 4u
// A record of the energy sums (sums.cu): elastic energy, dissipated, wall contacts,
// pair contacts, candidate pairs counted.
#define ENERGY_RECORD 5u
// A particle's role byte: frozen, a ghost (a copy of a particle another rank
// owns), or both; nonzero where nobody here moves it (World's `is_passive`).
#define FROZEN_ROLE 1u
#define GHOST_ROLE 2u
// A candidate pair's byte (spheres.cu): it touches; this world counts it in its
// totals (Particles::counts_pair: every pair in one process).
#define PAIR_TOUCHES 1u
#define PAIR_COUNTED 2u
#define RESULT_DOUBLES 9u
// A pair's energy terms (spheres.cu): elastic energy, dissipated.
#define PAIR_ENERGY_DOUBLES 2u
// A pair of materials' Hertz–Mindlin row: E*, G*, β, √(4G*/E*), the friction
// coefficient, the rolling friction coefficient and the rolling damping ratio.
#define MATERIAL_DOUBLES 7u
// Rolling resistance models (contact/rolling.rs): none, constant torque (model A),
// elastic–plastic spring–dashpot (model C).
#define ROLLING_NONE 0u
#define ROLLING_CONSTANT 1u
#define ROLLING_ELASTIC_PLASTIC 2u

// Whether this world counts pair (i, j), i of the smaller id, in its totals
// (world/particles.rs, Particles::counts_pair): where i is owned, unless i is
// frozen and j a ghost; where i is a ghost, if i is frozen and j owned.
static __device__ __forceinline__ bool counts_pair(unsigned char ri, unsigned char rj) {
    bool frozen_i = (ri & FROZEN_ROLE) != 0;
    bool ghost_i = (ri & GHOST_ROLE) != 0, ghost_j = (rj & GHOST_ROLE) != 0;
    return ghost_i ? frozen_i && !ghost_j : !(frozen_i && ghost_j);
}

// The volume of a spherical cap of height h on a sphere of radius r, and the area
// of its base disc (geometry/sphere.rs, cap_volume and cap_area).
static __device__ __forceinline__ double cap_volume(double r, double h) {
    const double pi = 3.14159265358979323846;
    h = fmin(fmax(h, 0.0), 2.0 * r);
    return pi * h * h * (3.0 * r - h) / 3.0;
}

static __device__ __forceinline__ double cap_area(double r, double h) {
    const double pi = 3.14159265358979323846;
    h = fmin(fmax(h, 0.0), r);
    return pi * (2.0 * r * h - h * h);
}

// 2 √(5/6), the factor of the damping coefficients.
#define DAMPING_FACTOR 1.8257418583505537

struct Spring {
    Vec3 spring;
    double stiffness;
};

static __device__ __forceinline__ double spring_energy(Spring s) {
    return 0.5 * s.stiffness * norm_squared(s.spring);
}

// The factor that brings a spring of squared length `held`, cut by `along` the new
// normal, back to its length (contact/tangential.rs): the series of
// (1 - e)^(-1/2) to e^2 where the normal barely turned, the square root elsewhere.
static __device__ __forceinline__ double length_kept(double along_squared, double held,
                                                     Vec3 projected) {
    if (along_squared <= 1e-6 * held) {
        double turn = along_squared / held;
        return 1.0 + turn * (0.5 + 0.375 * turn);
    }
    double p = norm_squared(projected);
    return p > 0.0 ? sqrt(held / p) : 1.0;
}

// Cundall–Strack friction (contact/tangential.rs): the force on body 2, the spring
// kept in *kept, whether the contact slides (the cap is active) in *sliding.
static __device__ __forceinline__ Vec3 tangential_force(Spring history, Vec3 normal,
                                                        Vec3 relative_velocity, double dt,
                                                        double stiffness, double damping,
                                                        double limit, Spring* kept,
                                                        bool* sliding) {
    Vec3 previous = history.spring;
    double along = dot(normal, previous);
    Vec3 spring = sub(previous, scale(normal, along));
    double held = norm_squared(previous);
    if (held > 0.0) {
        double keep = history.stiffness > 0.0 && stiffness > history.stiffness
                          ? history.stiffness / stiffness
                          : 1.0;
        spring = scale(spring, keep * length_kept(along * along, held, spring));
    }
    Vec3 vt = sub(relative_velocity, scale(normal, dot(normal, relative_velocity)));
    spring = add(spring, scale(vt, dt));
    Vec3 trial = sub(scale(spring, -stiffness), scale(vt, damping));
    double squared = norm_squared(trial);
    *sliding = !(squared <= limit * limit || squared == 0.0);
    if (!*sliding) {
        *kept = Spring{spring, stiffness};
        return trial;
    }
    double magnitude = sqrt(squared);
    Vec3 force = scale(trial, limit / magnitude);
    double length = norm(spring);
    if (stiffness > 0.0 && stiffness * length > limit) {
        spring = scale(spring, limit / (stiffness * length));
    }
    *kept = Spring{spring, stiffness};
    return force;
}

// The share of a contact's non-conservative force dotted with its whole force that
// `dissipated` takes at the step's end velocity (engine/cpu/forces.rs `ahead`): the
// normal damping's, (N - E) N, and where the contact slides friction's |F_t|^2.
static __device__ __forceinline__ double dissipation_ahead(double normal, double elastic,
                                                           Vec3 friction, bool sliding) {
    double damping = (normal - elastic) * normal;
    return sliding ? damping + norm_squared(friction) : damping;
}

// Energy a contact dissipated over a step (engine/cpu/forces.rs `dissipated`): the
// work of its non-conservative force on body 2 at the half-step relative velocity
// plus, for the share `ahead`, half a kick of its own force ahead; of the pure
// torque `resisting` at the relative spin; less what its friction spring stored.
static __device__ __forceinline__ double contact_dissipation(Vec3 non_conservative,
                                                             double ahead, Vec3 resisting,
                                                             Vec3 relative, Vec3 spin,
                                                             double inverse_mass,
                                                             Spring before, Spring after,
                                                             double dt) {
    double kick = 0.5 * dt * inverse_mass;
    return -dt * (dot(non_conservative, relative) + kick * ahead + dot(resisting, spin)) -
           (spring_energy(after) - spring_energy(before));
}

// What a round contact puts on body 2: force, torque about its centroid, the
// friction spring to keep, the elastic energy held and the energy dissipated.
struct RoundContact {
    Vec3 force, torque;
    Spring kept;
    double energy, dissipated;
    // The rolling spring's torque to keep.
    Vec3 rolling;
};

// A round contact's rolling resistance: the model, the rolling inertia about the
// contact point, and the spring's torque of the last step.
struct Rolling {
    unsigned model;
    double inertia;
    Vec3 spring;
};

// The rolling torque on body 2 of a contact of unit normal `n` and relative spin
// `spin` under `r` (contact/rolling.rs, rolling_torque), with the pair's rolling
// friction and damping, the normal force and stiffness and the effective radius;
// the spring's torque to keep into *kept.
static __device__ Vec3 rolling_torque(const Rolling& r, double friction, double damping, Vec3 n,
                                      Vec3 spin, double normal_force, double normal_stiffness,
                                      double radius, double dt, Vec3* kept) {
    Vec3 zero = Vec3{0.0, 0.0, 0.0};
    Vec3 roll = sub(spin, scale(n, dot(n, spin)));
    double limit = friction * radius * normal_force;
    if (r.model == ROLLING_CONSTANT) {
        *kept = zero;
        double speed = norm(roll);
        return speed > 0.0 ? scale(roll, -limit / speed) : zero;
    }
    double arm = friction * radius;
    double kr = 2.25 * normal_stiffness * (arm * arm);
    // The kept torque, turned into the current tangent plane at its length.
    Vec3 held = sub(r.spring, scale(n, dot(n, r.spring)));
    double projected = norm(held);
    if (projected > 0.0) {
        held = scale(held, norm(r.spring) / projected);
    }
    Vec3 elastic = sub(held, scale(roll, kr * dt));
    double magnitude = norm(elastic);
    if (magnitude > limit) {
        Vec3 capped = scale(elastic, limit / magnitude);
        *kept = capped;
        return capped;
    }
    Vec3 dashpot = scale(roll, -2.0 * damping * sqrt(r.inertia * kr));
    Vec3 total = add(elastic, dashpot);
    double size = norm(total);
    *kept = elastic;
    return size > limit ? scale(total, limit / size) : total;
}

// A Hertz–Mindlin contact of `depth` along `normal` (from body 1 to body 2), at
// `lever` from body 2's centroid, with the relative velocity at the contact point,
// the relative spin, the inverse effective mass, the effective radius, the
// material pair's row `m` and the rolling resistance `roll` (engine/cpu/hertz.rs
// `round_contact_force`).
static __device__ RoundContact round_contact(double depth, Vec3 normal, Vec3 lever,
                                             Vec3 relative, Vec3 spin, double inverse_mass,
                                             double radius, const double* m, Spring before,
                                             Rolling roll, double dt) {
    double young = m[0], shear = m[1], beta = m[2], damping_ratio = m[3], friction = m[4];
    // Hertz–Mindlin (contact/hertz_mindlin.rs).
    double mass = 1.0 / inverse_mass;
    double a = sqrt(radius * depth);
    double tangent = 2.0 * young * a;
    double stiffness = (2.0 / 3.0) * tangent;
    double elastic = stiffness * depth;
    double damping_n = -DAMPING_FACTOR * beta * sqrt(tangent * mass);
    double vn = dot(relative, normal);
    double normal_force = fmax(elastic - damping_n * vn, 0.0);
    double kt = 8.0 * shear * a;
    double damping_t = damping_n * damping_ratio;
    RoundContact c;
    bool sliding;
    Vec3 t = tangential_force(before, normal, relative, dt, kt, damping_t,
                              friction * normal_force, &c.kept, &sliding);
    c.force = add(scale(normal, normal_force), t);
    c.torque = cross(lever, c.force);
    Vec3 resisting = Vec3{0.0, 0.0, 0.0};
    c.rolling = roll.spring;
    if (roll.model != ROLLING_NONE) {
        resisting = rolling_torque(roll, m[5], m[6], normal, spin, normal_force, stiffness,
                                   radius, dt, &c.rolling);
        c.torque = add(c.torque, resisting);
    }
    c.energy = 0.4 * elastic * depth + spring_energy(c.kept);
    c.dissipated = contact_dissipation(sub(c.force, scale(normal, elastic)),
                                       dissipation_ahead(normal_force, elastic, t, sliding),
                                       resisting, relative, spin, inverse_mass, before, c.kept,
                                       dt);
    return c;
}


// A candidate pair's outputs (spheres.cu, pairs.cu) where it is apart: a zero
// result, and as its energy terms the friction spring `before` let go (where this
// world counts the pair).
static __device__ __forceinline__ void store_apart(double* result, double* energy,
                                                   unsigned char* touching, bool counted,
                                                   Spring before) {
    for (unsigned k = 0; k < RESULT_DOUBLES; ++k) {
        result[k] = 0.0;
    }
    energy[0] = 0.0;
    energy[1] = counted ? spring_energy(before) : 0.0;
    *touching = counted ? PAIR_COUNTED : 0u;
}

// A candidate pair's outputs where its particles, at xi and xj, touch: the force on
// the second, the first's reaction torque and the second's torque, the energy
// terms (where counted) and its byte.
static __device__ __forceinline__ void store_contact(double* result, double* energy,
                                                     unsigned char* touching, bool counted,
                                                     Vec3 xi, Vec3 xj, Vec3 force, Vec3 torque,
                                                     double elastic, double dissipated) {
    Vec3 reaction = scale(add(torque, cross(sub(xj, xi), force)), -1.0);
    store3(result, 0, force);
    store3(result, 1, reaction);
    store3(result, 2, torque);
    energy[0] = counted ? elastic : 0.0;
    energy[1] = counted ? dissipated : 0.0;
    *touching = PAIR_TOUCHES | (counted ? PAIR_COUNTED : 0u);
}

// What the Hertz–Mindlin contacts of spheres read: per body type its radius, 1/m,
// 1/I, rolling inertia about a contact on its surface (I + m r²) and material; per
// pair of materials (row-major) its row (MATERIAL_DOUBLES).
struct HertzTable {
    const double* radius;
    const double* inverse_mass;
    const double* inverse_inertia;
    const double* rolling_inertia;
    const unsigned* material;
    unsigned materials;
    const double* material_pairs;
};

// The contact of spheres of types ti and tj at xi and xj, moving at vi and vj with
// angular momenta li and lj, holding `before` and the rolling spring `rolling`
// under rolling model `model` (engine/cpu/hertz.rs, sphere_pair): false where they
// do not overlap (or their centres coincide).
static __device__ bool sphere_pair(const HertzTable& t, unsigned ti, unsigned tj, Vec3 xi,
                                   Vec3 xj, Vec3 vi, Vec3 vj, Vec3 li, Vec3 lj, Spring before,
                                   unsigned model, Vec3 rolling, double dt, RoundContact* c) {
    double ra = t.radius[ti], rb = t.radius[tj];
    Vec3 d = sub(xj, xi);
    double distance_squared = norm_squared(d);
    double reach = ra + rb;
    if (!(distance_squared < reach * reach) || distance_squared == 0.0) {
        return false;
    }
    double distance = sqrt(distance_squared);
    Vec3 normal = scale(d, 1.0 / distance);
    double depth = reach - distance;
    Vec3 lever_i = scale(normal, ra - 0.5 * depth);
    Vec3 lever_j = scale(normal, -(rb - 0.5 * depth));
    Vec3 wi = scale(li, t.inverse_inertia[ti]);
    Vec3 wj = scale(lj, t.inverse_inertia[tj]);
    Vec3 relative = sub(sub(add(vj, cross(wj, lever_j)), vi), cross(wi, lever_i));
    Vec3 spin = sub(wj, wi);
    double inverse_mass = t.inverse_mass[ti] + t.inverse_mass[tj];
    const double* m =
        t.material_pairs + MATERIAL_DOUBLES * (t.material[ti] * t.materials + t.material[tj]);
    double inertia = model == ROLLING_NONE
                         ? 0.0
                         : 1.0 / (1.0 / t.rolling_inertia[ti] + 1.0 / t.rolling_inertia[tj]);
    *c = round_contact(depth, normal, lever_j, relative, spin, inverse_mass, ra * rb / (ra + rb),
                       m, before, Rolling{model, inertia, rolling}, dt);
    return true;
}
