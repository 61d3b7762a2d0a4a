// The geometry of a sphere's contacts (geometry/sphere.rs): with a sphere, a lens
// (`sphere_sphere`); with a convex polyhedron (`sphere_polyhedron`), where the
// centre lies outside, the nearest point of the faces that face it (each face a
// fan of triangles, closest_on_triangle), where it lies inside, the way out
// through the nearest face. The CPU finds the nearest point by GJK; the two agree
// to round-off. Compiled after vec.cuh, contact.cuh, triangle.cuh and overlap.cuh.

// A round contact's geometry: depth, unit normal (from body 1 to body 2: from the
// polyhedron to the sphere), the point midway into the overlap (relative to body
// 1's centre for two spheres), the overlap's volume and the area of its section.
struct CapContact {
    double depth;
    Vec3 normal, point;
    double volume, area;
};

// Sphere 2 of radius r2 at `c2` from sphere 1 of radius r1: false where apart.
static __device__ bool sphere_sphere(double r1, double r2, Vec3 c2, CapContact* out) {
    const double pi = 3.14159265358979323846;
    double d = norm(c2);
    double depth = r1 + r2 - d;
    if (depth <= 0.0) {
        return false;
    }
    Vec3 normal = d > 0.0 ? divide(c2, d) : Vec3{1.0, 0.0, 0.0};
    if (d <= fabs(r1 - r2)) {
        // One sphere inside the other.
        double r = fmin(r1, r2);
        out->volume = 4.0 / 3.0 * pi * (r * r * r);
        out->area = pi * r * r;
    } else {
        // A lens; the contact circle lies at distance x from centre 1.
        double x = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
        out->volume = cap_volume(r1, r1 - x) + cap_volume(r2, r2 - (d - x));
        out->area = pi * fmax(r1 * r1 - x * x, 0.0);
    }
    out->depth = depth;
    out->normal = normal;
    out->point = scale(normal, r1 - 0.5 * depth);
    return true;
}

// Shape `shape` (its body frame) against the sphere of radius `r` centred at `c`
// (in that frame): false where they do not touch.
static __device__ bool sphere_polyhedron(const ShapeTable& table, unsigned shape, Vec3 c, double r,
                                         CapContact* out) {
    if (!(norm(c) < table.circumradius[shape] + r)) {
        return false;
    }
    const unsigned* index = table.index + 4 * shape;
    unsigned first_vertex = index[0], first_face = index[2], faces = index[3];
    // The face plane farthest below the centre (the last of equals, as Rust's
    // max_by).
    double farthest = -1.7976931348623157e308;
    unsigned out_face = 0;
    for (unsigned f = 0; f < faces; ++f) {
        const double* p = table.planes + 4 * (first_face + f);
        double d = plane_distance(Plane{Vec3{p[0], p[1], p[2]}, p[3]}, c);
        if (d >= farthest) {
            farthest = d;
            out_face = f;
        }
    }
    Vec3 closest, normal;
    double depth;
    if (farthest <= 0.0) {
        // The centre is inside: leave through the nearest face.
        const double* p = table.planes + 4 * (first_face + out_face);
        normal = Vec3{p[0], p[1], p[2]};
        closest = sub(c, scale(normal, farthest));
        depth = r - farthest;
    } else {
        double least = 1.7976931348623157e308;
        for (unsigned f = 0; f < faces; ++f) {
            const double* p = table.planes + 4 * (first_face + f);
            if (!(plane_distance(Plane{Vec3{p[0], p[1], p[2]}, p[3]}, c) > 0.0)) {
                continue;
            }
            const unsigned* span = table.face_span + 2 * (first_face + f);
            const unsigned* loop = table.loops + span[0];
            Vec3 a = load3(table.vertices, first_vertex + loop[0]);
            for (unsigned k = 1; k + 1 < span[1]; ++k) {
                Vec3 b = load3(table.vertices, first_vertex + loop[k]);
                Vec3 e = load3(table.vertices, first_vertex + loop[k + 1]);
                Vec3 q = closest_on_triangle(a, b, e, c);
                double squared = norm_squared(sub(c, q));
                if (squared < least) {
                    least = squared;
                    closest = q;
                }
            }
        }
        double distance = sqrt(least);
        if (!(distance < r)) {
            return false;
        }
        normal = divide(sub(c, closest), distance);
        depth = r - distance;
    }
    out->depth = depth;
    out->normal = normal;
    out->point = sub(closest, scale(normal, 0.5 * depth));
    out->volume = cap_volume(r, depth);
    out->area = cap_area(r, depth);
    return true;
}
