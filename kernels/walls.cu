// The contacts of spheres with wall facets, under Hertz–Mindlin or the volume law
// (engine/cpu/walls.rs, engine/cpu/patch.rs, geometry/sphere.rs): one thread per
// particle, the facets near it of every wall (facet_grid.cuh), the facets of one
// plane merged into one contact at the deepest, the contacts added to the
// particle's force and torque in wall and patch order after the pairs' gather:
// the CPU backend's operations in its order, so the same bits. Then the walls'
// forces, torques and facet forces, and the contacts' energies, as rows and
// records that sums.cu folds in a fixed order (the CPU's sums to round-off).
//
// Layouts: facets of all walls one after the other, wall w's from
// wall_facets[w] to wall_facets[w + 1]: placed corners (9 doubles) and unit
// normals (3), and the walls' facet grids (facet_grid.cuh). Per wall: its
// material, and velocity, angular velocity and reference point (9 doubles). Per particle WALL_SLOTS contacts: the key (wall,
// and the plane's four rounded numbers: 5 long longs), the friction spring (4
// doubles), and for the sums the force, the torque, the facet's share, the
// elastic energy and the energy dissipated (9 doubles) and the facet; the count of
// contacts.

// A sphere's contact with one facet, as geometry/sphere.rs `sphere_triangle`
// and engine/cpu/dispatch.rs give it.
struct FacetContact {
    double depth, volume, area;
    Vec3 normal, point;
};

// A sphere's contact with one facet (unit normal n, the centre `height` above its
// plane), and whether it is the face's. Where the centre projects into the facet,
// the plane's contact, without the closest-point search (geometry/sphere.rs
// `sphere_on_face`; the edges' inward normals n × (b − a) are the ones
// engine/cpu/walls.rs places once per facet); elsewhere the closest point's, as
// geometry/sphere.rs `sphere_triangle` and engine/cpu/dispatch.rs give it.
static __device__ __forceinline__ bool sphere_facet(const double* t, Vec3 n, Vec3 centre,
                                                    double r, double height,
                                                    FacetContact* out, bool* face) {
    Vec3 a = load3(t, 0), b = load3(t, 1), c = load3(t, 2);
    *face = (dot(cross(n, sub(b, a)), sub(centre, a)) >= 0.0) &
            (dot(cross(n, sub(c, b)), sub(centre, b)) >= 0.0) &
            (dot(cross(n, sub(a, c)), sub(centre, c)) >= 0.0) & (height < r);
    Vec3 q, normal;
    double depth;
    if (*face) {
        depth = r - height;
        normal = n;
        q = sub(centre, scale(n, height));
    } else {
        q = closest_on_triangle(a, b, c, centre);
        Vec3 offset = sub(centre, q);
        double distance = norm(offset);
        if (distance >= r) {
            return false;
        }
        if (distance > 0.0) {
            normal = divide(offset, distance);
        } else {
            normal = normalize(cross(sub(b, a), sub(c, a)));
        }
        depth = r - distance;
    }
    out->depth = depth;
    out->normal = normal;
    out->point = sub(q, scale(normal, 0.5 * depth));
    out->volume = cap_volume(r, depth);
    out->area = cap_area(r, depth);
    return true;
}

// One thread per sphere: its wall contacts (see the file's head), none for a
// passive one (frozen or a ghost); a particle of a type that is no sphere
// (`type_sphere` 0) is left alone, its slots and load untouched (a world of
// polyhedra and spheres: polyhedra.cu writes those). Where `round_volume` is 1 the
// contact follows the volume law (volume_law.cuh, engine/cpu/walls.rs patch_force:
// per body type its law row, per pair of materials the volume law's), where 0
// Hertz–Mindlin with the rolling resistance `rolling_model` (contact.cuh; per body
// type its rolling inertia about a contact on its surface). A slot's history is
// `history_doubles` long: the spring (3) and its stiffness; where 5 or more the
// twist (0 under Hertz–Mindlin); where 8 the rolling spring (3).
// `overflow` is set when a particle has more than WALL_SLOTS contacts.
extern "C" __global__ void sphere_walls(
    unsigned n, double dt, const double* position, const double* velocity,
    const double* orientation, const double* angular_momentum, const unsigned* body_type,
    const unsigned char* role, const unsigned char* type_sphere, const double* type_radius,
    const double* type_mass, const double* type_inertia, const double* type_rolling_inertia,
    const unsigned* type_material, unsigned materials, const double* material_pairs,
    unsigned round_volume, unsigned rolling_model, const double* type_law,
    const double* material_law, unsigned walls, const unsigned* wall_facets,
    const double* facets, const double* facet_normals, const double* grid_frame,
    const unsigned* grid_head, const unsigned* grid_starts, const unsigned* grid_entries,
    const unsigned* wall_material, const double* wall_motion, unsigned history_doubles,
    const unsigned* old_count, const long long* old_keys, const double* old_springs,
    unsigned* count, long long* keys, double* springs, double* records, unsigned* record_facet,
    double* force, double* torque, unsigned char* touching, unsigned* overflow) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n || !type_sphere[body_type[i]]) {
        return;
    }
    count[i] = 0;
    if (role[i]) {
        return;
    }
    unsigned kind = body_type[i];
    double r = type_radius[kind];
    Vec3 x = load3(position, i);
    Vec3 l = load3(angular_momentum, i);
    Vec3 inertia = load3(type_inertia, kind);
    Quat q = load_orientation(orientation, i);
    // World::angular_velocity of an isotropic body: L / I.
    Vec3 spin = angular_velocity(q, l, inertia, true);
    Vec3 f = load3(force, i), t = load3(torque, i);
    FacetGrids grids = FacetGrids{grid_frame, grid_head, grid_starts, grid_entries};
    unsigned made = 0;
    for (unsigned w = 0; w < walls; ++w) {
        // The patches of this wall: key, the deepest facet's contact (a face
        // contact wins and closes the patch: engine/cpu/patch.rs), its facet and
        // share.
        long long patch_key[WALL_SLOTS][4];
        FacetContact patch[WALL_SLOTS];
        unsigned patch_facet[WALL_SLOTS];
        double patch_share[WALL_SLOTS];
        bool patch_face[WALL_SLOTS];
        unsigned patches = 0;
        FacetQuery near = facet_query(grids, w, x, r);
        for (unsigned j = next_facet(&near, 0); j != NO_FACET; j = next_facet(&near, j + 1)) {
            unsigned k = wall_facets[w] + j;
            const double* tri = facets + 9 * k;
            Vec3 nrm = load3(facet_normals, k);
            double height = dot(nrm, sub(x, load3(tri, 0)));
            if (!(height >= 0.0 && height <= r)) {
                continue;
            }
            long long key[4];
            plane_key(nrm, load3(tri, 0), r, key);
            unsigned p = 0;
            while (p < patches && !(patch_key[p][0] == key[0] && patch_key[p][1] == key[1] &&
                                    patch_key[p][2] == key[2] && patch_key[p][3] == key[3])) {
                ++p;
            }
            if (p < patches && patch_face[p]) {
                continue;
            }
            FacetContact g;
            bool face;
            if (!sphere_facet(tri, nrm, x, r, height, &g, &face)) {
                continue;
            }
            if (p == patches) {
                if (patches == WALL_SLOTS) {
                    atomicOr(overflow, 1u);
                    continue;
                }
                for (int c = 0; c < 4; ++c) {
                    patch_key[p][c] = key[c];
                }
                patch[p] = g;
                patch_facet[p] = k;
                patch_share[p] = g.volume;
                patch_face[p] = face;
                ++patches;
            } else if (face || g.depth > patch[p].depth) {
                patch[p] = g;
                patch_facet[p] = k;
                patch_share[p] = 1.0;
                patch_face[p] = face;
            }
        }
        const double* wm = wall_motion + 9 * w;
        Vec3 wall_velocity = load3(wm, 0), wall_spin = load3(wm, 1), reference = load3(wm, 2);
        const double* m =
            material_pairs + MATERIAL_DOUBLES * (type_material[kind] * materials + wall_material[w]);
        for (unsigned p = 0; p < patches; ++p) {
            FacetContact g = patch[p];
            bool finite = isfinite(g.normal.x) && isfinite(g.normal.y) && isfinite(g.normal.z);
            if (!(g.area > 0.0) || !finite) {
                continue;
            }
            if (made == WALL_SLOTS) {
                atomicOr(overflow, 1u);
                break;
            }
            // RelativeMotion::of_wall.
            Vec3 lever = sub(g.point, x);
            Vec3 at = add(load3(velocity, i), cross(spin, lever));
            Vec3 wall_at = add(wall_velocity, cross(wall_spin, sub(g.point, reference)));
            Vec3 relative = sub(at, wall_at);
            double inverse_mass = inverse_mass_at(q, x, type_mass[kind], inertia, g.point,
                                                  g.normal);
            // The patch's spring of the last step, found by its key.
            long long* key = keys + KEY_WORDS * (WALL_SLOTS * i + made);
            key[0] = w;
            for (int c = 0; c < 4; ++c) {
                key[1 + c] = patch_key[p][c];
            }
            Spring before = Spring{Vec3{0.0, 0.0, 0.0}, 0.0};
            double twist = 0.0;
            Vec3 rolling = Vec3{0.0, 0.0, 0.0};
            unsigned held = held_slot(old_keys + KEY_WORDS * WALL_SLOTS * i, old_count[i], key);
            if (held < old_count[i]) {
                const double* h = old_springs + history_doubles * (WALL_SLOTS * i + held);
                before = Spring{load3(h, 0), h[3]};
                twist = history_doubles > HISTORY_DOUBLES ? h[4] : 0.0;
                rolling = history_doubles >= 8 ? load3(h + 5, 0) : rolling;
            }
            RoundContact c;
            if (round_volume) {
                VolumeGeometry vg;
                vg.volume = g.volume;
                vg.area = g.area;
                vg.depth = g.depth;
                vg.normal = g.normal;
                vg.point = g.point;
                vg.has_gradient = false;
                const double* law = type_law + TYPE_LAW_DOUBLES * kind;
                const double* row = material_law + MATERIAL_LAW_DOUBLES *
                                                       (type_material[kind] * materials +
                                                        wall_material[w]);
                VolumeMotion motion =
                    VolumeMotion{relative, sub(spin, wall_spin), inverse_mass, law[6]};
                // ContactLaws::wall: the moduli in series over the particle's radius.
                VolumeContact v =
                    volume_contact(vg, motion, row[2 + DAMPING_NODES] / law[5],
                                   row[3 + DAMPING_NODES] / law[5], law[2], law[3], row, before,
                                   twist, dt, x);
                c = RoundContact{v.force, v.torque, v.kept, v.energy, v.dissipated, rolling};
                twist = v.twist;
            } else {
                Rolling roll = Rolling{rolling_model, type_rolling_inertia[kind], rolling};
                c = round_contact(g.depth, g.normal, lever, relative, sub(spin, wall_spin),
                                  inverse_mass, r, m, before, roll, dt);
            }
            double* h = springs + history_doubles * (WALL_SLOTS * i + made);
            store3(h, 0, c.kept.spring);
            h[3] = c.kept.stiffness;
            if (history_doubles > HISTORY_DOUBLES) {
                h[4] = twist;
            }
            if (history_doubles >= 8) {
                store3(h + 5, 0, c.rolling);
            }
            double* record = records + WALL_RECORD_DOUBLES * (WALL_SLOTS * i + made);
            store3(record, 0, c.force);
            store3(record, 1, c.torque);
            record[6] = patch_share[p];
            record[7] = c.energy;
            record[8] = c.dissipated;
            record_facet[WALL_SLOTS * i + made] = patch_facet[p];
            f = add(f, c.force);
            t = add(t, c.torque);
            touching[i] = 1;
            ++made;
        }
    }
    count[i] = made;
    store3(force, i, f);
    store3(torque, i, t);
}

// The walls' sums, first pass (sums.cu folds the rest): thread t of `groups` adds
// the wall contacts of particles t, t + groups, … in that order into row t of
// `rows`, what the particles push on the walls: per wall its force and torque
// about its reference point (6 doubles), then per facet its force (3 doubles).
extern "C" __global__ void wall_sum_rows(unsigned n, const double* position, unsigned walls,
                                         const unsigned* wall_facets, const double* wall_motion,
                                         const unsigned* count, const long long* keys,
                                         const double* records, const unsigned* record_facet,
                                         unsigned groups, double* rows) {
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
            Vec3 f = load3(record, 0), torque = load3(record, 1);
            add_wall_reaction(row, w, x, load3(wall_motion + 9 * w, 2), f, torque);
            double share = record[6];
            if (share > 0.0) {
                unsigned facet = 2 * walls + record_facet[slot];
                store3(row, facet, sub(load3(row, facet), scale(f, share / share)));
            }
        }
    }
}

// One thread a particle: the elastic energy held in its wall contacts, the energy
// they dissipated over the step with the springs of its wall contacts that ended
// (in a slot of the last step, not in this one's; in the order of their keys), and
// their count, as record `first + i` of `terms` (ENERGY_RECORD doubles, summed by
// sums.cu). The CPU backend's terms (engine/cpu/walls.rs), the ended springs in its
// order. A slot's history is `history_doubles` long, the spring first (spheres' and
// polyhedra's contacts alike).
extern "C" __global__ void wall_energy_terms(unsigned n, const unsigned* count,
                                             const long long* keys, const double* records,
                                             const unsigned* old_count,
                                             const long long* old_keys,
                                             const double* old_springs,
                                             unsigned history_doubles, unsigned first,
                                             double* terms) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) {
        return;
    }
    double energy = 0.0, dissipated = 0.0;
    for (unsigned s = 0; s < count[i]; ++s) {
        const double* record = records + WALL_RECORD_DOUBLES * (WALL_SLOTS * i + s);
        energy += record[7];
        dissipated += record[8];
    }
    // The ended slots, in the order of their keys.
    unsigned order[WALL_SLOTS];
    unsigned m = 0;
    for (unsigned s = 0; s < old_count[i]; ++s) {
        const long long* o = old_keys + KEY_WORDS * (WALL_SLOTS * i + s);
        if (held_slot(keys + KEY_WORDS * WALL_SLOTS * i, count[i], o) < count[i]) {
            continue;
        }
        unsigned at = m++;
        for (; at > 0; --at) {
            const long long* a = old_keys + KEY_WORDS * (WALL_SLOTS * i + order[at - 1]);
            unsigned c = 0;
            while (c < KEY_WORDS && a[c] == o[c]) {
                ++c;
            }
            if (c == KEY_WORDS || a[c] < o[c]) {
                break;
            }
            order[at] = order[at - 1];
        }
        order[at] = s;
    }
    for (unsigned k = 0; k < m; ++k) {
        const double* h = old_springs + history_doubles * (WALL_SLOTS * i + order[k]);
        dissipated += spring_energy(Spring{load3(h, 0), h[3]});
    }
    double* record = terms + ENERGY_RECORD * (first + i);
    record[0] = energy;
    record[1] = dissipated;
    record[2] = (double)count[i];
    record[3] = 0.0;
    record[4] = 0.0;
}
