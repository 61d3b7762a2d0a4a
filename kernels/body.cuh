// How a rigid body moves at a contact, as the contact laws read it
// (world/mod.rs World::angular_velocity, engine/cpu/relative_motion.rs
// inverse_mass_at), shared by the spheres' wall contacts (walls.cu) and the
// polyhedra's contacts (polyhedra.cu). Compiled after vec.cuh.

// A body's angular velocity from its angular momentum `l`, principal moments
// `inertia` in the body frame (all equal where `isotropic`: L / I).
static __device__ Vec3 angular_velocity(Quat q, Vec3 l, Vec3 inertia, bool isotropic) {
    if (isotropic) {
        return divide(l, inertia.x);
    }
    return rotate(q, div3(rotate(conjugate(q), l), inertia));
}

// The inverse mass at `point` along `n` of a body of centroid `x`, orientation `q`,
// mass `mass` and principal moments `inertia`.
static __device__ double inverse_mass_at(Quat q, Vec3 x, double mass, Vec3 inertia, Vec3 point,
                                         Vec3 n) {
    Vec3 lever = rotate(conjugate(q), cross(sub(point, x), n));
    return 1.0 / mass + dot(div3(lever, inertia), lever);
}
