//! The native C API (`interfaces/c/talus.h`): a scene as a component, stepped from C.
//!
//! Every function returns `TALUS_OK` (0) or `TALUS_ERROR` (1); the message of the last
//! error on the calling thread is `talus_last_error()`. A refused call leaves the
//! component as it was; a panic inside talus is caught, reported, and leaves the
//! component in the error state (only `talus_free` is then useful). The FMI entry
//! points live in [`crate::fmi`]; both go through [`guard`].

pub mod guard;

use std::cell::RefCell;
use std::ffi::{CString, c_char, c_int};
use std::path::Path;

use guard::{catch, put, slice, slice_mut, text};

use crate::cosim::Component;

/// Success.
pub const TALUS_OK: c_int = 0;
/// Failure: see `talus_last_error`.
pub const TALUS_ERROR: c_int = 1;

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(message: &str) {
    let c = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// An opaque component handle for C.
pub struct TalusComponent {
    component: Component,
    saved: Vec<u8>,
    /// The text `talus_warnings` hands out (kept until the next call).
    warnings: std::ffi::CString,
}

/// Runs `f` on the handle: null checked, panics caught (the component then goes to
/// the error state), errors stored for `talus_last_error`.
fn with(
    handle: *mut TalusComponent,
    f: impl FnOnce(&mut TalusComponent) -> Result<(), String>,
) -> c_int {
    if handle.is_null() {
        set_error("the component is a null pointer");
        return TALUS_ERROR;
    }
    // SAFETY: a non-null handle comes from `talus_create` and is not yet freed.
    let h = unsafe { &mut *handle };
    let result = catch(|| f(h));
    match result {
        Ok(()) => TALUS_OK,
        Err(message) => {
            if message.starts_with("internal error") {
                h.component.fail();
            }
            set_error(&message);
            TALUS_ERROR
        }
    }
}

fn wall_name(c: &Component, wall: usize) -> Result<String, String> {
    c.scene()
        .world
        .walls
        .get(wall)
        .map(|w| w.name.clone())
        .ok_or_else(|| {
            format!(
                "wall index {wall} out of range (the scene has {})",
                c.scene().world.walls.len()
            )
        })
}

fn var(c: &Component, name: &str) -> Result<usize, String> {
    c.variable(name).map_err(|e| e.to_string())
}

/// Sets the two input variables `wall.suffix` of a wall driven by `kind`, all or
/// none. Shared with the Python module, whose calls are these.
pub fn set_wall_inputs(
    c: &mut Component,
    wall: usize,
    inputs: [(&str, &[f64]); 2],
    kind: &str,
) -> Result<(), String> {
    let name = wall_name(c, wall)?;
    let mut refs = Vec::new();
    let mut values = Vec::new();
    for (suffix, x) in inputs {
        let var = var(c, &format!("{name}.{suffix}"))
            .map_err(|_| format!("wall '{name}' is not driven from outside by {kind}"))?;
        for (element, value) in x.iter().enumerate() {
            refs.push(crate::cosim::VarRef { var, element });
            values.push(*value);
        }
    }
    c.set_real(&refs, &values).map_err(|e| e.to_string())
}

/// The message of the last failed call on this thread ("" if none). Valid until the
/// next failing call on the thread.
#[unsafe(no_mangle)]
pub extern "C" fn talus_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// The talus version.
#[unsafe(no_mangle)]
pub extern "C" fn talus_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Loads a scene file; null on failure.
///
/// # Safety
/// `scene_path` is a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_create(scene_path: *const c_char) -> *mut TalusComponent {
    let r = catch(|| {
        let path = unsafe { text(scene_path, "scene_path") }?;
        Component::instantiate(Path::new(""), path).map_err(|e| e.to_string())
    });
    match r {
        Ok(component) => Box::into_raw(Box::new(TalusComponent {
            component,
            saved: Vec::new(),
            warnings: std::ffi::CString::default(),
        })),
        Err(message) => {
            set_error(&message);
            std::ptr::null_mut()
        }
    }
}

/// Frees a component (null is ignored); its worker threads have exited on return.
///
/// # Safety
/// `handle` comes from `talus_create` and is not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_free(handle: *mut TalusComponent) {
    if !handle.is_null() {
        let _ = catch(|| {
            drop(unsafe { Box::from_raw(handle) });
            Ok(())
        });
    }
}

/// Initialises at `start_time` (enter and exit initialisation).
///
/// # Safety
/// `handle` is a live component.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_initialize(handle: *mut TalusComponent, start_time: f64) -> c_int {
    with(handle, |h| {
        h.component
            .enter_initialization_mode(start_time)
            .and_then(|_| h.component.exit_initialization_mode())
            .map_err(|e| e.to_string())
    })
}

/// Advances from `t` (the current time) by `h`.
///
/// # Safety
/// `handle` is a live component.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_step(handle: *mut TalusComponent, t: f64, h: f64) -> c_int {
    with(handle, |c| {
        c.component.do_step(t, h).map_err(|e| e.to_string())
    })
}

/// Ends the run (writes the last output if an output directory is set).
///
/// # Safety
/// `handle` is a live component.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_terminate(handle: *mut TalusComponent) -> c_int {
    with(handle, |c| {
        c.component.terminate().map_err(|e| e.to_string())
    })
}

/// Simulated time.
///
/// # Safety
/// `handle` is a live component, `time` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_time(handle: *mut TalusComponent, time: *mut f64) -> c_int {
    with(handle, |c| {
        let t = c
            .component
            .simulation()
            .ok_or("the component is not initialised")?
            .time();
        unsafe { put(time, t, "time") }
    })
}

/// What the user should know about the scene at the current parameters (a time step
/// above the suggested one, as `talus check` says it), one warning per line; "" when
/// there is none. The text lives until the next call on the component.
///
/// # Safety
/// `handle` is a live component, `text` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_warnings(
    handle: *mut TalusComponent,
    text: *mut *const c_char,
) -> c_int {
    with(handle, |c| {
        let joined = c.component.warnings().join("\n").replace('\0', " ");
        c.warnings = std::ffi::CString::new(joined).map_err(|e| e.to_string())?;
        unsafe { put(text, c.warnings.as_ptr(), "text") }
    })
}

/// Number of walls.
///
/// # Safety
/// `handle` is a live component, `count` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_wall_count(handle: *mut TalusComponent, count: *mut usize) -> c_int {
    with(handle, |c| unsafe {
        put(count, c.component.scene().world.walls.len(), "count")
    })
}

/// Index of the wall called `name`.
///
/// # Safety
/// `handle` is a live component, `name` a C string, `index` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_wall_index(
    handle: *mut TalusComponent,
    name: *const c_char,
    index: *mut usize,
) -> c_int {
    with(handle, |c| {
        let name = unsafe { text(name, "name") }?;
        let w = c
            .component
            .wall(name)
            .ok_or_else(|| format!("no wall called '{name}'"))?;
        unsafe { put(index, w, "index") }
    })
}

/// Sets the velocity inputs of a wall driven from outside by velocity (held from the
/// next step on).
///
/// # Safety
/// `handle` is a live component; `velocity` and `angular_velocity` hold 3 values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_set_wall_velocity(
    handle: *mut TalusComponent,
    wall: usize,
    velocity: *const f64,
    angular_velocity: *const f64,
) -> c_int {
    with(handle, |h| {
        let v = unsafe { slice(velocity, 3, "velocity") }?;
        let w = unsafe { slice(angular_velocity, 3, "angular_velocity") }?;
        set_wall_inputs(
            &mut h.component,
            wall,
            [("velocity", v), ("angular_velocity", w)],
            "velocity",
        )
    })
}

/// Sets the pose inputs of a wall driven from outside by pose: where its reference
/// point and orientation (w, x, y, z) are at the end of the next step.
///
/// # Safety
/// `handle` is a live component; `position` holds 3 values, `orientation` 4.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_set_wall_pose(
    handle: *mut TalusComponent,
    wall: usize,
    position: *const f64,
    orientation: *const f64,
) -> c_int {
    with(handle, |h| {
        let p = unsafe { slice(position, 3, "position") }?;
        let q = unsafe { slice(orientation, 4, "orientation") }?;
        set_wall_inputs(
            &mut h.component,
            wall,
            [("position", p), ("orientation", q)],
            "pose",
        )
    })
}

fn wall_pair(
    h: &mut TalusComponent,
    wall: usize,
    names: [&str; 2],
    force: *mut f64,
    torque: *mut f64,
) -> Result<(), String> {
    let c = &h.component;
    let name = wall_name(c, wall)?;
    let f = c
        .get_real_vector(var(c, &format!("{name}.{}", names[0]))?)
        .map_err(|e| e.to_string())?;
    let t = c
        .get_real_vector(var(c, &format!("{name}.{}", names[1]))?)
        .map_err(|e| e.to_string())?;
    unsafe { slice_mut(force, 3, "force") }?.copy_from_slice(&f);
    unsafe { slice_mut(torque, 3, "torque") }?.copy_from_slice(&t);
    Ok(())
}

/// Mean force and torque (about the wall's reference point) of the particles on a
/// wall over the last step: impulse divided by the step.
///
/// # Safety
/// `handle` is a live component; `force` and `torque` have room for 3 values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_wall_force(
    handle: *mut TalusComponent,
    wall: usize,
    force: *mut f64,
    torque: *mut f64,
) -> c_int {
    with(handle, |h| {
        wall_pair(h, wall, ["force", "torque"], force, torque)
    })
}

/// Force and torque on a wall at the end of the last step.
///
/// # Safety
/// As for `talus_get_wall_force`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_wall_force_end(
    handle: *mut TalusComponent,
    wall: usize,
    force: *mut f64,
    torque: *mut f64,
) -> c_int {
    with(handle, |h| {
        wall_pair(h, wall, ["force_end", "torque_end"], force, torque)
    })
}

/// Sizes of a wall's mesh.
///
/// # Safety
/// `handle` is a live component; `vertices` and `triangles` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_wall_mesh_size(
    handle: *mut TalusComponent,
    wall: usize,
    vertices: *mut usize,
    triangles: *mut usize,
) -> c_int {
    with(handle, |h| {
        let mesh = h
            .component
            .wall_mesh(wall)
            .ok_or_else(|| wall_name(&h.component, wall).unwrap_err())?;
        unsafe { put(vertices, mesh.vertices.len(), "vertices") }?;
        unsafe { put(triangles, mesh.triangles.len(), "triangles") }
    })
}

/// A wall's mesh as placed now: `3 n_vertices` coordinates and `3 n_triangles`
/// vertex indices (counter-clockwise seen from the particles).
///
/// # Safety
/// `handle` is a live component; the arrays have the sizes given.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_wall_mesh(
    handle: *mut TalusComponent,
    wall: usize,
    vertices: *mut f64,
    n_vertices: usize,
    triangles: *mut u32,
    n_triangles: usize,
) -> c_int {
    with(handle, |h| {
        let mesh = h
            .component
            .wall_mesh(wall)
            .ok_or_else(|| wall_name(&h.component, wall).unwrap_err())?;
        if n_vertices != mesh.vertices.len() || n_triangles != mesh.triangles.len() {
            return Err(format!(
                "the mesh has {} vertices and {} triangles, not {n_vertices} and {n_triangles}",
                mesh.vertices.len(),
                mesh.triangles.len()
            ));
        }
        let v = unsafe { slice_mut(vertices, 3 * n_vertices, "vertices") }?;
        for (out, p) in v.chunks_exact_mut(3).zip(&mesh.vertices) {
            out.copy_from_slice(p.coords.as_slice());
        }
        let t = unsafe { slice_mut(triangles, 3 * n_triangles, "triangles") }?;
        for (out, tri) in t.chunks_exact_mut(3).zip(mesh.triangles) {
            out.copy_from_slice(tri);
        }
        Ok(())
    })
}

/// The force on each facet of a wall at the end of the last step (`3 n_triangles`
/// values).
///
/// # Safety
/// `handle` is a live component; `forces` has room for `3 n_triangles` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_facet_forces(
    handle: *mut TalusComponent,
    wall: usize,
    forces: *mut f64,
    n_triangles: usize,
) -> c_int {
    with(handle, |h| {
        let c = &h.component;
        let name = wall_name(c, wall)?;
        let f = c
            .get_real_vector(var(c, &format!("{name}.facet_force"))?)
            .map_err(|e| e.to_string())?;
        if f.len() != 3 * n_triangles {
            return Err(format!(
                "the wall has {} facets, not {n_triangles}",
                f.len() / 3
            ));
        }
        unsafe { slice_mut(forces, f.len(), "forces") }?.copy_from_slice(&f);
        Ok(())
    })
}

/// The structured fluid grid of a scene with `[fluid]` (`grid = "cartesian"`): the
/// lower corner of its first cell, the cell edges and the cell counts along x, y and
/// z (3 values each). Per-cell arrays (`fluid.velocity`, `fluid.solid_fraction` ...;
/// see `talus_get_real`) run x fastest, then y, then z, with x y z per cell for
/// vectors. Other kinds of cells: an error (see `talus_get_fluid_cells`).
///
/// # Safety
/// `handle` is a live component; `origin`, `cell` and `counts` have room for 3 values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_fluid_grid(
    handle: *mut TalusComponent,
    origin: *mut f64,
    cell: *mut f64,
    counts: *mut usize,
) -> c_int {
    with(handle, |h| {
        let grid = h.component.fluid_grid().map_err(|e| e.to_string())?;
        // Every pointer checked before any is written.
        let (o, c, n) = unsafe {
            (
                slice_mut(origin, 3, "origin")?,
                slice_mut(cell, 3, "cell")?,
                slice_mut(counts, 3, "counts")?,
            )
        };
        let grid = grid.as_cartesian().ok_or_else(|| {
            format!(
                "the fluid's cells are {}, not a structured grid: talus_get_fluid_cells gives them",
                grid.kind()
            )
        })?;
        o.copy_from_slice(grid.origin().coords.as_slice());
        c.copy_from_slice(grid.cell_size().as_slice());
        n.copy_from_slice(&grid.counts());
        Ok(())
    })
}

/// The number of fluid cells of a scene with `[fluid]` (any kind of grid).
///
/// # Safety
/// `handle` is a live component; `count` points to writable memory.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_fluid_cell_count(
    handle: *mut TalusComponent,
    count: *mut usize,
) -> c_int {
    with(handle, |h| {
        let cells = h.component.fluid_grid().map_err(|e| e.to_string())?.len();
        unsafe { slice_mut(count, 1, "count") }?[0] = cells;
        Ok(())
    })
}

/// Every fluid cell's centre (x y z per cell: a cylindrical grid's cell at
/// mid-radius, mid-angle and mid-height) and volume, in the order of the per-cell
/// arrays; `n` is the number of cells (`talus_get_fluid_cell_count`), `centres` has
/// room for `3 n` values and `volumes` for `n`.
///
/// # Safety
/// `handle` is a live component; `centres` and `volumes` have room as stated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_fluid_cells(
    handle: *mut TalusComponent,
    n: usize,
    centres: *mut f64,
    volumes: *mut f64,
) -> c_int {
    with(handle, |h| {
        let grid = h.component.fluid_grid().map_err(|e| e.to_string())?;
        if n != grid.len() {
            return Err(format!("n is {n}, the fluid has {} cells", grid.len()));
        }
        let (c, v) = unsafe {
            (
                slice_mut(centres, 3 * n, "centres")?,
                slice_mut(volumes, n, "volumes")?,
            )
        };
        for k in 0..n {
            c[3 * k..3 * k + 3].copy_from_slice(grid.centre(k).coords.as_slice());
            v[k] = grid.cell_volume(k);
        }
        Ok(())
    })
}

/// The number of particles whose fluid `talus_get_particle_fluid` gives (scenes
/// with `[fluid]`; it changes as inlets add particles).
///
/// # Safety
/// `handle` is a live component; `count` points to writable memory.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_particle_count(
    handle: *mut TalusComponent,
    count: *mut usize,
) -> c_int {
    with(handle, |h| {
        h.component.fluid_grid().map_err(|e| e.to_string())?;
        unsafe { slice_mut(count, 1, "count") }?[0] = h.component.world().particles.owned();
        Ok(())
    })
}

/// What the fluid does to each of the `n` particles (`talus_get_particle_count`):
/// its id, the drag of the last force evaluation (x y z, N), the slip (the fluid's
/// velocity at the particle less its own, x y z, m/s) and the local void fraction.
/// `ids` and `voidage` have room for `n` values, `drag` and `slip` for `3 n`.
/// Particles come in the order of their ids (on ranks too).
///
/// # Safety
/// `handle` is a live component; the arrays have room as stated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_particle_fluid(
    handle: *mut TalusComponent,
    n: usize,
    ids: *mut u64,
    drag: *mut f64,
    slip: *mut f64,
    voidage: *mut f64,
) -> c_int {
    with(handle, |h| {
        let (id, fluid) = h.component.particle_fluid().map_err(|e| e.to_string())?;
        if n != id.len() {
            return Err(format!("n is {n}, there are {} particles", id.len()));
        }
        let (i, d, s, v) = unsafe {
            (
                slice_mut(ids, n, "ids")?,
                slice_mut(drag, 3 * n, "drag")?,
                slice_mut(slip, 3 * n, "slip")?,
                slice_mut(voidage, n, "voidage")?,
            )
        };
        i.copy_from_slice(&id);
        for (k, f) in fluid.iter().enumerate() {
            d[3 * k..3 * k + 3].copy_from_slice(f.drag.as_slice());
            s[3 * k..3 * k + 3].copy_from_slice(f.slip.as_slice());
            v[k] = f.voidage;
        }
        Ok(())
    })
}

/// Reads the `n` values of the real variable called `name`.
///
/// # Safety
/// `handle` is a live component, `name` a C string, `values` has room for `n`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_get_real(
    handle: *mut TalusComponent,
    name: *const c_char,
    values: *mut f64,
    n: usize,
) -> c_int {
    with(handle, |h| {
        let c = &h.component;
        let name = unsafe { text(name, "name") }?;
        let x = c
            .get_real_vector(var(c, name)?)
            .map_err(|e| e.to_string())?;
        if x.len() != n {
            return Err(format!("variable '{name}' has {} values, not {n}", x.len()));
        }
        unsafe { slice_mut(values, n, "values") }?.copy_from_slice(&x);
        Ok(())
    })
}

/// Sets the `n` values of the real variable called `name`.
///
/// # Safety
/// `handle` is a live component, `name` a C string, `values` holds `n` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_set_real(
    handle: *mut TalusComponent,
    name: *const c_char,
    values: *const f64,
    n: usize,
) -> c_int {
    with(handle, |h| {
        let c = &mut h.component;
        let name = unsafe { text(name, "name") }?;
        let v = var(c, name)?;
        let size = c.variables()[v].size;
        if size != n {
            return Err(format!("variable '{name}' has {size} values, not {n}"));
        }
        let x = unsafe { slice(values, n, "values") }?;
        c.set_real_vector(v, x).map_err(|e| e.to_string())
    })
}

/// Saves the whole state; `*bytes` points to `*size` bytes owned by the component,
/// valid until the next save or `talus_free`.
///
/// # Safety
/// `handle` is a live component; `bytes` and `size` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_save_state(
    handle: *mut TalusComponent,
    bytes: *mut *const u8,
    size: *mut usize,
) -> c_int {
    with(handle, |h| {
        let state = h.component.save_state().map_err(|e| e.to_string())?;
        h.saved = h.component.state_to_bytes(&state);
        unsafe { put(bytes, h.saved.as_ptr(), "bytes") }?;
        unsafe { put(size, h.saved.len(), "size") }
    })
}

/// Restores a state saved by `talus_save_state` (of the same scene).
///
/// # Safety
/// `handle` is a live component; `bytes` holds `size` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn talus_restore_state(
    handle: *mut TalusComponent,
    bytes: *const u8,
    size: usize,
) -> c_int {
    with(handle, |h| {
        let b = unsafe { slice(bytes, size, "bytes") }?;
        let state = h.component.state_from_bytes(b).map_err(|e| e.to_string())?;
        h.component.restore_state(&state).map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cosim::Mode;
    use std::ffi::CStr;

    fn drum() -> *mut TalusComponent {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/drum_fmu/drum.toml\0");
        let h = unsafe { talus_create(path.as_ptr().cast()) };
        assert!(!h.is_null());
        h
    }

    #[test]
    fn warnings_follow_the_time_step_parameter() {
        let h = drum();
        let mut text: *const c_char = std::ptr::null();
        assert_eq!(unsafe { talus_warnings(h, &mut text) }, TALUS_OK);
        assert_eq!(unsafe { std::ffi::CStr::from_ptr(text) }.to_bytes(), b"");
        let dt = [5e-3];
        let name = c"dt";
        assert_eq!(
            unsafe { talus_set_real(h, name.as_ptr(), dt.as_ptr(), 1) },
            TALUS_OK
        );
        assert_eq!(unsafe { talus_warnings(h, &mut text) }, TALUS_OK);
        let warning = unsafe { std::ffi::CStr::from_ptr(text) }.to_string_lossy();
        assert!(warning.contains("above the suggested"), "{warning}");
        assert_eq!(
            unsafe { talus_warnings(h, std::ptr::null_mut()) },
            TALUS_ERROR
        );
        assert_eq!(
            unsafe { talus_warnings(std::ptr::null_mut(), &mut text) },
            TALUS_ERROR
        );
        unsafe { talus_free(h) };
    }

    #[test]
    fn a_panic_becomes_an_error_status_and_the_error_state() {
        let h = drum();
        let status = with(h, |_| panic!("deliberate"));
        assert_eq!(status, TALUS_ERROR);
        let message = unsafe { CStr::from_ptr(talus_last_error()) }
            .to_string_lossy()
            .into_owned();
        assert!(
            message.contains("panic") && message.contains("deliberate"),
            "{message}"
        );
        assert_eq!(unsafe { &*h }.component.mode(), Mode::Error);
        // Nothing but free works afterwards.
        assert_eq!(unsafe { talus_initialize(h, 0.0) }, TALUS_ERROR);
        unsafe { talus_free(h) };
    }

    #[test]
    fn null_handles_and_pointers_are_refused() {
        assert_eq!(
            unsafe { talus_initialize(std::ptr::null_mut(), 0.0) },
            TALUS_ERROR
        );
        assert!(unsafe { talus_create(std::ptr::null()) }.is_null());
        let h = drum();
        assert_eq!(
            unsafe { talus_wall_count(h, std::ptr::null_mut()) },
            TALUS_ERROR
        );
        unsafe { talus_free(h) };
    }
}
