// The facets of a wall near a particle, found through the wall's facet grid
// (world/walls.rs FacetGrid: a uniform grid in the wall's own frame, each cell
// listing in ascending order the facets whose bounding boxes meet it), so that a
// wall kernel's work per particle follows the facets near it, not the mesh's size.
// The facets come out in ascending index order without repeats, as the CPU
// backend's lists hold them: the wall stages merge patches and sum forces in facet
// order, and that order is part of their bits. Compiled after vec.cuh.
//
// Layout, per wall: its frame and its grid's box (GRID_FRAME_DOUBLES: the frame's
// translation (3) and rotation (i, j, k, w) in the world, the grid's origin (3) in
// the frame, the cell edge), its grid's cells along x, y and z and where its cells'
// starts and its entries begin in the shared arrays (GRID_WORDS); per cell its
// first entry, relative to the wall's first, and one start past the last cell; the
// entries: facet indices within the wall.

#define GRID_FRAME_DOUBLES 11u
#define GRID_WORDS 5u
#define NO_FACET 0xffffffffu

// The walls' facet grids as the kernels receive them (see the layout above).
struct FacetGrids {
    const double* frame;
    const unsigned* head;
    const unsigned* starts;
    const unsigned* entries;
};

// The cells of one wall's grid that a particle's ball may meet: `lo` to `hi`
// (inclusive) along each axis; none where `lo[0] > hi[0]`.
struct FacetQuery {
    const unsigned* starts;
    const unsigned* entries;
    unsigned dims[3];
    unsigned lo[3], hi[3];
};

// Cell coordinate of `p` along one axis, clamped to the grid (FacetGrid::coords).
static __device__ __forceinline__ unsigned grid_coord(double p, double origin, double cell,
                                                      unsigned dims) {
    double c = floor((p - origin) / cell);
    if (!(c > 0.0)) {
        return 0;
    }
    return c < (double)(dims - 1) ? (unsigned)c : dims - 1;
}

// The cells of wall `w`'s grid that the ball of `radius` about the world point `x`
// may meet (FacetGrid::query). The ball is widened by a millionth of its radius:
// the centre is brought into the wall's frame here and the facets were placed in
// the world on the host, so the two differ by round-off, and a facet the exact
// tests would find must not fall outside by it (a facet more is only tested).
static __device__ FacetQuery facet_query(const FacetGrids& grids, unsigned w, Vec3 x,
                                         double radius) {
    const unsigned* head = grids.head + GRID_WORDS * w;
    const double* frame = grids.frame + GRID_FRAME_DOUBLES * w;
    FacetQuery q;
    q.starts = grids.starts + head[3];
    q.entries = grids.entries + head[4];
    q.lo[0] = 1;
    q.hi[0] = 0;
    for (unsigned k = 0; k < 3; ++k) {
        q.dims[k] = head[k];
    }
    if (q.dims[0] == 0) {
        return q;
    }
    Quat rotation = Quat{frame[6], frame[3], frame[4], frame[5]};
    Vec3 local = rotate(conjugate(rotation), sub(x, load3(frame, 0)));
    double at[3] = {local.x, local.y, local.z};
    double half = radius * (1.0 + 1e-6);
    double cell = frame[10];
    unsigned lo[3], hi[3];
    for (unsigned k = 0; k < 3; ++k) {
        double origin = frame[7 + k];
        double top = origin + q.dims[k] * cell;
        if (at[k] + half < origin || at[k] - half > top) {
            return q;
        }
        lo[k] = grid_coord(at[k] - half, origin, cell, q.dims[k]);
        hi[k] = grid_coord(at[k] + half, origin, cell, q.dims[k]);
    }
    for (unsigned k = 0; k < 3; ++k) {
        q.lo[k] = lo[k];
        q.hi[k] = hi[k];
    }
    return q;
}

// The smallest facet index at least `from` that the query's cells list, NO_FACET
// where none: each cell's entries ascend, so its first entry at least `from` is
// found by bisection, and the least of those over the cells is the next facet.
static __device__ unsigned next_facet(const FacetQuery* q, unsigned from) {
    unsigned best = NO_FACET;
    if (q->lo[0] > q->hi[0]) {
        return best;
    }
    for (unsigned z = q->lo[2]; z <= q->hi[2]; ++z) {
        for (unsigned y = q->lo[1]; y <= q->hi[1]; ++y) {
            for (unsigned x = q->lo[0]; x <= q->hi[0]; ++x) {
                unsigned c = (z * q->dims[1] + y) * q->dims[0] + x;
                unsigned a = q->starts[c], b = q->starts[c + 1];
                while (a < b) {
                    unsigned mid = a + (b - a) / 2;
                    if (q->entries[mid] < from) {
                        a = mid + 1;
                    } else {
                        b = mid;
                    }
                }
                if (a < q->starts[c + 1] && q->entries[a] < best) {
                    best = q->entries[a];
                }
            }
        }
    }
    return best;
}
