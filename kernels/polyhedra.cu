// The contacts of convex polyhedra: `polyhedron_overlaps`, one thread per pair of
// shapes, the exact overlap at its relative pose (overlap.cuh) as a record of
// OVERLAP_DOUBLES (volume 0: apart); `polyhedron_contacts`, one thread per
// candidate pair of particles of a world with polyhedra or under the volume law,
// the overlap and the volume law's force (volume_law.cuh), or a sphere's
// contact under Hertz–Mindlin or the volume law (contact.cuh, round_geometry.cuh);
// `polyhedron_facets`, one thread per particle shape and wall triangle, the
// overlap with the prism under the triangle (facet.cuh);
// `polyhedron_wall_patches`, one thread per particle, its patches against the walls
// (wall_patches.cuh); `polyhedron_wall_contacts`, one thread per particle, the
// volume law's contact of each patch; `polyhedron_wall_sum_rows`, what they push on
// the walls and their facets. Compiled after vec.cuh, contact.cuh, body.cuh,
// triangle.cuh, overlap.cuh, round_geometry.cuh, volume_law.cuh, facet.cuh and
// wall_patches.cuh.

// A pose of B in A's frame: B's centroid (three doubles), then its orientation
// (w, x, y, z).
#define POSE_DOUBLES 7u

extern "C" __global__ void polyhedron_overlaps(
    unsigned n, const unsigned* shape_index, const unsigned* face_span, const unsigned* loops,
    const Mask* face_masks, const double* vertices, const double* planes,
    const double* circumradius, const unsigned* pair_shapes, const double* poses,
    double* records) {
    unsigned k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= n) {
        return;
    }
    ShapeTable table =
        ShapeTable{shape_index, face_span, loops, face_masks, vertices, planes, circumradius};
    const double* pose = poses + POSE_DOUBLES * k;
    Vec3 t = Vec3{pose[0], pose[1], pose[2]};
    Quat q = Quat{pose[3], pose[4], pose[5], pose[6]};
    OverlapScratch scratch;
    polyhedron_overlap(table, pair_shapes[2 * k], pair_shapes[2 * k + 1], t, q, &scratch,
                       records + OVERLAP_DOUBLES * k);
}

// A body type without a shape in the table: a sphere.
#define NO_SHAPE 0xffffffffu
// Doubles of a history with a rolling spring: the spring, its stiffness, the
// twist, the rolling spring.
#define ROLLING_HISTORY_DOUBLES 8u

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
extern "C" __global__ void polyhedron_contacts(
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
    unsigned char counted_flag = counted ? PAIR_COUNTED : 0u;
    Spring before = Spring{load3(h, 0), h[3]};
    Rolling roll = Rolling{rolling_model, 0.0, rolls ? load3(h + 5, 0) : Vec3{0.0, 0.0, 0.0}};
    PairContact c;
    bool touches = !(role[i] && role[j]) &&
                   pair_contact(table, states, types, round_volume != 0, i, j, before, h[4], roll,
                                dt, &c);
    if (!touches) {
        for (unsigned k = 0; k < RESULT_DOUBLES; ++k) {
            result[k] = 0.0;
        }
        // The friction spring's energy is let go with the contact.
        energy[0] = 0.0;
        energy[1] = counted ? spring_energy(before) : 0.0;
        touching[e] = counted_flag;
        for (unsigned k = 0; k < history_doubles; ++k) {
            h[k] = 0.0;
        }
        return;
    }
    Vec3 xi = load3(position, i), xj = load3(position, j);
    Vec3 reaction = scale(add(c.torque, cross(sub(xj, xi), c.force)), -1.0);
    store3(result, 0, c.force);
    store3(result, 1, reaction);
    store3(result, 2, c.torque);
    energy[0] = counted ? c.energy : 0.0;
    energy[1] = counted ? c.dissipated : 0.0;
    touching[e] = PAIR_TOUCHES | counted_flag;
    store3(h, 0, c.kept.spring);
    h[3] = c.kept.stiffness;
    h[4] = c.twist;
    if (rolls) {
        store3(h + 5, 0, c.rolling);
    }
}

// One thread per query: shape `shapes[k]` against the triangle `triangles[9k..]`
// (its body frame, counter-clockwise seen from the particle), the overlap with the
// prism under it as a record of FACET_DOUBLES (volume 0: none).
extern "C" __global__ void polyhedron_facets(
    unsigned n, const unsigned* shape_index, const unsigned* face_span, const unsigned* loops,
    const Mask* face_masks, const double* vertices, const double* planes,
    const double* circumradius, const unsigned* shapes, const double* triangles,
    double* records) {
    unsigned k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= n) {
        return;
    }
    ShapeTable table =
        ShapeTable{shape_index, face_span, loops, face_masks, vertices, planes, circumradius};
    Side side;
    Polygon poly;
    place_body(table, shapes[k], &side);
    Vec3 tri[3] = {load3(triangles, 3 * k), load3(triangles, 3 * k + 1),
                   load3(triangles, 3 * k + 2)};
    facet_overlap(table, &side, circumradius[shapes[k]], tri, &poly,
                  records + FACET_DOUBLES * k);
}

// One thread per particle: its patches against every wall, in wall order, each
// with its facets' shares (wall_patches.cuh; the facets as index within their
// wall); none for a sphere, nor for a particle nobody here moves (frozen or a
// ghost). `overflow` is
// set where a particle has more patches than WALL_SLOTS or a patch more facets
// than SHARE_SLOTS. Per wall, its first facet (walls + 1 entries); per facet, its
// triangle in world coordinates and its unit normal.
extern "C" __global__ void polyhedron_wall_patches(
    unsigned n, const double* position, const double* orientation, const unsigned* body_type,
    const unsigned char* role, const unsigned* type_shape, const unsigned* shape_index, const unsigned* face_span,
    const unsigned* loops, const Mask* face_masks, const double* vertices, const double* planes,
    const double* circumradius, unsigned walls, const unsigned* wall_facets,
    const double* facets, const double* facet_normals, unsigned* patch_count,
    unsigned* patch_wall, long long* patch_keys, double* patch_geometry,
    unsigned* patch_shares, unsigned* share_facet, double* share_volume, unsigned* overflow) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    patch_count[i] = 0;
    unsigned shape = type_shape[body_type[i]];
    if (role[i] || shape == NO_SHAPE) {
        return;
    }
    ShapeTable table =
        ShapeTable{shape_index, face_span, loops, face_masks, vertices, planes, circumradius};
    Side side;
    Polygon poly;
    place_body(table, shape, &side);
    Vec3 x = load3(position, i);
    Quat q = load_orientation(orientation, i);
    unsigned made = 0;
    for (unsigned w = 0; w < walls; ++w) {
        Patch patches[WALL_SLOTS];
        unsigned count = 0;
        bool fits = wall_patches(table, &side, circumradius[shape], x, q, wall_facets[w],
                                 wall_facets[w + 1], facets, facet_normals, &poly, patches,
                                 &count);
        if (!fits || made + count > WALL_SLOTS) {
            atomicOr(overflow, 1u);
        }
        for (unsigned p = 0; p < count && made < WALL_SLOTS; ++p, ++made) {
            unsigned slot = WALL_SLOTS * i + made;
            const Patch* patch = &patches[p];
            patch_wall[slot] = w;
            for (unsigned c = 0; c < 4; ++c) {
                patch_keys[4 * slot + c] = patch->key[c];
            }
            double* g = patch_geometry + PATCH_DOUBLES * slot;
            g[0] = patch->volume;
            store3(g + 1, 0, patch->point);
            store3(g + 4, 0, patch->normal);
            g[7] = patch->area;
            g[8] = patch->depth;
            store3(g + 9, 0, patch->rotation_gradient);
            patch_shares[slot] = patch->shares;
            for (unsigned k = 0; k < patch->shares; ++k) {
                share_facet[SHARE_SLOTS * slot + k] = patch->facet[k] - wall_facets[w];
                share_volume[SHARE_SLOTS * slot + k] = patch->share[k];
            }
        }
    }
    patch_count[i] = made;
}

// One thread per particle: the volume law's contact of each of its wall patches
// (polyhedron_wall_patches) with an area and a finite normal, its friction spring
// found among the particle's springs of the step before by wall and plane key,
// added to the particle's force and torque in wall and patch order after the
// pairs' gather (engine/cpu/walls.rs, particle_contacts and patch_force): keys,
// springs, records (triangle.cuh) and each contact's patch slot into the
// particle's slots, their count into `count`. Per wall its material and motion
// (velocity, angular velocity, reference point). A slot's history is
// `history_doubles` long (polyhedron_contacts' layout; a rolling spring kept as it
// was).
extern "C" __global__ void polyhedron_wall_contacts(
    unsigned n, double dt, const double* position, const double* orientation,
    const double* velocity, const double* angular_momentum, const unsigned* body_type,
    const double* type_mass, const double* type_inertia, const unsigned char* type_isotropic,
    const double* type_law, const unsigned* type_material, unsigned materials,
    const double* material_law, const unsigned* wall_material, const double* wall_motion,
    const unsigned* patch_count, const unsigned* patch_wall, const long long* patch_keys,
    const double* patch_geometry, const unsigned* patch_shares, const double* share_volume,
    unsigned history_doubles, const unsigned* old_count, const long long* old_keys,
    const double* old_history,
    unsigned* count, long long* keys, double* history, double* records, unsigned* record_patch,
    double* force, double* torque, unsigned char* touching) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    unsigned t = body_type[i];
    Vec3 x = load3(position, i), inertia = load3(type_inertia, t);
    Quat q = load_orientation(orientation, i);
    Vec3 spin = angular_velocity(q, load3(angular_momentum, i), inertia, type_isotropic[t]);
    const double* law = type_law + TYPE_LAW_DOUBLES * t;
    Vec3 f = load3(force, i), tq = load3(torque, i);
    unsigned made = 0;
    for (unsigned s = 0; s < patch_count[i]; ++s) {
        unsigned slot = WALL_SLOTS * i + s;
        const double* p = patch_geometry + PATCH_DOUBLES * slot;
        VolumeGeometry g;
        g.volume = p[0];
        g.point = load3(p + 1, 0);
        g.normal = load3(p + 4, 0);
        g.area = p[7];
        g.depth = p[8];
        g.rotation_gradient = load3(p + 9, 0);
        g.has_gradient = true;
        bool finite = isfinite(g.normal.x) && isfinite(g.normal.y) && isfinite(g.normal.z);
        if (!(g.area > 0.0) || !finite) {
            continue;
        }
        unsigned w = patch_wall[slot];
        const double* wm = wall_motion + 9 * w;
        const double* m =
            material_law + MATERIAL_LAW_DOUBLES * (type_material[t] * materials + wall_material[w]);
        // ContactLaws::wall: the moduli in series over the particle's radius.
        double normal_stiffness = m[2 + DAMPING_NODES] / law[5];
        double tangential_stiffness = m[3 + DAMPING_NODES] / law[5];
        // RelativeMotion::of_wall.
        VolumeMotion motion;
        Vec3 at = add(load3(velocity, i), cross(spin, sub(g.point, x)));
        Vec3 wall_at = add(load3(wm, 0), cross(load3(wm, 1), sub(g.point, load3(wm, 2))));
        motion.velocity = sub(at, wall_at);
        motion.spin = sub(spin, load3(wm, 1));
        motion.inverse_mass = inverse_mass_at(q, x, type_mass[t], inertia, g.point, g.normal);
        motion.inertia = law[6];
        // The patch's spring of the last step, found by its key.
        unsigned out = WALL_SLOTS * i + made;
        long long* key = keys + KEY_WORDS * out;
        key[0] = w;
        for (unsigned c = 0; c < 4; ++c) {
            key[1 + c] = patch_keys[4 * slot + c];
        }
        Spring before = Spring{Vec3{0.0, 0.0, 0.0}, 0.0};
        double twist = 0.0;
        Vec3 rolling = Vec3{0.0, 0.0, 0.0};
        unsigned held = held_slot(old_keys + KEY_WORDS * WALL_SLOTS * i, old_count[i], key);
        if (held < old_count[i]) {
            const double* h = old_history + (size_t)history_doubles * (WALL_SLOTS * i + held);
            before = Spring{load3(h, 0), h[3]};
            twist = h[4];
            if (history_doubles >= ROLLING_HISTORY_DOUBLES) {
                rolling = load3(h + 5, 0);
            }
        }
        VolumeContact c = volume_contact(g, motion, normal_stiffness, tangential_stiffness,
                                         law[2], law[3], m, before, twist, dt, x);
        double* h = history + (size_t)history_doubles * out;
        store3(h, 0, c.kept.spring);
        h[3] = c.kept.stiffness;
        h[4] = c.twist;
        if (history_doubles >= ROLLING_HISTORY_DOUBLES) {
            store3(h + 5, 0, rolling);
        }
        // The facets' total share (a serial sum, as the CPU's).
        double total = 0.0;
        for (unsigned k = 0; k < patch_shares[slot]; ++k) {
            total += share_volume[SHARE_SLOTS * slot + k];
        }
        double* r = records + WALL_RECORD_DOUBLES * out;
        store3(r, 0, c.force);
        store3(r, 1, c.torque);
        r[6] = total;
        r[7] = c.energy;
        r[8] = c.dissipated;
        record_patch[out] = slot;
        f = add(f, c.force);
        tq = add(tq, c.torque);
        touching[i] = 1;
        ++made;
    }
    count[i] = made;
    store3(force, i, f);
    store3(torque, i, tq);
}

// The walls' sums of a world of polyhedra, spheres among them or not, first pass
// (walls.cu's wall_sum_rows, which sums.cu folds on): thread t of `groups` adds the
// wall contacts of particles t, t + groups, … in that order into row t of `rows`:
// per wall its force and torque about its reference point (6 doubles), then per
// facet its force (3 doubles), each of a polyhedron's patch's facets its share of
// the patch's force, a sphere's facet (record_index: sphere_walls' facet) all of it.
extern "C" __global__ void polyhedron_wall_sum_rows(
    unsigned n, const double* position, const unsigned* body_type, const unsigned* type_shape,
    unsigned walls, const unsigned* wall_facets,
    const double* wall_motion, const unsigned* count, const long long* keys,
    const double* records, const unsigned* record_index, const unsigned* patch_shares,
    const unsigned* share_facet, const double* share_volume, unsigned groups, double* rows) {
    unsigned t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= groups) {
        return;
    }
    double* row = zeroed_wall_row(rows, t, walls, wall_facets);
    for (unsigned i = t; i < n; i += groups) {
        Vec3 x = load3(position, i);
        for (unsigned s = 0; s < count[i]; ++s) {
            unsigned slot = WALL_SLOTS * i + s;
            unsigned w = (unsigned)keys[KEY_WORDS * slot];
            const double* record = records + WALL_RECORD_DOUBLES * slot;
            Vec3 f = load3(record, 0);
            add_wall_reaction(row, w, x, load3(wall_motion + 9 * w, 2), f, load3(record, 1));
            double total = record[6];
            if (!(total > 0.0)) {
                continue;
            }
            if (type_shape[body_type[i]] == NO_SHAPE) {
                unsigned facet = 2 * walls + record_index[slot];
                store3(row, facet, sub(load3(row, facet), scale(f, total / total)));
                continue;
            }
            unsigned patch = record_index[slot];
            for (unsigned k = 0; k < patch_shares[patch]; ++k) {
                unsigned facet = 2 * walls + wall_facets[w] + share_facet[SHARE_SLOTS * patch + k];
                double share = share_volume[SHARE_SLOTS * patch + k];
                store3(row, facet, sub(load3(row, facet), scale(f, share / total)));
            }
        }
    }
}
