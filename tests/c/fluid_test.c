/* Drives the coupled fluid of a scene through the native C API: the grid, per-cell
 * inputs set by pointer and length, outputs read back, misuse refused.
 * Usage: fluid_test SCENE. Prints the outputs after two steps as
 * "source SX SY SZ solid S" (%.17g) and "ok", and exits 0 when every check passes. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "talus.h"

#include "check.h"

/* The swirl of tests/cosim_fluid.rs: a velocity differing from cell to cell. */
static void swirl(double *u, size_t cells, double phase) {
    for (size_t c = 0; c < cells; ++c) {
        double x = (double)c;
        u[3 * c] = 0.3 * sin(x + phase);
        u[3 * c + 1] = -0.2 * cos(0.5 * x);
        u[3 * c + 2] = 2.0 + 0.05 * x + phase;
    }
}

int main(int argc, char **argv) {
    if (argc < 2) return 2;
    talus_component *c = talus_create(argv[1]);
    CHECK(c != NULL, "create");
    if (!c) return 1;

    double origin[3], cell[3];
    size_t counts[3];
    CHECK(talus_get_fluid_grid(c, origin, cell, counts) == TALUS_OK, "grid");
    CHECK(counts[0] == 3 && counts[1] == 3 && counts[2] == 6, "3 x 3 x 6 cells");
    CHECK(cell[2] == 0.01 && origin[0] == 0.0, "cell size and origin");
    CHECK(talus_get_fluid_grid(c, origin, NULL, counts) == TALUS_ERROR, "null cell refused");
    size_t cells = counts[0] * counts[1] * counts[2];
    /* Every kind of cells: centres and volumes. */
    size_t n = 0;
    CHECK(talus_get_fluid_cell_count(c, &n) == TALUS_OK && n == cells, "cell count");
    double centres[3 * 54], volumes[54];
    CHECK(n == 54, "54 cells");
    CHECK(talus_get_fluid_cells(c, n - 1, centres, volumes) == TALUS_ERROR, "wrong n refused");
    CHECK(talus_get_fluid_cells(c, n, centres, NULL) == TALUS_ERROR, "null volumes refused");
    CHECK(talus_get_fluid_cells(c, n, centres, volumes) == TALUS_OK, "cells");
    /* Cell [1, 2, 3] (x fastest): centre (0.015, 0.025, 0.035), volume 1 cm3. */
    size_t k = 1 + 3 * (2 + 3 * 3);
    CHECK(fabs(centres[3 * k] - 0.015) < 1e-15 && fabs(centres[3 * k + 1] - 0.025) < 1e-15 &&
              fabs(centres[3 * k + 2] - 0.035) < 1e-15,
          "a cell's centre");
    CHECK(fabs(volumes[k] - 1e-6) < 1e-20, "a cell's volume");

    double *u = malloc(3 * cells * sizeof(double));
    double *before = malloc(3 * cells * sizeof(double));
    double *source = malloc(3 * cells * sizeof(double));
    double *solid = malloc(cells * sizeof(double));
    double h = 13 * 2e-5;

    swirl(u, cells, 0.0);
    CHECK(talus_set_real(c, "fluid.velocity", u, 3 * cells) == TALUS_OK, "set before init");
    CHECK(talus_initialize(c, 0.0) == TALUS_OK, "initialize");

    /* Misuse: a wrong length, a NaN; the inputs stay as they were. */
    CHECK(talus_get_real(c, "fluid.velocity", before, 3 * cells) == TALUS_OK, "read inputs");
    CHECK(talus_set_real(c, "fluid.velocity", u, 10) == TALUS_ERROR, "wrong length refused");
    CHECK(strstr(talus_last_error(), "162") != NULL, "the error gives the size");
    u[7] = NAN;
    CHECK(talus_set_real(c, "fluid.velocity", u, 3 * cells) == TALUS_ERROR, "NaN refused");
    swirl(u, cells, 0.0);
    CHECK(talus_set_real(c, "fluid.solid_fraction", solid, cells) == TALUS_ERROR,
          "an output cannot be set");
    CHECK(talus_get_real(c, "fluid.velocity", source, 3 * cells) == TALUS_OK, "read again");
    CHECK(memcmp(source, before, 3 * cells * sizeof(double)) == 0, "inputs unchanged");
    CHECK(talus_get_fluid_grid(NULL, origin, cell, counts) == TALUS_ERROR, "null handle");

    for (int k = 0; k < 2; ++k) {
        swirl(u, cells, 0.7 * k);
        CHECK(talus_set_real(c, "fluid.velocity", u, 3 * cells) == TALUS_OK, "set velocity");
        CHECK(talus_step(c, k * h, h) == TALUS_OK, "step");
    }
    CHECK(talus_get_real(c, "fluid.momentum_source", source, 3 * cells) == TALUS_OK, "source");
    CHECK(talus_get_real(c, "fluid.solid_fraction", solid, cells) == TALUS_OK, "solid");
    double s[3] = {0, 0, 0}, phi = 0;
    for (size_t i = 0; i < cells; ++i) {
        for (int d = 0; d < 3; ++d) s[d] += source[3 * i + d];
        phi += solid[i];
    }
    printf("source %.17g %.17g %.17g solid %.17g\n", s[0], s[1], s[2], phi);
    CHECK(s[2] < 0.0, "the particles take momentum from the gas");

    /* Per particle: ids, drag, slip, voidage; sums printed for the Rust side. */
    size_t np = 0;
    CHECK(talus_get_particle_count(c, &np) == TALUS_OK && np > 0, "particle count");
    uint64_t *ids = malloc(np * sizeof(uint64_t));
    double *drag = malloc(3 * np * sizeof(double)), *slip = malloc(3 * np * sizeof(double));
    double *voidage = malloc(np * sizeof(double));
    CHECK(talus_get_particle_fluid(c, np + 1, ids, drag, slip, voidage) == TALUS_ERROR,
          "wrong n refused");
    CHECK(talus_get_particle_fluid(c, np, ids, NULL, slip, voidage) == TALUS_ERROR,
          "null drag refused");
    CHECK(talus_get_particle_fluid(c, np, ids, drag, slip, voidage) == TALUS_OK, "particles");
    double d = 0, e = 0, w = 0;
    uint64_t id_sum = 0;
    for (size_t i = 0; i < np; ++i) {
        d += drag[3 * i + 2];
        w += slip[3 * i + 2];
        e += voidage[i];
        id_sum += ids[i];
    }
    printf("particles %zu drag %.17g slip %.17g voidage %.17g ids %llu\n", np, d, w, e,
           (unsigned long long)id_sum);
    free(ids);
    free(drag);
    free(slip);
    free(voidage);

    talus_free(c);
    free(u);
    free(before);
    free(source);
    free(solid);
    if (failures == 0) printf("ok\n");
    return failures == 0 ? 0 : 1;
}
