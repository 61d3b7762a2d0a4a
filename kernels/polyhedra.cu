// The contacts of convex polyhedra: `polyhedron_overlaps`, one thread per pair of
// shapes, the exact overlap at its relative pose (overlap.cuh) as a record of
// OVERLAP_DOUBLES (volume 0: apart) (the particles' pairs are pairs.cu's);
// `polyhedron_facets`, one thread per particle shape and wall triangle, the
// overlap with the prism under the triangle (facet.cuh);
// `polyhedron_wall_patches`, one thread per particle, its patches against the walls
// (wall_patches.cuh); `polyhedron_wall_contacts`, one thread per particle, the
// volume law's contact of each patch; `polyhedron_wall_sum_rows`, what they push on
// the walls and their facets. Compiled after vec.cuh, contact.cuh, body.cuh,
// triangle.cuh, overlap.cuh, volume_law.cuh, facet.cuh, facet_grid.cuh and
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
// ghost). `overflow` is set where a particle has more patches than WALL_SLOTS or
// a patch more facets than SHARE_SLOTS. Per wall, its first facet (walls + 1
// entries); per facet, its triangle in world coordinates and its unit normal;
// the walls' facet grids (facet_grid.cuh).
extern "C" __global__ void polyhedron_wall_patches(
    unsigned n, const double* position, const double* orientation, const unsigned* body_type,
    const unsigned char* role, const unsigned* type_shape, const unsigned* shape_index, const unsigned* face_span,
    const unsigned* loops, const Mask* face_masks, const double* vertices, const double* planes,
    const double* circumradius, unsigned walls, const unsigned* wall_facets,
    const double* facets, const double* facet_normals, const double* grid_frame,
    const unsigned* grid_head, const unsigned* grid_starts, const unsigned* grid_entries,
    unsigned* patch_count,
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
    FacetGrids grids = FacetGrids{grid_frame, grid_head, grid_starts, grid_entries};
    unsigned made = 0;
    for (unsigned w = 0; w < walls; ++w) {
        Patch patches[WALL_SLOTS];
        unsigned count = 0;
        bool fits = wall_patches(table, &side, circumradius[shape], x, q, grids, w,
                                 wall_facets[w], facets, facet_normals, &poly, patches, &count);
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
// `history_doubles` long (pairs.cu's layout; a rolling spring kept as it
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
