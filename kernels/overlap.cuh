// The exact overlap of two convex polyhedra: volume, centroid, contact normal and
// area, extent along the normal, and the volume's derivatives with respect to
// turning either shape (geometry/overlap/mod.rs). The bit-mask path
// (geometry/overlap/masked.rs) for shapes of at most 64 faces and 64 vertices:
// per plane of one shape, a bit per vertex of the other says "outside" and one
// "on"; the faces that bound the intersection, and the planes that cut each, follow
// from ANDs of these with the faces' vertex sets; each such face is clipped
// (Sutherland–Hodgman, geometry/polygon.rs) and its piece summed by the divergence
// theorem. The CPU's operations in its order, without its per-pair cache: where the
// CPU evaluates a kept topology instead of clipping, the two differ by round-off.
// Compiled after vec.cuh.

#define MASK_FACES 64u
#define MASK_VERTICES 64u
// Most vertices of a clipped face: a face of at most 64 vertices, one more per cut.
#define MAX_CLIPPED 128u
// Pieces' vertices kept for the extent along the normal; beyond these the faces
// are clipped a second time to find it.
#define PIECE_POINTS 128u
// An overlap's record: volume (0: apart), centroid, normal, area, depth, the
// rotation gradients of A and of B.
#define OVERLAP_DOUBLES 15u

typedef unsigned long long Mask;

struct Plane {
    Vec3 normal;
    double offset;
};

// A rotation matrix, by rows.
struct Mat3 {
    double m[9];
};

static __device__ __forceinline__ double plane_distance(Plane p, Vec3 x) {
    return dot(p.normal, x) - p.offset;
}

// nalgebra's UnitQuaternion::to_rotation_matrix.
static __device__ __forceinline__ Mat3 rotation_matrix(Quat q) {
    double i = q.x, j = q.y, k = q.z, w = q.w;
    double ww = w * w, ii = i * i, jj = j * j, kk = k * k;
    double ij = i * j * 2.0, wk = w * k * 2.0, wj = w * j * 2.0;
    double ik = i * k * 2.0, jk = j * k * 2.0, wi = w * i * 2.0;
    return Mat3{{ww + ii - jj - kk, ij - wk, wj + ik, wk + ij, ww - ii + jj - kk, jk - wi,
                 ik - wj, wi + jk, ww - ii - jj + kk}};
}

// A matrix times a vector as nalgebra's gemv computes it: column by column, so
// each row a dot product from the left.
static __device__ __forceinline__ Vec3 mat_vec(const Mat3& r, Vec3 v) {
    return Vec3{r.m[0] * v.x + r.m[1] * v.y + r.m[2] * v.z,
                r.m[3] * v.x + r.m[4] * v.y + r.m[5] * v.z,
                r.m[6] * v.x + r.m[7] * v.y + r.m[8] * v.z};
}

// The index of the lowest set bit of a nonzero mask.
static __device__ __forceinline__ unsigned lowest_bit(Mask m) {
    return (unsigned)(__ffsll((long long)m) - 1);
}

// Vertices 0..n as a set.
static __device__ __forceinline__ Mask first_vertices(unsigned n) {
    return n >= 64u ? ~0ull : (1ull << n) - 1ull;
}

// The shapes on the device (engine/cuda/device_polyhedra.rs), each in its body
// frame with its centroid at the origin.
// A body type's shape index where it has no shape in the table: a sphere.
#define NO_SHAPE 0xffffffffu

struct ShapeTable {
    // Per shape: its first vertex, vertex count, first face, face count.
    const unsigned* index;
    // Per face: its first entry in `loops` and its vertex count.
    const unsigned* face_span;
    // Each face's vertices (indices within the shape), counter-clockwise from outside.
    const unsigned* loops;
    // Per face: its vertices as bits.
    const Mask* face_masks;
    // Three doubles per vertex.
    const double* vertices;
    // Four doubles per face: the outward unit normal, the offset.
    const double* planes;
    // Per shape: the largest distance of a vertex from the centroid.
    const double* circumradius;
};

// One shape placed in A's frame, as the other shape's planes see it (masked.rs,
// MaskedSide): `out[k]` and `on[k]` are its vertices outside and on plane k of the
// other shape (no bits beyond its vertices; zero for planes not reached).
struct Side {
    Vec3 points[MASK_VERTICES];
    Plane planes[MASK_FACES];
    unsigned vertex_count, face_count, face_base;
    // All its vertices.
    Mask all;
    // Its planes that the other shape's bounding sphere reaches.
    Mask reached;
    Mask out[MASK_FACES];
    Mask on[MASK_FACES];
};

// Places shape `shape` in A's frame: turned by `*r` and moved by `t` (overlap/mod.rs,
// point_in_a and plane_in_a); with `r` null, as it is in its body frame.
static __device__ void place_side(const ShapeTable& table, unsigned shape, const Mat3* r, Vec3 t,
                                  Side* side) {
    unsigned vertex_base = table.index[4 * shape];
    side->vertex_count = table.index[4 * shape + 1];
    side->face_base = table.index[4 * shape + 2];
    side->face_count = table.index[4 * shape + 3];
    side->all = first_vertices(side->vertex_count);
    for (unsigned v = 0; v < side->vertex_count; ++v) {
        Vec3 p = load3(table.vertices, vertex_base + v);
        side->points[v] = r ? add(mat_vec(*r, p), t) : p;
    }
    for (unsigned f = 0; f < side->face_count; ++f) {
        const double* plane = table.planes + 4 * (side->face_base + f);
        Vec3 normal = Vec3{plane[0], plane[1], plane[2]};
        if (r) {
            normal = mat_vec(*r, normal);
            side->planes[f] = Plane{normal, plane[3] + dot(normal, t)};
        } else {
            side->planes[f] = Plane{normal, plane[3]};
        }
    }
}

// Shape `shape` as it is in its body frame.
static __device__ __forceinline__ void place_body(const ShapeTable& table, unsigned shape,
                                                  Side* side) {
    place_side(table, shape, 0, Vec3{0.0, 0.0, 0.0}, side);
}

// The planes of `side` whose outside the ball (`centre`, `radius`) reaches to within
// `tol` (masked.rs, planes_reached).
static __device__ Mask planes_reached(const Side* side, Vec3 centre, double radius, double tol) {
    Mask reached = 0;
    for (unsigned k = 0; k < side->face_count; ++k) {
        double reach = plane_distance(side->planes[k], centre) + radius + tol;
        if (reach >= 0.0) {
            reached |= 1ull << k;
        }
    }
    return reached;
}

// Per reached plane of `other`, the vertices of `own` outside it and on it, within
// `tol` (masked.rs, vertex_masks_scalar).
static __device__ void vertex_masks(Side* own, const Side* other, double tol) {
    for (unsigned k = 0; k < other->face_count; ++k) {
        own->out[k] = 0;
        own->on[k] = 0;
    }
    for (Mask planes = other->reached; planes != 0; planes &= planes - 1) {
        unsigned k = lowest_bit(planes);
        Plane p = other->planes[k];
        Mask o = 0, n = 0;
        for (unsigned v = 0; v < own->vertex_count; ++v) {
            double d = plane_distance(p, own->points[v]);
            o |= (Mask)(d > tol) << v;
            n |= (Mask)(d <= tol && d >= -tol) << v;
        }
        own->out[k] = o;
        own->on[k] = n;
    }
}

// Whether one plane of the other shape has every vertex of `side` outside.
static __device__ bool separated(const Side* side, const Side* other) {
    for (unsigned k = 0; k < other->face_count; ++k) {
        if (side->out[k] == side->all) {
            return true;
        }
    }
    return false;
}

// How face `f` of `own` meets `other` (masked.rs, face_cut): false when it cannot
// bound the intersection; else the other's planes that cut it and whether it lies
// flush in a plane of the other of equal orientation.
static __device__ bool face_cut(const ShapeTable& table, const Side* own, const Side* other,
                                unsigned f, Mask* planes, bool* flush) {
    Mask out_f = other->out[f], on_f = other->on[f];
    Mask in_f = other->all & ~(out_f | on_f);
    bool straddles = out_f != 0 && in_f != 0;
    bool touches_from_inside = on_f != 0 && out_f == 0;
    if (!(straddles || touches_from_inside)) {
        return false;
    }
    Mask face = table.face_masks[own->face_base + f];
    Vec3 normal = own->planes[f].normal;
    *planes = 0;
    *flush = false;
    for (Mask reached = other->reached; reached != 0; reached &= reached - 1) {
        unsigned g = lowest_bit(reached);
        Mask outside = face & own->out[g];
        if (outside == face) {
            return false;
        }
        if (outside == 0) {
            if ((face & own->on[g]) == face && dot(other->planes[g].normal, normal) > 0.0) {
                *flush = true;
            }
            continue;
        }
        Mask other_face = table.face_masks[other->face_base + g];
        bool reaches = ((other_face & out_f) != 0 && (other_face & in_f) != 0) ||
                       (other_face & on_f) != 0;
        *planes |= (Mask)reaches << g;
    }
    return true;
}

// A convex polygon in a double buffer (polygon.rs, FixedPolygon).
struct Polygon {
    Vec3 buffers[2][MAX_CLIPPED];
    double dist[MAX_CLIPPED];
    unsigned current, len;
};

static __device__ __forceinline__ const Vec3* polygon_points(const Polygon* poly) {
    return poly->buffers[poly->current];
}

// Where the segment from `inside` (distance di <= 0) to `outside` (do_ > 0) meets
// the plane (polygon.rs, cut).
static __device__ __forceinline__ Vec3 cut_point(Vec3 inside, double di, Vec3 outside,
                                                  double do_) {
    double t = di / (di - do_);
    return add(inside, scale(sub(outside, inside), t));
}

// Clips the polygon to the inside of `plane` (polygon.rs, FixedPolygon::clip).
static __device__ void clip_polygon(Polygon* poly, Plane plane) {
    unsigned n = poly->len;
    const Vec3* input = poly->buffers[poly->current];
    Vec3* output = poly->buffers[poly->current ^ 1u];
    bool any_out = false, any_in = false;
    for (unsigned k = 0; k < n; ++k) {
        double d = plane_distance(plane, input[k]);
        poly->dist[k] = d;
        any_out |= d > 0.0;
        any_in |= d <= 0.0;
    }
    if (!any_out) {
        return;
    }
    if (!any_in) {
        poly->len = 0;
        return;
    }
    unsigned m = 0;
    for (unsigned k = 0; k < n; ++k) {
        unsigned j = k + 1 == n ? 0 : k + 1;
        Vec3 p = input[k], q = input[j];
        double dp = poly->dist[k], dq = poly->dist[j];
        if (dp <= 0.0) {
            if (m < MAX_CLIPPED) {
                output[m++] = p;
            }
            if (dq > 0.0 && m < MAX_CLIPPED) {
                output[m++] = cut_point(p, dp, q, dq);
            }
        } else if (dq <= 0.0 && m < MAX_CLIPPED) {
            output[m++] = cut_point(q, dq, p, dp);
        }
    }
    poly->current ^= 1u;
    poly->len = m;
}

// Face `f` of `side` as a polygon.
static __device__ void set_face(const ShapeTable& table, const Side* side, unsigned f,
                                Polygon* poly) {
    unsigned first = table.face_span[2 * (side->face_base + f)];
    unsigned count = table.face_span[2 * (side->face_base + f) + 1];
    poly->current = 0;
    poly->len = count < MAX_CLIPPED ? count : MAX_CLIPPED;
    for (unsigned k = 0; k < poly->len; ++k) {
        poly->buffers[0][k] = side->points[table.loops[first + k]];
    }
}

// Face `f` of `own` clipped by the planes `cut` of `other` (masked.rs,
// clip_by_planes): false when fewer than three vertices remain.
static __device__ bool clipped_face(const ShapeTable& table, const Side* own, const Side* other,
                                    unsigned f, Mask cut, Polygon* poly) {
    set_face(table, own, f, poly);
    for (; cut != 0; cut &= cut - 1) {
        clip_polygon(poly, other->planes[lowest_bit(cut)]);
        if (poly->len < 3) {
            return false;
        }
    }
    return poly->len >= 3;
}

// Volume and first moment of a closed surface of convex planar pieces (polygon.rs,
// SurfaceSums): cones from the first piece's first vertex.
struct SurfaceSums {
    bool has_apex;
    Vec3 apex;
    double volume6;
    Vec3 moment24;
};

// Vector areas and their moments of one shape's pieces (overlap/mod.rs, SideSums).
struct SideSums {
    Vec3 area, moment, flush_area, flush_moment;
};

// The pieces summed as they are found, and their vertices for the extent.
struct Pieces {
    SideSums a, b;
    SurfaceSums surface;
    Vec3 points[PIECE_POINTS];
    unsigned point_count;
    // More vertices than `points` holds.
    bool overflow;
};

// Adds a piece (polygon.rs, SurfaceSums::add_piece_by; overlap/mod.rs, Pieces::add).
static __device__ void add_piece(Pieces* pieces, const Vec3* poly, unsigned len, Vec3 normal,
                                 bool of_b, bool flush) {
    SurfaceSums* s = &pieces->surface;
    Vec3 p0 = poly[0];
    if (!s->has_apex) {
        s->has_apex = true;
        s->apex = p0;
    }
    double twice_area = 0.0;
    Vec3 spread = Vec3{0.0, 0.0, 0.0};
    Vec3 u = sub(poly[1], p0);
    for (unsigned k = 2; k < len; ++k) {
        Vec3 v = sub(poly[k], p0);
        double w = dot(normal, cross(u, v));
        twice_area += w;
        spread = add(spread, scale(add(u, v), w));
        u = v;
    }
    Vec3 offset = sub(p0, s->apex);
    double h = dot(offset, normal);
    s->volume6 += h * twice_area;
    s->moment24 = add(s->moment24, scale(add(spread, scale(offset, 3.0 * twice_area)), h));
    Vec3 weighted = add(spread, scale(p0, 3.0 * twice_area));
    Vec3 area = scale(normal, 0.5 * twice_area);
    Vec3 c = cross(weighted, normal);
    Vec3 moment = divide(c, 6.0);
    SideSums* side = of_b ? &pieces->b : &pieces->a;
    if (flush) {
        side->flush_area = add(side->flush_area, area);
        side->flush_moment = add(side->flush_moment, moment);
    } else {
        side->area = add(side->area, area);
        side->moment = add(side->moment, moment);
    }
    for (unsigned k = 0; k < len; ++k) {
        if (pieces->point_count < PIECE_POINTS) {
            pieces->points[pieces->point_count++] = poly[k];
        } else {
            pieces->overflow = true;
        }
    }
}

// The lowest and highest height along `normal` of the piece's vertices.
static __device__ __forceinline__ void extend_extent(const Vec3* points, unsigned len,
                                                     Vec3 normal, double* lo, double* hi) {
    for (unsigned k = 0; k < len; ++k) {
        double h = dot(normal, points[k]);
        *lo = fmin(*lo, h);
        *hi = fmax(*hi, h);
    }
}

// The faces of A clipped by B, then those of B by A (masked.rs, plan_with_sets and
// overlap_planned): summed into `pieces`, or, with `pieces` null, their vertices'
// extent along `normal`. False where a plane separates the shapes.
static __device__ bool clip_faces(const ShapeTable& table, const Side* a, const Side* b,
                                  Polygon* poly, Pieces* pieces, Vec3 normal, double* lo,
                                  double* hi) {
    if (separated(a, b) || separated(b, a)) {
        return false;
    }
    for (int of_b = 0; of_b < 2; ++of_b) {
        const Side* own = of_b ? b : a;
        const Side* other = of_b ? a : b;
        for (Mask faces = own->reached; faces != 0; faces &= faces - 1) {
            unsigned f = lowest_bit(faces);
            Mask cut;
            bool flush;
            // A face of B lying in a plane of A of equal orientation is covered by
            // A's face.
            if (!face_cut(table, own, other, f, &cut, &flush) || (of_b && flush)) {
                continue;
            }
            if (!clipped_face(table, own, other, f, cut, poly)) {
                continue;
            }
            if (pieces) {
                add_piece(pieces, polygon_points(poly), poly->len, own->planes[f].normal,
                          of_b != 0, flush);
            } else {
                extend_extent(polygon_points(poly), poly->len, normal, lo, hi);
            }
        }
    }
    return true;
}

// What one overlap needs besides its record: both shapes placed, a polygon, the
// pieces. About 19 KB: a thread's local memory.
struct OverlapScratch {
    Side a, b;
    Polygon poly;
    Pieces pieces;
};

// The overlap of shapes `shape_a` and `shape_b`, B's centroid at `t` and turned by
// `q` in A's frame, into `record` (OVERLAP_DOUBLES; volume 0 where they do not
// overlap or only touch). geometry/overlap/mod.rs, overlap_with and summarise.
static __device__ void polyhedron_overlap(const ShapeTable& table, unsigned shape_a,
                                          unsigned shape_b, Vec3 t, Quat q,
                                          OverlapScratch* s, double* record) {
    for (unsigned c = 0; c < OVERLAP_DOUBLES; ++c) {
        record[c] = 0.0;
    }
    double ra = table.circumradius[shape_a], rb = table.circumradius[shape_b];
    if (norm(t) >= ra + rb) {
        return;
    }
    Mat3 r = rotation_matrix(q);
    place_body(table, shape_a, &s->a);
    place_side(table, shape_b, &r, t, &s->b);
    double tol = 1e-12 * fmax(ra, rb);
    s->a.reached = planes_reached(&s->a, t, rb, tol);
    s->b.reached = planes_reached(&s->b, Vec3{0.0, 0.0, 0.0}, ra, tol);
    vertex_masks(&s->a, &s->b, tol);
    vertex_masks(&s->b, &s->a, tol);
    Pieces* pieces = &s->pieces;
    pieces->a = pieces->b = SideSums{};
    pieces->surface = SurfaceSums{};
    pieces->point_count = 0;
    pieces->overflow = false;
    double lo = 0.0, hi = 0.0;
    Vec3 zero = Vec3{0.0, 0.0, 0.0};
    if (!clip_faces(table, &s->a, &s->b, &s->poly, pieces, zero, &lo, &hi) ||
        !pieces->surface.has_apex) {
        return;
    }
    double volume = pieces->surface.volume6 / 6.0;
    if (!(volume > 0.0)) {
        return;
    }
    SideSums a = pieces->a, b = pieces->b;
    Vec3 s_b = add(b.area, a.flush_area);
    Vec3 twice = sub(a.area, s_b);
    double area = 0.5 * norm(twice);
    // A shape inside the other has no area vector: the normal is a convention.
    Vec3 normal = Vec3{1.0, 0.0, 0.0};
    if (area > 0.0) {
        double d = 2.0 * area;
        normal = divide(twice, d);
    }
    // The largest finite doubles: there is at least one piece.
    lo = 1.7976931348623157e308;
    hi = -1.7976931348623157e308;
    if (pieces->overflow) {
        clip_faces(table, &s->a, &s->b, &s->poly, 0, normal, &lo, &hi);
    } else {
        extend_extent(pieces->points, pieces->point_count, normal, &lo, &hi);
    }
    double d4 = 4.0 * pieces->surface.volume6;
    Vec3 m = pieces->surface.moment24;
    Vec3 centroid = add(pieces->surface.apex, divide(m, d4));
    Vec3 gradient_b = sub(add(b.moment, a.flush_moment), cross(t, s_b));
    record[0] = volume;
    store3(record + 1, 0, centroid);
    store3(record + 4, 0, normal);
    record[7] = area;
    record[8] = hi - lo;
    store3(record + 9, 0, a.moment);
    store3(record + 12, 0, gradient_b);
}
