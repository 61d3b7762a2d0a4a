// The kick–drift–kick of the owned particles. First the opening kick and drift
// (engine/cpu/motion.rs,
// engine/integrate.rs), one thread per particle: velocity Verlet for translation
// with the forces of the last evaluation, and for rotation a half kick of the
// world-frame angular momentum followed by the torque-free rotation of the implicit
// midpoint rule, whose orientation turns by the Cayley rotation of the midpoint
// angular velocity (closed form for an isotropic body, fixed-point iteration to
// round-off otherwise).
//
// The helpers are vec.cuh's.
//
// Layout, as the host world holds it: per particle 3 doubles of position,
// velocity, angular momentum, force and torque; the orientation as a unit
// quaternion (i, j, k, w); its body type; its role as a byte (contact.cuh's
// roles: nonzero, frozen or a ghost, is not moved here). Per body type: the mass
// and the 3 principal moments of inertia.

// C^T v for the Cayley rotation of w: v turned back by the unit quaternion (1, w)/|.|.
static __device__ __forceinline__ Vec3 cayley_transpose(Vec3 w, Vec3 v) {
    return rotate(conjugate(normalised(Quat{1.0, w.x, w.y, w.z})), v);
}

// 1 / sqrt(s) by its series about 1 where s is within 1e-6 of it, else by the root
// (integrate.rs: a turned unit quaternion's squared norm is 1 + |w|^2).
static __device__ __forceinline__ double reciprocal_root_near_one(double s) {
    double e = s - 1.0;
    if (fabs(e) <= 1e-6) {
        return 1.0 - e * (0.5 - 0.375 * e);
    }
    return 1.0 / sqrt(s);
}

// The torque-free rotation over dt of a body of principal moments `inertia`.
static __device__ void free_rotation(Quat* q, Vec3* l, Vec3 inertia, double dt) {
    if (l->x == 0.0 && l->y == 0.0 && l->z == 0.0) {
        // Without angular momentum the body does not turn (integrate.rs).
        return;
    }
    double most = fmax(inertia.x, fmax(inertia.y, inertia.z));
    double least = fmin(inertia.x, fmin(inertia.y, inertia.z));
    if (most - least <= 1e-12 * most) {
        // L stays; the body turns by the Cayley rotation of h ω / 2: q + (0, w) ⊗ q
        // with the world-frame w = L h / (2 I), normalised.
        Vec3 w = scale(*l, 0.5 * dt / inertia.x);
        Quat turned = qmul(Quat{0.0, w.x, w.y, w.z}, *q);
        turned = Quat{q->w + turned.w, q->x + turned.x, q->y + turned.y, q->z + turned.z};
        double s = reciprocal_root_near_one(qnorm_squared(turned));
        *q = Quat{turned.w * s, turned.x * s, turned.y * s, turned.z * s};
        return;
    }
    Vec3 l0 = rotate(conjugate(*q), *l);
    Vec3 inverse = Vec3{1.0 / inertia.x, 1.0 / inertia.y, 1.0 / inertia.z};
    double size = fmax(norm(l0), 2.2250738585072014e-308);
    Vec3 l1 = l0;
    for (int k = 0; k < 64; ++k) {
        Vec3 w = scale(mul(scale(add(l0, l1), 0.5), inverse), 0.5 * dt);
        Vec3 next = cayley_transpose(w, l0);
        double change = norm(sub(next, l1));
        l1 = next;
        if (change <= 1e-15 * size) {
            break;
        }
    }
    Vec3 w = scale(mul(scale(add(l0, l1), 0.5), inverse), 0.5 * dt);
    l1 = cayley_transpose(w, l0);
    *q = normalised(qmul(*q, normalised(Quat{1.0, w.x, w.y, w.z})));
    *l = rotate(*q, l1);
}

extern "C" __global__ void kick_drift(
    unsigned n, double dt, double* position, double* velocity, double* orientation,
    double* angular_momentum, const double* force, const double* torque,
    const unsigned* body_type, const unsigned char* role, const double* mass,
    const double* inertia) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n || role[i]) {
        return;
    }
    unsigned kind = body_type[i];
    Vec3 v = add(load3(velocity, i), scale(load3(force, i), 0.5 * dt / mass[kind]));
    store3(velocity, i, v);
    store3(position, i, add(load3(position, i), scale(v, dt)));
    Quat q = load_orientation(orientation, i);
    Vec3 l = add(load3(angular_momentum, i), scale(load3(torque, i), 0.5 * dt));
    free_rotation(&q, &l, load3(inertia, kind), dt);
    orientation[4 * i] = q.x;
    orientation[4 * i + 1] = q.y;
    orientation[4 * i + 2] = q.z;
    orientation[4 * i + 3] = q.w;
    store3(angular_momentum, i, l);
}

// The closing half kick with the forces just evaluated (engine/cpu/motion.rs), one
// thread per particle: the CPU backend's operations in its order, so the same bits.
extern "C" __global__ void closing_kick(
    unsigned n, double dt, double* velocity, double* angular_momentum,
    const double* force, const double* torque, const unsigned* body_type,
    const unsigned char* role, const double* mass) {
    unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n || role[i]) {
        return;
    }
    Vec3 v = add(load3(velocity, i), scale(load3(force, i), 0.5 * dt / mass[body_type[i]]));
    store3(velocity, i, v);
    store3(angular_momentum, i,
           add(load3(angular_momentum, i), scale(load3(torque, i), 0.5 * dt)));
}
