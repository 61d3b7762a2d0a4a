// The volume-based contact law of polyhedra (engine/cpu/forces.rs contact_force,
// contact/normal.rs, contact/damping.rs, contact/area.rs): Feng's normal force
// along the area vector from the overlap volume's potential, regularised below
// V₀, with damping calibrated to the restitution coefficient; Cundall–Strack
// friction (contact.cuh); rocking damping and twisting friction. The CPU backend's
// operations in its order. Compiled after vec.cuh and contact.cuh.

// Nodes of a damping table over the force exponent p in [1/3, 5].
#define DAMPING_NODES 21u
#define DAMPING_P_MIN (1.0 / 3.0)
#define DAMPING_P_MAX 5.0
#define PI_DOUBLE 3.141592653589793
// A body type's law row: normal and tangential stiffness factors (E/R, G/R), the
// regularisation volume V₀ and its cube root, the inverse smallest principal
// moment, the volume-equivalent radius R, the smallest principal moment.
#define TYPE_LAW_DOUBLES 7u
// A pair of materials' law row: friction coefficient, restitution, damping nodes,
// the moduli in series of a particle against a wall, normal and tangential
// (engine/laws.rs, ContactLaws::wall).
#define MATERIAL_LAW_DOUBLES (4u + DAMPING_NODES)
// A contact's history under the volume law: the friction spring, its stiffness,
// the twist; with a rolling spring after them (Hertz–Mindlin's rolling resistance
// beside the volume law).
#define VOLUME_HISTORY_DOUBLES 5u
#define ROLLING_HISTORY_DOUBLES 8u

// The damping ratio at exponent p, interpolated in the material pair's nodes
// (contact/damping.rs, DampingTable::zeta).
static __device__ double damping_ratio(const double* material_law, double p) {
    const double* zeta = material_law + 2;
    double clamped = p < DAMPING_P_MIN ? DAMPING_P_MIN : (p > DAMPING_P_MAX ? DAMPING_P_MAX : p);
    double s = ((clamped - DAMPING_P_MIN) / (DAMPING_P_MAX - DAMPING_P_MIN)) *
               (double)(DAMPING_NODES - 1u);
    unsigned k = s >= 0.0 ? (unsigned)floor(s) : 0u;
    if (k > DAMPING_NODES - 2u) {
        k = DAMPING_NODES - 2u;
    }
    double w = s - (double)k;
    return zeta[k] * (1.0 - w) + zeta[k + 1] * w;
}

// Rust's f64::signum: 1 for +0, -1 for -0.
static __device__ __forceinline__ double signum(double x) {
    return copysign(1.0, x);
}

struct NormalForce {
    Vec3 force;
    // The force's size along the normal (>= 0).
    double magnitude;
    double elastic, energy, exponent;
};

// contact/normal.rs, normal_force.
static __device__ NormalForce volume_normal_force(double volume, double area, double depth,
                                                  Vec3 normal, Vec3 relative,
                                                  double effective_mass, double stiffness,
                                                  double v0, double cbrt_v0, double dt,
                                                  const double* material_law) {
    volume = fmax(volume, 0.0);
    bool regular = volume < v0;
    NormalForce n;
    if (regular) {
        double s = cbrt_v0 * cbrt_v0;
        n.elastic = stiffness * area * volume / s;
        n.energy = 0.5 * stiffness * volume * volume / s;
    } else {
        double v13 = cbrt(volume);
        n.elastic = stiffness * area * v13;
        n.energy = 0.75 * stiffness * volume * v13 - 0.25 * stiffness * v0 * cbrt_v0;
    }
    double a = 1.0;
    if (volume > 0.0) {
        a = area * depth / volume;
        a = a < 1.0 ? 1.0 : (a > 3.0 ? 3.0 : a);
    }
    n.exponent = regular ? 2.0 * a - 1.0 : 4.0 * a / 3.0 - 1.0;
    double magnitude = n.elastic;
    if (depth > 0.0 && material_law[1] < 1.0) {
        double tangent_stiffness = n.exponent * n.elastic / depth;
        double coefficient = 2.0 * damping_ratio(material_law, n.exponent) *
                             sqrt(effective_mass * tangent_stiffness);
        double vn = dot(relative, normal);
        double damping_force = coefficient * fabs(vn);
        if (dt > 0.0) {
            damping_force = fmin(damping_force, effective_mass * fabs(vn) / dt);
        }
        magnitude -= damping_force * signum(vn);
    }
    n.magnitude = fmax(magnitude, 0.0);
    n.force = scale(normal, n.magnitude);
    return n;
}

// Damping of the rocking of a flat contact (contact/area.rs, rocking_damping).
static __device__ Vec3 rocking_damping(Vec3 spin, Vec3 normal, double area,
                                       double tangent_stiffness, double inertia, double zeta,
                                       double dt) {
    Vec3 rocking = sub(spin, scale(normal, dot(spin, normal)));
    if (!(area > 0.0 && tangent_stiffness > 0.0 && inertia > 0.0 && zeta > 0.0)) {
        return Vec3{0.0, 0.0, 0.0};
    }
    double second_moment_ratio = area / (4.0 * PI_DOUBLE);
    double stiffness = tangent_stiffness * second_moment_ratio;
    double coefficient = 2.0 * zeta * sqrt(inertia * stiffness);
    if (dt > 0.0) {
        coefficient = fmin(coefficient, inertia / dt);
    }
    return scale(scale(rocking, -1.0), coefficient);
}

// Twisting friction (contact/area.rs, twisting_friction): the torque on body 2, the
// twist kept in *twist.
static __device__ Vec3 twisting_friction(double* twist, Vec3 spin, Vec3 normal, double area,
                                         double tangential_stiffness, double inertia,
                                         double coulomb, double dt) {
    if (!(area > 0.0 && tangential_stiffness > 0.0 && inertia > 0.0 && coulomb > 0.0)) {
        *twist = 0.0;
        return Vec3{0.0, 0.0, 0.0};
    }
    double rate = dot(normal, spin);
    double stiffness = tangential_stiffness * area / (2.0 * PI_DOUBLE);
    double damping = 2.0 * sqrt(inertia * stiffness);
    if (dt > 0.0) {
        damping = fmin(damping, inertia / dt);
    }
    double angle = *twist + rate * dt;
    double trial = -stiffness * angle - damping * rate;
    double cap = coulomb * (2.0 / 3.0) * sqrt(area / PI_DOUBLE);
    double moment = trial;
    if (!(fabs(trial) <= cap)) {
        if (stiffness * fabs(angle) > cap) {
            angle *= cap / (stiffness * fabs(angle));
        }
        moment = cap * signum(trial);
    }
    *twist = angle;
    return scale(normal, moment);
}

// A contact's geometry in world coordinates (engine/cpu/dispatch.rs,
// ContactGeometry), with the rotation gradient of body 2 (`has_gradient`).
struct VolumeGeometry {
    double volume, area, depth;
    Vec3 normal, point, rotation_gradient;
    bool has_gradient;
};

// How the bodies move against each other at the contact point
// (engine/cpu/relative_motion.rs).
struct VolumeMotion {
    Vec3 velocity, spin;
    double inverse_mass, inertia;
};

// What a volume-law contact puts on body 2: force, torque about its centroid, the
// history to keep, the elastic energy held and the energy dissipated.
struct VolumeContact {
    Vec3 force, torque;
    Spring kept;
    double twist;
    double energy, dissipated;
};

// engine/cpu/forces.rs, contact_force: body 2's centroid at `centre`, the pair's
// stiffness factors, regularisation, friction and damping (material_law).
static __device__ VolumeContact volume_contact(const VolumeGeometry& g, const VolumeMotion& m,
                                               double normal_stiffness,
                                               double tangential_stiffness, double v0,
                                               double cbrt_v0, const double* material_law,
                                               Spring before, double twist_before, double dt,
                                               Vec3 centre) {
    double friction = material_law[0];
    double effective_mass = 1.0 / m.inverse_mass;
    NormalForce n = volume_normal_force(g.volume, g.area, g.depth, g.normal, m.velocity,
                                        effective_mass, normal_stiffness, v0, cbrt_v0, dt,
                                        material_law);
    double kt = tangential_stiffness * g.area;
    double zeta1 = damping_ratio(material_law, 1.0);
    double ct = 2.0 * zeta1 * sqrt(effective_mass * kt);
    VolumeContact c;
    double limit = friction * norm(n.force);
    bool sliding;
    Vec3 t = tangential_force(before, g.normal, m.velocity, dt, kt, ct, limit, &c.kept,
                              &sliding);
    Vec3 force = add(n.force, t);
    Vec3 rocking = Vec3{0.0, 0.0, 0.0};
    if (g.depth > 0.0) {
        rocking = rocking_damping(m.spin, g.normal, g.area, n.exponent * n.elastic / g.depth,
                                  m.inertia, zeta1, dt);
    }
    c.twist = twist_before;
    Vec3 twisting = twisting_friction(&c.twist, m.spin, g.normal, g.area, kt, m.inertia, limit,
                                      dt);
    Vec3 lever = sub(g.point, centre);
    Vec3 moment;
    if (g.has_gradient && g.area > 0.0) {
        // The elastic part from the potential (U' = elastic / area); damping and
        // friction act at the contact point.
        Vec3 elastic = scale(g.normal, n.elastic);
        moment = add(scale(g.rotation_gradient, -(n.elastic / g.area)),
                     cross(lever, sub(force, elastic)));
    } else {
        moment = cross(lever, force);
    }
    Vec3 damping_torque = add(rocking, twisting);
    c.force = force;
    c.torque = add(damping_torque, moment);
    c.energy = n.energy + spring_energy(c.kept);
    c.dissipated = contact_dissipation(sub(force, scale(g.normal, n.elastic)),
                                       dissipation_ahead(n.magnitude, n.elastic, t, sliding),
                                       damping_torque, m.velocity, m.spin, m.inverse_mass,
                                       before, c.kept, dt);
    return c;
}
