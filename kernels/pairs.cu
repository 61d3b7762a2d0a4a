// The contacts of the candidate pairs of any world but spheres under Hertz–Mindlin
// alone (spheres.cu steps those): `pair_contacts`, one thread per pair, two
// polyhedra by their exact overlap (overlap.cuh) under the volume law
// (volume_law.cuh), two spheres by their lens and a sphere and a polyhedron at the
// sphere's cap (round_geometry.cuh) under the volume law or Hertz–Mindlin with its
// rolling resistance (contact.cuh) (engine/cpu/pairs.rs, engine/cpu/dispatch.rs,
// engine/cpu/forces.rs, engine/cpu/hertz.rs). Compiled after vec.cuh,
// contact.cuh, body.cuh, triangle.cuh, overlap.cuh, round_geometry.cuh and
// volume_law.cuh.

// What a pair's contact puts on the second particle (force, torque about its
// centroid), the first's reaction torque, the energies, and the history it keeps.
struct PairContact {
    Vec3 force, torque;
    Spring kept;
    double twist, energy, dissipated;
    Vec3 rolling;
};

// What the pair kernel reads of the particles.
struct PairStates {
    const double *position, *orientation, *velocity, *angular_momentum;
    const unsigned* body_type;
};

// What the pair kernel reads of the body types beside the shapes: mass, principal
// moments, whether equal, the volume law's rows (volume_law.cuh), material; per
// pair of materials the volume law's row; the spheres' Hertz–Mindlin table.
struct PairTypes {
    const double *mass, *inertia;
    const unsigned char* isotropic;
    const double* law;
    const unsigned* material;
    unsigned materials;
    const double* material_law;
    const unsigned* shape;
    HertzTable hertz;
};

// A particle's angular velocity (World::angular_velocity).
static __device__ __forceinline__ Vec3 spin_of(const PairStates& s, const PairTypes& t, unsigned i,
                                               unsigned ti, Quat q) {
    return angular_velocity(q, load3(s.angular_momentum, i), load3(t.inertia, ti),
                            t.isotropic[ti]);
}

// Particles i (a polyhedron) and j (a sphere), or the other way round where the
// sphere comes first: their contact's geometry, the polyhedron locally flat, its
// point at the sphere's cap (engine/cpu/dispatch.rs, pair_geometry). False where
// apart.
static __device__ bool cap_geometry(const ShapeTable& table, const PairStates& s,
                                    const PairTypes& t, unsigned i, unsigned j,
                                    VolumeGeometry* g) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    bool sphere_first = t.shape[ti] == NO_SHAPE;
    unsigned p = sphere_first ? j : i, q = sphere_first ? i : j;
    unsigned tp = sphere_first ? tj : ti, tq = sphere_first ? ti : tj;
    Vec3 xp = load3(s.position, p), xq = load3(s.position, q);
    Quat qp = load_orientation(s.orientation, p);
    CapContact cap;
    // The sphere's centre in the polyhedron's frame (Isometry3::inverse_transform_point).
    Vec3 c = rotate(conjugate(qp), sub(xq, xp));
    if (!sphere_polyhedron(table, t.shape[tp], c, t.hertz.radius[tq], &cap)) {
        return false;
    }
    g->volume = cap.volume;
    g->area = cap.area;
    g->depth = cap.depth;
    g->normal = rotate(qp, cap.normal);
    g->point = add(rotate(qp, cap.point), xp);
    g->has_gradient = false;
    if (sphere_first) {
        g->normal = scale(g->normal, -1.0);
    }
    return true;
}

// Spheres i and j: their lens (geometry/sphere.rs, sphere_sphere). False where
// apart.
static __device__ bool lens_geometry(const PairStates& s, const PairTypes& t, unsigned i,
                                     unsigned j, VolumeGeometry* g) {
    Vec3 xi = load3(s.position, i);
    CapContact lens;
    const double* radius = t.hertz.radius;
    if (!sphere_sphere(radius[s.body_type[i]], radius[s.body_type[j]],
                       sub(load3(s.position, j), xi), &lens)) {
        return false;
    }
    g->volume = lens.volume;
    g->area = lens.area;
    g->depth = lens.depth;
    g->normal = lens.normal;
    g->point = add(xi, lens.point);
    g->has_gradient = false;
    return true;
}

// Polyhedra i and j: their overlap (overlap.cuh; engine/cpu/dispatch.rs,
// pair_geometry). False where they do not overlap.
static __device__ bool overlap_geometry(const ShapeTable& table, const PairStates& s,
                                        const PairTypes& t, unsigned i, unsigned j,
                                        VolumeGeometry* g) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    Vec3 xi = load3(s.position, i), xj = load3(s.position, j);
    Quat qi = load_orientation(s.orientation, i), qj = load_orientation(s.orientation, j);
    // B's pose in A's frame, as nalgebra's pi.inverse() * pj.
    Quat inverse = conjugate(qi);
    Vec3 tr = add(rotate(inverse, scale(xi, -1.0)), rotate(inverse, xj));
    OverlapScratch scratch;
    double o[OVERLAP_DOUBLES];
    polyhedron_overlap(table, t.shape[ti], t.shape[tj], tr, qmul(inverse, qj), &scratch, o);
    if (!(o[0] > 0.0)) {
        return false;
    }
    g->volume = o[0];
    g->area = o[7];
    g->depth = o[8];
    g->normal = rotate(qi, load3(o + 4, 0));
    g->point = add(rotate(qi, load3(o + 1, 0)), xi);
    g->rotation_gradient = rotate(qi, load3(o + 12, 0));
    g->has_gradient = true;
    return true;
}

// RelativeMotion::of_pair of particles i and j at the contact `g`, with the pair's
// rotational inertia `inertia`.
static __device__ VolumeMotion pair_motion(const PairStates& s, const PairTypes& t, unsigned i,
                                           unsigned j, Vec3 point, Vec3 normal, double inertia) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    Vec3 xi = load3(s.position, i), xj = load3(s.position, j);
    Quat qi = load_orientation(s.orientation, i), qj = load_orientation(s.orientation, j);
    Vec3 wi = spin_of(s, t, i, ti, qi), wj = spin_of(s, t, j, tj, qj);
    VolumeMotion m;
    m.velocity = sub(add(load3(s.velocity, j), cross(wj, sub(point, xj))),
                     add(load3(s.velocity, i), cross(wi, sub(point, xi))));
    m.spin = sub(wj, wi);
    m.inverse_mass = inverse_mass_at(qi, xi, t.mass[ti], load3(t.inertia, ti), point, normal) +
                     inverse_mass_at(qj, xj, t.mass[tj], load3(t.inertia, tj), point, normal);
    m.inertia = inertia;
    return m;
}

// The volume law's contact `g` of particles i and j, holding `before` and `twist`
// (engine/cpu/forces.rs, pair_force); a rolling spring is kept as it was.
static __device__ PairContact volume_pair(const PairStates& s, const PairTypes& t, unsigned i,
                                          unsigned j, const VolumeGeometry& g, Spring before,
                                          double twist, Vec3 rolling, double dt) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    const double* law_i = t.law + TYPE_LAW_DOUBLES * ti;
    const double* law_j = t.law + TYPE_LAW_DOUBLES * tj;
    VolumeMotion m = pair_motion(s, t, i, j, g.point, g.normal, 1.0 / (law_i[4] + law_j[4]));
    // The smaller regularisation volume (that of the smaller body), the first's on a tie.
    const double* regular = law_j[2] < law_i[2] ? law_j : law_i;
    const double* material =
        t.material_law + MATERIAL_LAW_DOUBLES * (t.material[ti] * t.materials + t.material[tj]);
    VolumeContact c = volume_contact(g, m, law_i[0] + law_j[0], law_i[1] + law_j[1], regular[2],
                                     regular[3], material, before, twist, dt,
                                     load3(s.position, j));
    return PairContact{c.force, c.torque, c.kept, c.twist, c.energy, c.dissipated, rolling};
}

// The rolling inertia `I + m r²` of body type `ti` about a contact at `r` from its
// centroid, I its smallest principal moment (engine/cpu/hertz.rs, rolling_inertia).
static __device__ __forceinline__ double rolling_inertia(const PairTypes& t, unsigned ti,
                                                         double r) {
    Vec3 inertia = load3(t.inertia, ti);
    return fmin(fmin(inertia.x, inertia.y), inertia.z) + t.mass[ti] * r * r;
}

// A sphere and a polyhedron at their cap `g` under Hertz–Mindlin, the polyhedron
// locally flat, with the rolling resistance `roll` (its inertia found here)
// (engine/cpu/pairs.rs, pair_contact).
static __device__ PairContact hertz_cap(const PairStates& s, const PairTypes& t, unsigned i,
                                        unsigned j, const VolumeGeometry& g, Spring before,
                                        Rolling roll, double dt) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    VolumeMotion m = pair_motion(s, t, i, j, g.point, g.normal, 0.0);
    const HertzTable& h = t.hertz;
    double r = t.shape[ti] == NO_SHAPE ? h.radius[ti] : h.radius[tj];
    const double* row =
        h.material_pairs + MATERIAL_DOUBLES * (h.material[ti] * h.materials + h.material[tj]);
    Vec3 xj = load3(s.position, j);
    double lever_i = norm(sub(g.point, load3(s.position, i))), lever_j = norm(sub(g.point, xj));
    roll.inertia =
        1.0 / (1.0 / rolling_inertia(t, ti, lever_i) + 1.0 / rolling_inertia(t, tj, lever_j));
    RoundContact c = round_contact(g.depth, g.normal, sub(g.point, xj), m.velocity, m.spin,
                                   m.inverse_mass, r, row, before, roll, dt);
    return PairContact{c.force, c.torque, c.kept, 0.0, c.energy, c.dissipated, c.rolling};
}

// The contact of particles i and j, where they touch (engine/cpu/pairs.rs,
// pair_contact): two polyhedra under the volume law; a sphere under the volume law
// where `round_volume`, else under Hertz–Mindlin with the rolling resistance
// `roll` (against a sphere by contact.cuh's sphere_pair).
static __device__ bool pair_contact(const ShapeTable& table, const PairStates& s,
                                    const PairTypes& t, bool round_volume, unsigned i,
                                    unsigned j, Spring before, double twist, Rolling roll,
                                    double dt, PairContact* out) {
    unsigned ti = s.body_type[i], tj = s.body_type[j];
    bool sphere_i = t.shape[ti] == NO_SHAPE, sphere_j = t.shape[tj] == NO_SHAPE;
    VolumeGeometry g;
    if (sphere_i && sphere_j && !round_volume) {
        RoundContact c;
        if (!sphere_pair(t.hertz, ti, tj, load3(s.position, i), load3(s.position, j),
                         load3(s.velocity, i), load3(s.velocity, j),
                         load3(s.angular_momentum, i), load3(s.angular_momentum, j), before,
                         roll.model, roll.spring, dt, &c)) {
            return false;
        }
        *out = PairContact{c.force, c.torque, c.kept, twist, c.energy, c.dissipated, c.rolling};
        return true;
    }
    if (sphere_i && sphere_j) {
        if (!lens_geometry(s, t, i, j, &g)) {
            return false;
        }
    } else if (sphere_i || sphere_j) {
        if (!cap_geometry(table, s, t, i, j, &g)) {
            return false;
        }
        if (!round_volume) {
            *out = hertz_cap(s, t, i, j, g, before, roll, dt);
            out->twist = twist;
            return true;
        }
    } else if (!overlap_geometry(table, s, t, i, j, &g)) {
        return false;
    }
    *out = volume_pair(s, t, i, j, g, before, twist, roll.spring, dt);
    return true;
}

// One thread per candidate pair of a world with polyhedra or under the volume law:
// where one of the two moves here (is neither frozen nor a ghost), its contact
// (pair_contact) into the pair's result, its history replaced by what the contact
// leaves; apart, a zero result and history, and the friction spring's energy as
// dissipated (engine/cpu/pairs.rs). The result, energy terms and byte are
// spheres.cu's (the gather and the sums read both alike). Per body type: its
// shape (NO_SHAPE: a
// sphere), mass, principal moments, whether they are equal, its volume-law row and
// material; per pair of materials (row-major) its volume-law row; and the spheres'
// Hertz–Mindlin table (contact.cuh, HertzTable). Spheres follow the volume law
// where `round_volume` is 1, Hertz–Mindlin where 0, with the rolling resistance
// `rolling_model` (contact.cuh). A pair's history is `history_doubles` long: the
// spring (3), its stiffness, the twist, and where 8 the rolling spring (3).
extern "C" __global__ void pair_contacts(
    unsigned pair_count, double dt, const unsigned* pairs, const double* position,
    const double* orientation, const double* velocity, const double* angular_momentum,
    const unsigned* body_type, const unsigned char* role, const double* type_mass,
    const double* type_inertia, const unsigned char* type_isotropic, const double* type_law,
    const unsigned* type_material, unsigned materials, const double* material_law,
    const unsigned* type_shape, const unsigned* shape_index, const unsigned* face_span,
    const unsigned* loops, const Mask* face_masks, const double* vertices, const double* planes,
    const double* circumradius, const double* type_radius, const double* type_inverse_mass,
    const double* type_inverse_inertia, const double* type_rolling_inertia,
    const unsigned* hertz_material, unsigned hertz_materials, const double* material_pairs,
    unsigned round_volume, unsigned history_doubles, unsigned rolling_model, double* history,
    double* results, double* energies, unsigned char* touching) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    ShapeTable table =
        ShapeTable{shape_index, face_span, loops, face_masks, vertices, planes, circumradius};
    PairStates states =
        PairStates{position, orientation, velocity, angular_momentum, body_type};
    PairTypes types = PairTypes{
        type_mass,   type_inertia,  type_isotropic,
        type_law,    type_material, materials,
        material_law, type_shape,
        HertzTable{type_radius, type_inverse_mass, type_inverse_inertia, type_rolling_inertia,
                   hertz_material, hertz_materials, material_pairs}};
    unsigned i = pairs[2 * e], j = pairs[2 * e + 1];
    double* h = history + (size_t)history_doubles * e;
    bool rolls = history_doubles >= ROLLING_HISTORY_DOUBLES;
    double* result = results + RESULT_DOUBLES * e;
    double* energy = energies + PAIR_ENERGY_DOUBLES * e;
    bool counted = counts_pair(role[i], role[j]);
    Spring before = Spring{load3(h, 0), h[3]};
    Rolling roll = Rolling{rolling_model, 0.0, rolls ? load3(h + 5, 0) : Vec3{0.0, 0.0, 0.0}};
    PairContact c;
    bool touches = !(role[i] && role[j]) &&
                   pair_contact(table, states, types, round_volume != 0, i, j, before, h[4], roll,
                                dt, &c);
    if (!touches) {
        store_apart(result, energy, touching + e, counted, before);
        for (unsigned k = 0; k < history_doubles; ++k) {
            h[k] = 0.0;
        }
        return;
    }
    store_contact(result, energy, touching + e, counted, load3(position, i), load3(position, j),
                  c.force, c.torque, c.energy, c.dissipated);
    store3(h, 0, c.kept.spring);
    h[3] = c.kept.stiffness;
    h[4] = c.twist;
    if (rolls) {
        store3(h + 5, 0, c.rolling);
    }
}

