//! `talus._talus`: the co-simulation [`Component`] as the Python class `Scene`, with
//! numpy arrays in and out. The pure-Python package `talus` (`talus/__init__.py`)
//! re-exports it and adds `Scene.run`, a run to the end with a progress bar.
//!
//! The calls are the C API's (`interfaces/c/talus.h`) with Python's types: a refused
//! call raises `talus.TalusError` carrying talus's own message (file, line and field
//! for a scene) and leaves the scene as it was; a panic inside talus raises it too
//! and puts the scene in the error state, where only `reset` helps.
//!
//! Particle arrays are copies taken when asked for: a view into the live state would
//! change under the caller at the next step and dangle when an inlet grows the arrays.
//! Each copy is made once, into a buffer numpy then owns without copying again.

use std::path::Path;
use std::sync::{Mutex, MutexGuard, PoisonError};

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use talus::Real;
use talus::cosim::Component;
use talus::ffi::guard::catch;

pyo3::create_exception!(
    talus,
    TalusError,
    PyException,
    "A call talus refused (bad input, wrong mode, a diverging step), with its message."
);

/// A wall named by its index or its name.
#[derive(FromPyObject)]
enum WallRef {
    #[pyo3(transparent)]
    Index(usize),
    #[pyo3(transparent)]
    Name(String),
}

/// A scene file loaded as a co-simulation component.
///
/// Life cycle: ``Scene(path)`` → set parameters (``set("dt", ...)``) →
/// ``initialize(start_time)`` → ``step(h)`` … → ``terminate()``. SI units throughout;
/// wall forces are those the particles exert on the wall, torques are about the
/// wall's reference point.
#[pyclass(module = "talus", name = "Scene", subclass)]
struct Scene {
    /// Behind a mutex because a Python class must be shareable between threads and a
    /// component's backend need not be `Sync`; calls that change it take `&mut self`
    /// and reach it without locking.
    component: Mutex<Component>,
    path: String,
}

/// Two vectors of 3 (a force and a torque).
type Pair<'py> = (Bound<'py, PyArray1<Real>>, Bound<'py, PyArray1<Real>>);

/// `n × 3` values as an `(n, 3)` array.
fn rows3<'py>(py: Python<'py>, values: Vec<Real>) -> PyResult<Bound<'py, PyArray2<Real>>> {
    let n = values.len() / 3;
    values.into_pyarray(py).reshape([n, 3])
}

impl Scene {
    /// The component, to read.
    fn c(&self) -> MutexGuard<'_, Component> {
        self.component
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// The component, to change.
    fn c_mut(&mut self) -> &mut Component {
        self.component
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// Runs `f` on the component: panics caught (the component then goes to the
    /// error state), errors raised as `TalusError`.
    fn call<T>(&mut self, f: impl FnOnce(&mut Component) -> Result<T, String>) -> PyResult<T> {
        let component = self.c_mut();
        catch(|| f(component)).map_err(|message| {
            if message.starts_with("internal error") {
                self.c_mut().fail();
            }
            TalusError::new_err(message)
        })
    }

    /// Reads without changing: errors raised as `TalusError`.
    fn read<T>(&self, f: impl FnOnce(&Component) -> Result<T, String>) -> PyResult<T> {
        catch(|| f(&self.c())).map_err(TalusError::new_err)
    }

    fn wall_index(&self, wall: &WallRef) -> PyResult<usize> {
        let count = self.c().scene().world.walls.len();
        match wall {
            WallRef::Index(k) if *k < count => Ok(*k),
            WallRef::Index(k) => Err(TalusError::new_err(format!(
                "wall index {k} out of range (the scene has {count})"
            ))),
            WallRef::Name(name) => self
                .c()
                .wall(name)
                .ok_or_else(|| TalusError::new_err(format!("no wall called '{name}'"))),
        }
    }

    fn wall_name(&self, wall: &WallRef) -> PyResult<String> {
        let k = self.wall_index(wall)?;
        Ok(self.c().scene().world.walls[k].name.clone())
    }

    /// All values of the real variable `name`.
    fn real(&self, name: &str) -> PyResult<Vec<Real>> {
        self.read(|c| {
            let var = c.variable(name).map_err(|e| e.to_string())?;
            c.get_real_vector(var).map_err(|e| e.to_string())
        })
    }

    /// Sets the two input variables `wall.suffix` of a wall driven from outside by
    /// `kind`, all or none, as the C API does once the sizes are checked.
    fn set_wall_inputs(
        &mut self,
        wall: &WallRef,
        inputs: [(&str, Vec<Real>, usize); 2],
        kind: &str,
    ) -> PyResult<()> {
        let wall = self.wall_index(wall)?;
        self.call(|c| {
            for (suffix, x, size) in &inputs {
                if x.len() != *size {
                    return Err(format!("{suffix}: {} values, expected {size}", x.len()));
                }
            }
            let [(a, x, _), (b, y, _)] = &inputs;
            talus::ffi::set_wall_inputs(c, wall, [(a, x), (b, y)], kind)
        })
    }

    /// The two wall outputs `wall.names[0]` and `wall.names[1]`.
    fn wall_pair<'py>(
        &self,
        py: Python<'py>,
        wall: &WallRef,
        names: [&str; 2],
    ) -> PyResult<Pair<'py>> {
        let wall = self.wall_name(wall)?;
        let [a, b] = names.map(|name| self.real(&format!("{wall}.{name}")));
        Ok((a?.into_pyarray(py), b?.into_pyarray(py)))
    }

    /// `f` of the running simulation's world.
    fn with_world<T>(&self, f: impl FnOnce(&talus::world::World) -> T) -> PyResult<T> {
        let c = self.c();
        let sim = c.simulation().ok_or_else(|| {
            TalusError::new_err("the scene is not initialised: call initialize() first")
        })?;
        Ok(f(sim.world()))
    }

    /// What the fluid does to each particle, in the order of the particle arrays (the
    /// component lists it by id; the arrays follow the world's storage).
    fn particle_fluid(&self) -> PyResult<Vec<talus::world::ParticleFluid>> {
        let (ids, each) = self.read(|c| c.particle_fluid().map_err(|e| e.to_string()))?;
        self.with_world(|w| {
            let p = &w.particles;
            (0..p.owned())
                .map(|i| ids.binary_search(&p.id[i]).map(|k| each[k]))
                .collect::<Result<Vec<_>, _>>()
        })?
        .map_err(|_| TalusError::new_err("a particle without its fluid row"))
    }

    /// One value per owned particle, `width` reals each, as an `(n, width)` array.
    fn per_particle<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        value: impl Fn(&talus::world::World, usize, &mut Vec<Real>),
    ) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let (n, out) = self.with_world(|world| {
            let n = world.particles.owned();
            let mut out = Vec::with_capacity(width * n);
            for i in 0..n {
                value(world, i, &mut out);
            }
            (n, out)
        })?;
        out.into_pyarray(py).reshape([n, width])
    }
}

#[pymethods]
impl Scene {
    /// Loads a scene (TOML); paths in it are relative to it.
    #[new]
    fn new(path: &str) -> PyResult<Self> {
        let component =
            catch(|| Component::instantiate(Path::new(""), path).map_err(|e| e.to_string()))
                .map_err(TalusError::new_err)?;
        Ok(Scene {
            component: Mutex::new(component),
            path: path.to_string(),
        })
    }

    fn __repr__(&self) -> String {
        let c = self.c();
        format!(
            "Scene('{}', mode={}, walls={})",
            self.path,
            c.mode(),
            c.scene().world.walls.len()
        )
    }

    /// Builds the simulation and starts it at `start_time` (FMI's enter and exit of
    /// initialisation).
    #[pyo3(signature = (start_time = 0.0))]
    fn initialize(&mut self, start_time: Real) -> PyResult<()> {
        self.call(|c| {
            c.enter_initialization_mode(start_time)
                .and_then(|_| c.exit_initialization_mode())
                .map_err(|e| e.to_string())
        })
    }

    /// Advances by `h` seconds from the current time; returns the new time. The
    /// Python lock is released while the step runs.
    fn step(&mut self, py: Python<'_>, h: Real) -> PyResult<Real> {
        // Before initialisation the component itself refuses the step, by its mode.
        let t = self.c().simulation().map_or(0.0, |s| s.time());
        let component = self.c_mut();
        let result = py.detach(|| {
            catch(|| {
                component.do_step(t, h).map_err(|e| e.to_string())?;
                Ok(component.simulation().map_or(t + h, |s| s.time()))
            })
        });
        result.map_err(|message| {
            if message.starts_with("internal error") {
                self.c_mut().fail();
            }
            TalusError::new_err(message)
        })
    }

    /// Ends the run (writes the last output when an output directory is set).
    fn terminate(&mut self) -> PyResult<()> {
        self.call(|c| c.terminate().map_err(|e| e.to_string()))
    }

    /// Back to the state after loading, with the start values (from any mode).
    fn reset(&mut self) {
        self.c_mut().reset();
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self) -> PyResult<Real> {
        self.c()
            .simulation()
            .map(|s| s.time())
            .ok_or_else(|| TalusError::new_err("the scene is not initialised"))
    }

    /// The scene's end time (`[simulation] end_time`), s.
    #[getter]
    fn end_time(&self) -> Real {
        self.c().scene().spec.simulation.end_time
    }

    /// The life-cycle mode: instantiated, initialisation, step, terminated or error.
    #[getter]
    fn mode(&self) -> String {
        self.c().mode().to_string()
    }

    /// Warnings at the current parameters (a time step above the suggested one).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.c().warnings()
    }

    /// The walls' names, in index order.
    #[getter]
    fn walls(&self) -> Vec<String> {
        let c = self.c();
        c.scene()
            .world
            .walls
            .iter()
            .map(|w| w.name.clone())
            .collect()
    }

    /// The names of all variables (those of the FMUs' model description).
    #[getter]
    fn variables(&self) -> Vec<String> {
        let c = self.c();
        c.variables().iter().map(|v| v.name.clone()).collect()
    }

    /// All values of the real variable `name` ("drum.torque", "kinetic_energy" ...).
    fn get<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<Real>>> {
        Ok(self.real(name)?.into_pyarray(py))
    }

    /// Sets all values of the real variable `name` (a parameter or an input).
    fn set(&mut self, name: &str, values: Vec<Real>) -> PyResult<()> {
        self.call(|c| {
            let var = c.variable(name).map_err(|e| e.to_string())?;
            let size = c.variables()[var].size;
            if values.len() != size {
                return Err(format!(
                    "variable '{name}' has {size} values, not {}",
                    values.len()
                ));
            }
            c.set_real_vector(var, &values).map_err(|e| e.to_string())
        })
    }

    /// Velocity inputs of a wall driven from outside by velocity: `velocity` of the
    /// reference point and `angular_velocity` about it, held from the next step on.
    fn set_wall_velocity(
        &mut self,
        wall: WallRef,
        velocity: Vec<Real>,
        angular_velocity: Vec<Real>,
    ) -> PyResult<()> {
        let inputs = [
            ("velocity", velocity, 3),
            ("angular_velocity", angular_velocity, 3),
        ];
        self.set_wall_inputs(&wall, inputs, "velocity")
    }

    /// Pose inputs of a wall driven from outside by pose: its reference point and
    /// orientation (w, x, y, z) at the end of the next step.
    fn set_wall_pose(
        &mut self,
        wall: WallRef,
        position: Vec<Real>,
        orientation: Vec<Real>,
    ) -> PyResult<()> {
        let inputs = [("position", position, 3), ("orientation", orientation, 4)];
        self.set_wall_inputs(&wall, inputs, "pose")
    }

    /// Mean force (N) and torque (N m) of the particles on a wall over the last step
    /// (impulse over the step): two arrays of 3.
    fn wall_force<'py>(&self, py: Python<'py>, wall: WallRef) -> PyResult<Pair<'py>> {
        self.wall_pair(py, &wall, ["force", "torque"])
    }

    /// Force and torque on a wall at the end of the last step.
    fn wall_force_end<'py>(&self, py: Python<'py>, wall: WallRef) -> PyResult<Pair<'py>> {
        self.wall_pair(py, &wall, ["force_end", "torque_end"])
    }

    /// Mean forces and torques on every wall over the last step: two `(walls, 3)`
    /// arrays, rows in wall order.
    #[allow(clippy::type_complexity)]
    fn wall_forces<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyArray2<Real>>, Bound<'py, PyArray2<Real>>)> {
        let (mut f, mut t) = (Vec::new(), Vec::new());
        for name in self.walls() {
            f.extend(self.real(&format!("{name}.force"))?);
            t.extend(self.real(&format!("{name}.torque"))?);
        }
        Ok((rows3(py, f)?, rows3(py, t)?))
    }

    /// A wall's mesh as placed now: vertices `(n, 3)` in metres and triangles
    /// `(m, 3)` of vertex indices, counter-clockwise seen from the particles.
    #[allow(clippy::type_complexity)]
    fn wall_mesh<'py>(
        &self,
        py: Python<'py>,
        wall: WallRef,
    ) -> PyResult<(Bound<'py, PyArray2<Real>>, Bound<'py, PyArray2<u32>>)> {
        let k = self.wall_index(&wall)?;
        let (vertices, triangles) = {
            let c = self.c();
            let mesh = c
                .wall_mesh(k)
                .ok_or_else(|| TalusError::new_err(format!("no wall {k}")))?;
            let vertices: Vec<Real> = mesh
                .vertices
                .iter()
                .flat_map(|p| p.coords.data.0[0])
                .collect();
            let triangles: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
            (vertices, triangles)
        };
        let m = triangles.len() / 3;
        Ok((
            rows3(py, vertices)?,
            triangles.into_pyarray(py).reshape([m, 3])?,
        ))
    }

    /// The force on each facet of a wall at the end of the last step, `(m, 3)`.
    fn facet_forces<'py>(
        &self,
        py: Python<'py>,
        wall: WallRef,
    ) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let name = self.wall_name(&wall)?;
        rows3(py, self.real(&format!("{name}.facet_force"))?)
    }

    /// Particles in the simulation now (owned ones).
    #[getter]
    fn particle_count(&self) -> PyResult<usize> {
        self.with_world(|w| w.particles.owned())
    }

    /// Particle ids, `(n,)`, in the order of the other particle arrays. That order
    /// changes every 1000 steps (the particles are stored by their place in space):
    /// match rows of different steps by id.
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u64>>> {
        let ids = self.with_world(|w| w.particles.id[..w.particles.owned()].to_vec())?;
        Ok(ids.into_pyarray(py))
    }

    /// Centroids, `(n, 3)`, m.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        self.per_particle(py, 3, |w, i, out| {
            out.extend_from_slice(w.particles.position[i].coords.as_slice())
        })
    }

    /// Velocities of the centroids, `(n, 3)`, m/s.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        self.per_particle(py, 3, |w, i, out| {
            out.extend_from_slice(w.particles.velocity[i].as_slice())
        })
    }

    /// Angular velocities in the world frame, `(n, 3)`, rad/s.
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        self.per_particle(py, 3, |w, i, out| {
            out.extend_from_slice(w.angular_velocity(i).as_slice())
        })
    }

    /// Orientations as unit quaternions (w, x, y, z) of the principal axes, `(n, 4)`.
    #[getter]
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        self.per_particle(py, 4, |w, i, out| {
            let q = w.particles.orientation[i];
            out.extend_from_slice(&[q.w, q.i, q.j, q.k]);
        })
    }

    /// With a `[fluid]`: each particle's drag of the last force evaluation, `(n, 3)`,
    /// N.
    #[getter]
    fn fluid_drag<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let each = self.particle_fluid()?;
        rows3(
            py,
            each.iter().flat_map(|f| f.drag.iter().copied()).collect(),
        )
    }

    /// With a `[fluid]`: the fluid's velocity at each particle less its own, `(n, 3)`,
    /// m/s.
    #[getter]
    fn fluid_slip<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let each = self.particle_fluid()?;
        rows3(
            py,
            each.iter().flat_map(|f| f.slip.iter().copied()).collect(),
        )
    }

    /// With a `[fluid]`: the fluid's volume fraction at each particle, `(n,)`.
    #[getter]
    fn fluid_voidage<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<Real>>> {
        let each = self.particle_fluid()?;
        Ok(each
            .iter()
            .map(|f| f.voidage)
            .collect::<Vec<_>>()
            .into_pyarray(py))
    }

    /// The whole state as bytes (checksummed; restores on a scene of the same file).
    fn save_state<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.call(|c| {
            let state = c.save_state().map_err(|e| e.to_string())?;
            Ok(c.state_to_bytes(&state))
        })?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Restores a state from `save_state`: stepping on gives the same results bit for
    /// bit.
    fn restore_state(&mut self, state: &[u8]) -> PyResult<()> {
        self.call(|c| {
            let s = c.state_from_bytes(state).map_err(|e| e.to_string())?;
            c.restore_state(&s).map_err(|e| e.to_string())
        })
    }
}

/// The talus version.
#[pyfunction]
fn version() -> &'static str {
    talus::VERSION
}

#[pymodule]
fn _talus(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add("TalusError", m.py().get_type::<TalusError>())?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
