/*
 * talus: the native C API.
 *
 * A scene file becomes a component that C code steps, drives and reads:
 *
 *     talus_component *c = talus_create("drum.toml");
 *     if (!c) { fprintf(stderr, "%s\n", talus_last_error()); return 1; }
 *     size_t drum; talus_wall_index(c, "drum", &drum);
 *     talus_initialize(c, 0.0);
 *     double v[3] = {0, 0, 0}, w[3] = {0, 3.0, 0}, f[3], m[3];
 *     talus_set_wall_velocity(c, drum, v, w);
 *     for (int k = 0; k < 100; ++k) {
 *         talus_step(c, 0.01 * k, 0.01);
 *         talus_get_wall_force(c, drum, f, m);
 *     }
 *     talus_free(c);
 *
 * Every function but talus_create, talus_free, talus_last_error and talus_version
 * returns TALUS_OK (0) or TALUS_ERROR (1). After an error, talus_last_error() gives
 * the message (per thread, valid until the next error on that thread). A refused
 * call leaves the component unchanged; an internal failure leaves it in the error
 * state. Wall forces are those the particles exert on the wall; torques are about
 * the wall's reference point. SI units throughout.
 */
#ifndef TALUS_H
#define TALUS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TALUS_OK 0
#define TALUS_ERROR 1

typedef struct TalusComponent talus_component;

/* Message of the last failed call on this thread ("" if none). */
const char *talus_last_error(void);
/* The library version, e.g. "0.1.0". */
const char *talus_version(void);

/* Loads a scene (TOML); NULL on failure. */
talus_component *talus_create(const char *scene_path);
/* Frees a component; its worker threads have exited when this returns. */
void talus_free(talus_component *c);

/* Life cycle: initialise at start_time, step from t (the current time) by h,
 * terminate (writes the last output when an output directory is set). */
int talus_initialize(talus_component *c, double start_time);
int talus_step(talus_component *c, double t, double h);
int talus_terminate(talus_component *c);
int talus_time(talus_component *c, double *time);
/* Warnings at the current parameters (a time step above the suggested one), one per
 * line, "" when none; *text lives until the next call on c. */
int talus_warnings(talus_component *c, const char **text);

/* Walls by index. */
int talus_wall_count(talus_component *c, size_t *count);
int talus_wall_index(talus_component *c, const char *name, size_t *index);

/* Inputs of walls driven from outside, held over the following steps:
 * velocity[3], angular_velocity[3] about the reference point; or the pose to reach
 * at the end of the next step, position[3] and orientation[4] = (w, x, y, z). */
int talus_set_wall_velocity(talus_component *c, size_t wall, const double *velocity,
                            const double *angular_velocity);
int talus_set_wall_pose(talus_component *c, size_t wall, const double *position,
                        const double *orientation);

/* Force[3] and torque[3] on a wall: the mean over the last step (impulse / step),
 * and the value at the end of the step. */
int talus_get_wall_force(talus_component *c, size_t wall, double *force, double *torque);
int talus_get_wall_force_end(talus_component *c, size_t wall, double *force, double *torque);

/* A wall's mesh as placed now: vertices[3 n_vertices], triangles[3 n_triangles];
 * the force on each facet at the end of the last step: forces[3 n_triangles]. */
int talus_get_wall_mesh_size(talus_component *c, size_t wall, size_t *n_vertices,
                             size_t *n_triangles);
int talus_get_wall_mesh(talus_component *c, size_t wall, double *vertices, size_t n_vertices,
                        uint32_t *triangles, size_t n_triangles);
int talus_get_facet_forces(talus_component *c, size_t wall, double *forces, size_t n_triangles);

/* Any real variable of the component by name ("drum.torque", "kinetic_energy" ...),
 * all n of its values. */
int talus_get_real(talus_component *c, const char *name, double *values, size_t n);
int talus_set_real(talus_component *c, const char *name, const double *values, size_t n);

/* The whole state as bytes (owned by the component, valid until the next save or
 * talus_free), and back: restoring and stepping again gives identical results. */
int talus_save_state(talus_component *c, const uint8_t **bytes, size_t *size);
int talus_restore_state(talus_component *c, const uint8_t *bytes, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* TALUS_H */
