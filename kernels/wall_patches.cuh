// The patches of a polyhedron against the walls (engine/cpu/walls.rs,
// particle_contacts, and engine/cpu/patch.rs with Merge::Sum): per wall, the
// facets the particle's centroid lies over within its bounding radius, each
// facet's overlap (facet.cuh) in world coordinates (engine/cpu/dispatch.rs,
// facet_geometry), summed by plane into patches whose prisms tile them, each with
// its facets' shares (volumes). The CPU's operations in its order, the facets of
// a wall in index order as the CPU's lists hold them. Compiled after vec.cuh,
// triangle.cuh, overlap.cuh, facet.cuh and facet_grid.cuh.

// Facets one patch's shares may name (a particle has at most WALL_SLOTS patches,
// triangle.cuh).
#define SHARE_SLOTS 16u
// A patch's geometry: volume, point, normal, area, depth, rotation gradient.
#define PATCH_DOUBLES 12u

struct Patch {
    long long key[4];
    double volume, area, depth;
    Vec3 point, normal, rotation_gradient;
    unsigned shares;
    unsigned facet[SHARE_SLOTS];
    double share[SHARE_SLOTS];
};

// Adds facet `f`'s contact to patch `p` (engine/cpu/patch.rs, PatchSet::add with
// Merge::Sum); false where the patch has no room for another share.
static __device__ bool merge_into(Patch* p, unsigned f, double volume, double area, double depth,
                                  Vec3 point, Vec3 normal, Vec3 rotation_gradient) {
    if (p->shares == SHARE_SLOTS) {
        return false;
    }
    double v = p->volume + volume;
    Vec3 weighted = add(scale(p->point, p->volume), scale(point, volume));
    p->point = divide(weighted, v);
    Vec3 sum = add(scale(p->normal, p->area), scale(normal, area));
    p->area = norm(sum);
    p->normal = divide(sum, p->area);
    p->volume = v;
    p->depth = fmax(p->depth, depth);
    p->rotation_gradient = add(p->rotation_gradient, rotation_gradient);
    p->facet[p->shares] = f;
    p->share[p->shares] = volume;
    ++p->shares;
    return true;
}

// The patches of particle `side` (its shape placed in its body frame, bounding
// radius `radius`, centroid `x`, orientation `q`) against the facets of wall `w`
// near it (facet_grid.cuh; the wall's facets from `first` in `facets`, world
// triangles of 9 doubles each, and `facet_normals`, unit normals), into `patches`
// (`*count` of them, at most WALL_SLOTS); false where they do not fit.
static __device__ bool wall_patches(const ShapeTable& table, const Side* side, double radius,
                                    Vec3 x, Quat q, const FacetGrids& grids, unsigned w,
                                    unsigned first, const double* facets,
                                    const double* facet_normals, Polygon* poly, Patch* patches,
                                    unsigned* count) {
    Quat back = conjugate(q);
    FacetQuery near = facet_query(grids, w, x, radius);
    for (unsigned j = next_facet(&near, 0); j != NO_FACET; j = next_facet(&near, j + 1)) {
        unsigned f = first + j;
        const double* t = facets + 9 * f;
        Vec3 n = load3(facet_normals, f);
        double height = dot(n, sub(x, load3(t, 0)));
        if (!(height >= 0.0 && height <= radius)) {
            continue;
        }
        // The triangle in the body frame (Isometry3::inverse_transform_point).
        Vec3 tri[3];
        for (unsigned k = 0; k < 3; ++k) {
            tri[k] = rotate(back, sub(load3(t, k), x));
        }
        double o[FACET_DOUBLES];
        facet_overlap(table, side, radius, tri, poly, o);
        if (!(o[0] > 0.0)) {
            continue;
        }
        Vec3 gradient = load3(o + 4, 0);
        double area = norm(gradient);
        Vec3 normal = divide(scale(rotate(q, gradient), -1.0), area);
        Vec3 point = add(rotate(q, load3(o + 1, 0)), x);
        Vec3 rotation_gradient = rotate(q, load3(o + 7, 0));
        long long key[4];
        plane_key(n, load3(t, 0), radius, key);
        unsigned p = 0;
        while (p < *count && !(patches[p].key[0] == key[0] && patches[p].key[1] == key[1] &&
                               patches[p].key[2] == key[2] && patches[p].key[3] == key[3])) {
            ++p;
        }
        if (p < *count) {
            if (!merge_into(&patches[p], f, o[0], area, o[10], point, normal,
                            rotation_gradient)) {
                return false;
            }
            continue;
        }
        if (*count == WALL_SLOTS) {
            return false;
        }
        Patch* fresh = &patches[(*count)++];
        for (unsigned c = 0; c < 4; ++c) {
            fresh->key[c] = key[c];
        }
        fresh->volume = o[0];
        fresh->area = area;
        fresh->depth = o[10];
        fresh->point = point;
        fresh->normal = normal;
        fresh->rotation_gradient = rotation_gradient;
        fresh->shares = 1;
        fresh->facet[0] = f;
        fresh->share[0] = o[0];
    }
    return true;
}
