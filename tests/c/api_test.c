/* Drives the drum scene through the native C API, checks results and misuse.
 * Usage: api_test DRUM_SCENE. Prints "ok" and exits 0 when every check passes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "talus.h"

#include "check.h"

int main(int argc, char **argv) {
    if (argc < 2) return 2;
    CHECK(talus_create("no/such/scene.toml") == NULL, "missing scene");
    CHECK(strstr(talus_last_error(), "no/such/scene.toml") != NULL, "the error names the file");
    REFUSED(talus_step(NULL, 0.0, 0.01), "null");

    talus_component *c = talus_create(argv[1]);
    CHECK(c != NULL, "create");
    if (!c) return 1;

    size_t walls = 0, drum = 99;
    CHECK(talus_wall_count(c, &walls) == TALUS_OK && walls == 1, "one wall");
    CHECK(talus_wall_index(c, "drum", &drum) == TALUS_OK && drum == 0, "wall index");
    REFUSED(talus_wall_index(c, "lid", &drum), "lid");

    double f[3], m[3], t = -1.0;
    REFUSED(talus_step(c, 0.0, 0.01), "instantiated");
    REFUSED(talus_get_wall_force(c, 0, f, m), "initialisation");
    REFUSED(talus_get_wall_force(c, 5, f, m), "out of range");
    CHECK(talus_initialize(c, 0.0) == TALUS_OK, "initialize");
    REFUSED(talus_initialize(c, 0.0), "step mode");

    double zero[3] = {0, 0, 0}, spin[3] = {0, 3.0, 0}, bad[3] = {0, NAN, 0};
    REFUSED(talus_set_wall_velocity(c, 0, zero, bad), "not finite");
    REFUSED(talus_set_wall_pose(c, 0, zero, zero), "not driven from outside by pose");
    CHECK(talus_set_wall_velocity(c, 0, zero, spin) == TALUS_OK, "set velocity");
    REFUSED(talus_step(c, 0.0, 0.0), "positive");
    REFUSED(talus_step(c, 0.0, -0.01), "positive");
    REFUSED(talus_step(c, 0.0, INFINITY), "positive");
    REFUSED(talus_step(c, 0.5, 0.01), "starts at");

    double now = 0.0;
    for (int k = 0; k < 20; ++k) {
        CHECK(talus_step(c, now, 0.01) == TALUS_OK, "step");
        now += 0.01;
    }
    CHECK(talus_time(c, &t) == TALUS_OK && t == now, "time lands on the communication point");
    CHECK(talus_get_wall_force(c, 0, f, m) == TALUS_OK, "mean force");
    CHECK(f[2] < 0.0, "the beads rest on the drum: their force on it points down");

    /* The per-facet forces add up to the wall's force at the end of the step. */
    size_t nv = 0, nt = 0;
    CHECK(talus_get_wall_mesh_size(c, 0, &nv, &nt) == TALUS_OK && nv > 0 && nt > 0, "mesh size");
    double *vertices = malloc(3 * nv * sizeof(double));
    uint32_t *triangles = malloc(3 * nt * sizeof(uint32_t));
    double *facet = malloc(3 * nt * sizeof(double));
    CHECK(talus_get_wall_mesh(c, 0, vertices, nv, triangles, nt) == TALUS_OK, "mesh");
    REFUSED(talus_get_wall_mesh(c, 0, vertices, nv + 1, triangles, nt), "vertices");
    int in_range = 1;
    for (size_t k = 0; k < 3 * nt; ++k) in_range &= triangles[k] < nv;
    CHECK(in_range, "triangle indices address the vertices");
    CHECK(talus_get_facet_forces(c, 0, facet, nt) == TALUS_OK, "facet forces");
    double fe[3], me[3], sum[3] = {0, 0, 0};
    CHECK(talus_get_wall_force_end(c, 0, fe, me) == TALUS_OK, "end force");
    for (size_t k = 0; k < nt; ++k)
        for (int d = 0; d < 3; ++d) sum[d] += facet[3 * k + d];
    for (int d = 0; d < 3; ++d)
        CHECK(fabs(sum[d] - fe[d]) <= 1e-9 * (fabs(fe[2]) + 1e-12), "facet forces add up");

    /* Rollback: save, step, restore, step: identical torque. */
    const uint8_t *bytes = NULL;
    size_t size = 0;
    CHECK(talus_save_state(c, &bytes, &size) == TALUS_OK && size > 0, "save");
    uint8_t *copy = malloc(size);
    memcpy(copy, bytes, size);
    double first[3], second[3];
    CHECK(talus_step(c, now, 0.02) == TALUS_OK, "step after save");
    CHECK(talus_get_wall_force(c, 0, f, first) == TALUS_OK, "torque");
    CHECK(talus_restore_state(c, copy, size) == TALUS_OK, "restore");
    CHECK(talus_time(c, &t) == TALUS_OK && t == now, "time restored");
    CHECK(talus_step(c, now, 0.02) == TALUS_OK, "step again");
    CHECK(talus_get_wall_force(c, 0, f, second) == TALUS_OK, "torque again");
    CHECK(memcmp(first, second, sizeof first) == 0, "identical after rollback");
    uint8_t garbage[64];
    memset(garbage, 7, sizeof garbage);
    REFUSED(talus_restore_state(c, garbage, sizeof garbage), "not a talus state");
    REFUSED(talus_restore_state(c, copy, size / 2), "damaged");

    double ke = -1.0;
    CHECK(talus_get_real(c, "kinetic_energy", &ke, 1) == TALUS_OK && ke > 0.0, "kinetic energy");
    REFUSED(talus_get_real(c, "drum.torque", m, 1), "3 values");
    REFUSED(talus_set_real(c, "drum.torque", m, 3), "cannot be set");
    CHECK(talus_terminate(c) == TALUS_OK, "terminate");
    REFUSED(talus_step(c, now, 0.01), "terminated");

    free(vertices);
    free(triangles);
    free(facet);
    free(copy);
    talus_free(c);
    talus_free(NULL);
    if (failures) {
        fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}
