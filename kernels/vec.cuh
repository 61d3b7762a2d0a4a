// Vectors and quaternions of doubles for the kernels, with nalgebra's operations in
// nalgebra's order (a dot product is (x x' + y y') + z z', a quaternion's norm
// (x² + z²) + (y² + w²), a normalisation divides by the norm), so that a kernel
// that performs the CPU backend's operations gives its bits. Every kernel file is
// compiled after this one (engine/cuda/nvrtc.rs prepends it; host.cpp includes it
// first).

struct Vec3 {
    double x, y, z;
};

// A quaternion w + x i + y j + z k.
struct Quat {
    double w, x, y, z;
};

static __device__ __forceinline__ Vec3 load3(const double* a, unsigned i) {
    return Vec3{a[3 * i], a[3 * i + 1], a[3 * i + 2]};
}

static __device__ __forceinline__ void store3(double* a, unsigned i, Vec3 v) {
    a[3 * i] = v.x;
    a[3 * i + 1] = v.y;
    a[3 * i + 2] = v.z;
}

static __device__ __forceinline__ Vec3 add(Vec3 a, Vec3 b) {
    return Vec3{a.x + b.x, a.y + b.y, a.z + b.z};
}

static __device__ __forceinline__ Vec3 sub(Vec3 a, Vec3 b) {
    return Vec3{a.x - b.x, a.y - b.y, a.z - b.z};
}

static __device__ __forceinline__ Vec3 scale(Vec3 a, double s) {
    return Vec3{a.x * s, a.y * s, a.z * s};
}

// a / s: each component divided (nalgebra's division by a scalar).
static __device__ __forceinline__ Vec3 divide(Vec3 a, double s) {
    return Vec3{a.x / s, a.y / s, a.z / s};
}

// Component by component a / b (nalgebra's component_div).
static __device__ __forceinline__ Vec3 div3(Vec3 a, Vec3 b) {
    return Vec3{a.x / b.x, a.y / b.y, a.z / b.z};
}

static __device__ __forceinline__ Vec3 mul(Vec3 a, Vec3 b) {
    return Vec3{a.x * b.x, a.y * b.y, a.z * b.z};
}

static __device__ __forceinline__ Vec3 cross(Vec3 a, Vec3 b) {
    return Vec3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

static __device__ __forceinline__ double dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

static __device__ __forceinline__ double norm_squared(Vec3 a) {
    return dot(a, a);
}

static __device__ __forceinline__ double norm(Vec3 a) {
    return sqrt(norm_squared(a));
}

// v / |v| (nalgebra's normalize).
static __device__ __forceinline__ Vec3 normalize(Vec3 v) {
    return divide(v, norm(v));
}

// Quaternion i of an array stored as nalgebra stores it: i, j, k, w.
static __device__ __forceinline__ Quat load_orientation(const double* o, unsigned i) {
    return Quat{o[4 * i + 3], o[4 * i], o[4 * i + 1], o[4 * i + 2]};
}

static __device__ __forceinline__ Quat qmul(Quat a, Quat b) {
    return Quat{
        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
        a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
    };
}

static __device__ __forceinline__ double qnorm_squared(Quat q) {
    return (q.x * q.x + q.z * q.z) + (q.y * q.y + q.w * q.w);
}

static __device__ __forceinline__ double qnorm(Quat q) {
    return sqrt(qnorm_squared(q));
}

// q / |q| (nalgebra's `new_normalize`).
static __device__ __forceinline__ Quat normalised(Quat q) {
    double n = qnorm(q);
    return Quat{q.w / n, q.x / n, q.y / n, q.z / n};
}

// v turned by the unit quaternion q: w t + u × t + v with t = 2 u × v, u = (x, y, z).
static __device__ __forceinline__ Vec3 rotate(Quat q, Vec3 v) {
    Vec3 u = Vec3{q.x, q.y, q.z};
    Vec3 t = scale(cross(u, v), 2.0);
    return add(add(scale(t, q.w), cross(u, t)), v);
}

static __device__ __forceinline__ Quat conjugate(Quat q) {
    return Quat{q.w, -q.x, -q.y, -q.z};
}
