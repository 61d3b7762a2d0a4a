// The overlap of a convex polyhedron with the prism under one wall facet
// (geometry/wall.rs, polyhedron_triangle): the particle's volume behind the facet
// within the facet's side planes, its centroid, the gradients of that volume with
// respect to the particle's translation and rotation, the depth, the area of the
// particle's section over the facet. Everything in the particle's body frame. The
// CPU's operations in its order (it keeps nothing between steps here, so the same
// bits), but for the pieces' vertices: the CPU keeps them for the volume's cones,
// the kernel clips the faces a second time instead, in the same order. Compiled
// after vec.cuh, overlap.cuh and triangle.cuh.

// A facet overlap's record: volume (0: none), centroid, volume gradient, rotation
// gradient, depth, section area, facet normal.
#define FACET_DOUBLES 15u

// The vector area of a planar polygon (geometry/polygon.rs, vector_area).
static __device__ Vec3 polygon_vector_area(const Vec3* poly, unsigned len) {
    Vec3 s = Vec3{0.0, 0.0, 0.0};
    Vec3 p0 = poly[0];
    for (unsigned k = 1; k + 1 < len; ++k) {
        s = add(s, cross(sub(poly[k], p0), sub(poly[k + 1], p0)));
    }
    return scale(s, 0.5);
}

// The first moment of a planar polygon's vector area about the origin
// (geometry/polygon.rs, area_moment).
static __device__ Vec3 polygon_area_moment(const Vec3* poly, unsigned len) {
    Vec3 m = Vec3{0.0, 0.0, 0.0};
    Vec3 p0 = poly[0];
    for (unsigned k = 1; k + 1 < len; ++k) {
        Vec3 a = scale(cross(sub(poly[k], p0), sub(poly[k + 1], p0)), 0.5);
        Vec3 sum = add(add(p0, poly[k]), poly[k + 1]);
        Vec3 centre = divide(sum, 3.0);
        m = add(m, cross(centre, a));
    }
    return m;
}

// Signed volume and first moment of cones from `origin` (geometry/polygon.rs,
// ConeSums).
struct ConeSums {
    Vec3 origin;
    double volume6;
    Vec3 moment24;
};

static __device__ void cone_add_polygon(ConeSums* cone, const Vec3* poly, unsigned len) {
    Vec3 a = sub(poly[0], cone->origin);
    for (unsigned k = 1; k + 1 < len; ++k) {
        Vec3 b = sub(poly[k], cone->origin);
        Vec3 c = sub(poly[k + 1], cone->origin);
        double det = dot(a, cross(b, c));
        cone->volume6 += det;
        cone->moment24 = add(cone->moment24, scale(add(add(a, b), c), det));
    }
}

static __device__ Vec3 cone_centroid(const ConeSums* cone) {
    double d = 4.0 * cone->volume6;
    return add(cone->origin, divide(cone->moment24, d));
}

// Whether some vertex of face `f` of `side` lies behind `facet` (wall.rs,
// faces_behind).
static __device__ bool face_behind(const ShapeTable& table, const Side* side, unsigned f,
                                   Plane facet) {
    unsigned first = table.face_span[2 * (side->face_base + f)];
    unsigned count = table.face_span[2 * (side->face_base + f) + 1];
    for (unsigned k = 0; k < count; ++k) {
        if (plane_distance(facet, side->points[table.loops[first + k]]) < 0.0) {
            return true;
        }
    }
    return false;
}

// Clips the polygon by `planes` in order until fewer than three vertices remain;
// whether three or more are left.
static __device__ bool clip_by(Polygon* poly, const Plane* planes, unsigned count) {
    for (unsigned k = 0; k < count; ++k) {
        clip_polygon(poly, planes[k]);
        if (poly->len < 3) {
            return false;
        }
    }
    return poly->len >= 3;
}

// The pieces of the particle's overlap with the prism bounded by `planes` (the
// facet, then the sides), in order: the particle's faces behind the facet clipped
// to the prism, then the prism's sides reaching `reach` below the facet clipped to
// the particle (wall.rs, overlap_with_prism). Each piece goes to `visit`.
template <typename Visit>
static __device__ void prism_pieces(const ShapeTable& table, const Side* side, const Vec3* tri,
                                    const Plane* planes, double reach, Polygon* poly,
                                    Visit visit) {
    Vec3 n = planes[0].normal;
    for (unsigned f = 0; f < side->face_count; ++f) {
        if (!face_behind(table, side, f, planes[0])) {
            continue;
        }
        set_face(table, side, f, poly);
        if (clip_by(poly, planes, 4)) {
            visit(false, polygon_points(poly), poly->len);
        }
    }
    for (unsigned s = 1; s < 4; ++s) {
        bool outside = false;
        for (unsigned v = 0; v < side->vertex_count; ++v) {
            outside |= !(plane_distance(planes[s], side->points[v]) <= 0.0);
        }
        if (!outside) {
            continue;
        }
        Vec3 a = tri[s - 1], b = tri[s % 3];
        Vec3 down = scale(n, reach);
        poly->current = 0;
        poly->len = 4;
        poly->buffers[0][0] = a;
        poly->buffers[0][1] = sub(a, down);
        poly->buffers[0][2] = sub(b, down);
        poly->buffers[0][3] = b;
        if (clip_by(poly, side->planes, side->face_count)) {
            visit(true, polygon_points(poly), poly->len);
        }
    }
}

// The overlap of the particle `side` (in its body frame) with the prism under the
// triangle `tri` (body frame, counter-clockwise seen from the particle), into
// `record` (FACET_DOUBLES; volume 0 where they do not overlap).
static __device__ void facet_overlap(const ShapeTable& table, const Side* side,
                                     double circumradius, const Vec3* tri, Polygon* poly,
                                     double* record) {
    for (unsigned c = 0; c < FACET_DOUBLES; ++c) {
        record[c] = 0.0;
    }
    Vec3 origin = Vec3{0.0, 0.0, 0.0};
    if (norm(closest_on_triangle(tri[0], tri[1], tri[2], origin)) >= circumradius) {
        return;
    }
    Vec3 n = normalize(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])));
    if (!(isfinite(n.x) && isfinite(n.y) && isfinite(n.z))) {
        return;
    }
    Plane planes[4];
    planes[0] = Plane{n, dot(n, tri[0])};
    // The deepest vertex: the first of the largest dot product with -n (geometry's
    // support_index over every vertex).
    Vec3 down = scale(n, -1.0);
    unsigned deepest = 0;
    double best = -1.7976931348623157e308;
    for (unsigned v = 0; v < side->vertex_count; ++v) {
        double d = dot(side->points[v], down);
        if (d > best || v == 0) {
            best = d;
            deepest = v;
        }
    }
    double max_depth = -plane_distance(planes[0], side->points[deepest]);
    if (max_depth <= 0.0) {
        return;
    }
    for (unsigned k = 0; k < 3; ++k) {
        Vec3 m = normalize(cross(sub(tri[(k + 1) % 3], tri[k]), n));
        planes[k + 1] = Plane{m, dot(m, tri[k])};
    }
    bool centre_within = true;
    for (unsigned k = 1; k < 4; ++k) {
        centre_within &= plane_distance(planes[k], origin) + circumradius <= 0.0;
    }
    bool vertices_within = true;
    for (unsigned v = 0; v < side->vertex_count && vertices_within; ++v) {
        for (unsigned k = 1; k < 4; ++k) {
            vertices_within &= plane_distance(planes[k], side->points[v]) <= 0.0;
        }
    }
    Vec3 area = origin, moment = origin;
    ConeSums cone;
    cone.volume6 = 0.0;
    cone.moment24 = origin;
    double depth, section;
    if (centre_within || vertices_within) {
        // Within the prism's sides: the part behind the facet plane (wall.rs,
        // overlap_with_half_space), the cones from a point on the plane.
        cone.origin = scale(scale(n, -1.0), plane_distance(planes[0], origin));
        for (unsigned f = 0; f < side->face_count; ++f) {
            if (!face_behind(table, side, f, planes[0])) {
                continue;
            }
            set_face(table, side, f, poly);
            clip_polygon(poly, planes[0]);
            if (poly->len >= 3) {
                area = add(area, polygon_vector_area(polygon_points(poly), poly->len));
                moment = add(moment, polygon_area_moment(polygon_points(poly), poly->len));
                cone_add_polygon(&cone, polygon_points(poly), poly->len);
            }
        }
        depth = max_depth;
        section = norm(area);
    } else {
        double reach = max_depth * (1.0 + 1e-6) + 1e-9 * circumradius;
        Vec3 sides = origin, sum = origin;
        double count = 0.0;
        depth = 0.0;
        bool any = false;
        prism_pieces(table, side, tri, planes, reach, poly,
                     [&](bool of_prism, const Vec3* piece, unsigned len) {
                         if (of_prism) {
                             sides = add(sides, polygon_vector_area(piece, len));
                         } else {
                             area = add(area, polygon_vector_area(piece, len));
                             moment = add(moment, polygon_area_moment(piece, len));
                             any = true;
                         }
                         for (unsigned k = 0; k < len; ++k) {
                             sum = add(sum, piece[k]);
                             depth = fmax(depth, -plane_distance(planes[0], piece[k]));
                         }
                         count += (double)len;
                     });
        if (!any) {
            return;
        }
        Vec3 mean = divide(sum, count);
        cone.origin = sub(mean, scale(n, plane_distance(planes[0], mean)));
        // The pieces again, in the same order, for the cones from there.
        prism_pieces(table, side, tri, planes, reach, poly,
                     [&](bool, const Vec3* piece, unsigned len) {
                         cone_add_polygon(&cone, piece, len);
                     });
        section = norm(add(area, sides));
    }
    double volume = cone.volume6 / 6.0;
    if (!(volume > 0.0)) {
        return;
    }
    record[0] = volume;
    store3(record + 1, 0, cone_centroid(&cone));
    store3(record + 4, 0, area);
    store3(record + 7, 0, moment);
    record[10] = depth;
    record[11] = section;
    store3(record + 12, 0, n);
}
