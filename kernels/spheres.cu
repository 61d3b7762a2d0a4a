// The Hertz–Mindlin contacts of a world of spheres (engine/cpu/hertz.rs,
// contact/hertz_mindlin.rs, contact/tangential.rs, engine/cpu/forces.rs) and the
// gather of every particle's forces (engine/cpu/pairs.rs): the CPU backend's
// operations in its order, so the same bits.
//
// The law is contact.cuh's. Layouts: per body type its Hertz–Mindlin table
// (contact.cuh, HertzTable); per pair its tangential history (spring, 3 doubles,
// and the stiffness it was stretched at) and its result (force on the second particle, torque on the first and on the
// second: 9 doubles), its energy terms (elastic energy, energy dissipated: apart
// from the results, so that their sums read them in a row; zero where this world
// does not count the pair) and its byte (contact.cuh: touches, counted). Per
// particle its role (contact.cuh: frozen, ghost).

// One thread per candidate pair: its contact without rolling resistance, if the
// spheres overlap and one of them moves here (is neither frozen nor a ghost), into
// its result; its history replaced by what the contact leaves (none when apart).
extern "C" __global__ void sphere_contacts(
    unsigned pair_count, double dt, const unsigned* pairs, const double* position,
    const double* velocity, const double* angular_momentum, const unsigned* body_type,
    const unsigned char* role, const double* type_radius, const double* type_inverse_mass,
    const double* type_inverse_inertia, const double* type_rolling_inertia,
    const unsigned* type_material, unsigned materials, const double* material_pairs,
    double* history, double* results, double* energies, unsigned char* touching) {
    unsigned e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= pair_count) {
        return;
    }
    HertzTable table = HertzTable{type_radius,         type_inverse_mass,
                                  type_inverse_inertia, type_rolling_inertia,
                                  type_material,        materials,
                                  material_pairs};
    unsigned i = pairs[2 * e], j = pairs[2 * e + 1];
    bool counted = counts_pair(role[i], role[j]);
    Spring before = Spring{load3(history + HISTORY_DOUBLES * e, 0),
                           history[HISTORY_DOUBLES * e + 3]};
    double* result = results + RESULT_DOUBLES * e;
    double* energy = energies + PAIR_ENERGY_DOUBLES * e;
    Vec3 xi = load3(position, i), xj = load3(position, j);
    RoundContact c;
    bool contact = !(role[i] && role[j]) &&
                   sphere_pair(table, body_type[i], body_type[j], xi, xj, load3(velocity, i),
                               load3(velocity, j), load3(angular_momentum, i),
                               load3(angular_momentum, j), before, ROLLING_NONE,
                               Vec3{0.0, 0.0, 0.0}, dt, &c);
    if (!contact) {
        store_apart(result, energy, touching + e, counted, before);
        bool held = before.spring.x != 0.0 || before.spring.y != 0.0 || before.spring.z != 0.0;
        for (unsigned k = 0; held && k < HISTORY_DOUBLES; ++k) {
            history[HISTORY_DOUBLES * e + k] = 0.0;
        }
        return;
    }
    store_contact(result, energy, touching + e, counted, xi, xj, c.force, c.torque, c.energy,
                  c.dissipated);
    history[HISTORY_DOUBLES * e] = c.kept.spring.x;
    history[HISTORY_DOUBLES * e + 1] = c.kept.spring.y;
    history[HISTORY_DOUBLES * e + 2] = c.kept.spring.z;
    history[HISTORY_DOUBLES * e + 3] = c.kept.stiffness;
}

// One thread per particle: its weight plus its pairs' forces in pair order (its
// partners in the order of their ids), and the torques; whether it touches (a
// frozen one does). A ghost gets no force, no torque and does not touch
// (engine/cpu/pairs.rs, StartLoads).
extern "C" __global__ void gather_forces(
    unsigned n, double gx, double gy, double gz, const unsigned* body_type,
    const double* type_mass, const unsigned char* role, const unsigned* incident_starts,
    const unsigned* incident, const double* results, const unsigned char* pair_touching,
    double* force, double* torque, unsigned char* touching) {
    unsigned k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= n) {
        return;
    }
    Vec3 t = Vec3{0.0, 0.0, 0.0};
    if (role[k] & GHOST_ROLE) {
        store3(force, k, t);
        store3(torque, k, t);
        touching[k] = 0;
        return;
    }
    unsigned char touches = role[k] & FROZEN_ROLE;
    Vec3 f = scale(Vec3{gx, gy, gz}, type_mass[body_type[k]]);
    for (unsigned s = incident_starts[k]; s < incident_starts[k + 1]; ++s) {
        unsigned entry = incident[s];
        unsigned e = entry & 0x7fffffffu;
        bool first = (entry & 0x80000000u) != 0;
        const double* c = results + RESULT_DOUBLES * e;
        double sign = first ? -1.0 : 1.0;
        touches |= pair_touching[e] & PAIR_TOUCHES;
        f = add(f, scale(load3(c, 0), sign));
        t = add(t, load3(c, first ? 1 : 2));
    }
    store3(force, k, f);
    store3(torque, k, t);
    touching[k] = touches;
}
