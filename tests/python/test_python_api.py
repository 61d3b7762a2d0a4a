"""The Python module `talus` (PyO3, built into the test venv by scripts/test.sh):
the same numbers as the native C API bit for bit, misuse raised as TalusError with
the scene left as it was, saved states continuing bit for bit, particle arrays, and
runs to an end with a progress bar, each particle's fluid."""
import ctypes
import struct

import numpy as np
import pytest

import talus
from conftest import SCENES

DRUM = str(SCENES["drum"])
OMEGA = 3.0  # rad/s about the drum axis (y)


def spun_drum():
    s = talus.Scene(DRUM)
    s.initialize(0.0)
    s.set_wall_velocity("drum", [0.0, 0.0, 0.0], [0.0, OMEGA, 0.0])
    return s


def bits(values):
    """The exact bits of float values: equality here is bit for bit (and -0.0 != 0.0)."""
    return [struct.pack("<d", float(x)) for x in values]


def test_the_drum_torque_equals_the_c_api_bit_for_bit(library):
    lib = ctypes.CDLL(str(library))
    lib.talus_create.restype = ctypes.c_void_p
    lib.talus_create.argtypes = [ctypes.c_char_p]
    handle = ctypes.c_void_p(lib.talus_create(DRUM.encode()))
    assert handle.value
    assert lib.talus_initialize(handle, ctypes.c_double(0.0)) == 0
    py = talus.Scene(DRUM)
    py.initialize(0.0)
    f, m = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
    t = 0.0
    # Uneven steps and a reversal: the sub-step loop and the drive are exercised.
    for k, omega in enumerate([OMEGA, OMEGA, OMEGA, -OMEGA, 0.5 * OMEGA, 0.0]):
        assert lib.talus_set_wall_velocity(handle, ctypes.c_size_t(0), (ctypes.c_double * 3)(),
                                           (ctypes.c_double * 3)(0, omega, 0)) == 0
        py.set_wall_velocity(0, np.zeros(3), np.array([0.0, omega, 0.0]))
        h = 0.013 + 0.01 * k
        assert lib.talus_step(handle, ctypes.c_double(t), ctypes.c_double(h)) == 0
        assert py.step(h) == pytest.approx(t + h, rel=1e-15)
        t += h
        assert lib.talus_get_wall_force(handle, ctypes.c_size_t(0), f, m) == 0
        force, torque = py.wall_force("drum")
        assert bits(torque) == bits(m) and bits(force) == bits(f), (torque, list(m))
    # The bed was lifted: the torque is not trivially zero.
    assert abs(m[1]) > 1e-4
    lib.talus_free(handle)


def test_misuse_raises_with_the_message_and_leaves_the_scene_as_it_was(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(open(DRUM).read().replace("end_time = 10.0", "end_time = 10.0\nend_tme = 3"))
    with pytest.raises(talus.TalusError, match=r"bad\.toml:8:1: unknown field `end_tme`"):
        talus.Scene(str(bad))
    with pytest.raises(talus.TalusError, match="cannot read"):
        talus.Scene(str(tmp_path / "missing.toml"))

    s, twin = talus.Scene(DRUM), talus.Scene(DRUM)
    with pytest.raises(talus.TalusError, match="instantiated"):
        s.step(0.01)  # before initialize
    with pytest.raises(talus.TalusError, match="not initialised"):
        s.positions
    for scene in (s, twin):
        scene.initialize(0.0)
        scene.set_wall_velocity("drum", [0, 0, 0], [0, OMEGA, 0])
        scene.step(0.02)
    before = s.save_state()
    refused = [
        (lambda: s.step(-0.01), "must be positive"),
        (lambda: s.step(float("nan")), "must be positive"),
        (lambda: s.set_wall_velocity("lid", [0, 0, 0], [0, 0, 0]), "no wall called 'lid'"),
        (lambda: s.set_wall_velocity(3, [0, 0, 0], [0, 0, 0]), "out of range"),
        (lambda: s.set_wall_velocity("drum", [0, 0], [0, 0, 0]), "2 values, expected 3"),
        (lambda: s.set_wall_pose("drum", [0, 0, 0], [1, 0, 0, 0]), "not driven from outside by pose"),
        (lambda: s.set("dt", [1e-5]), "parameter"),  # only before initialisation
        (lambda: s.set("drum.angular_velocity", [0.0, 1.0]), "has 3 values, not 2"),
        (lambda: s.get("no_such_variable"), "no_such_variable"),
        (lambda: s.restore_state(b"not a state"), "state"),
        (lambda: s.restore_state(before[:-5]), "state"),
    ]
    for call, message in refused:
        with pytest.raises(talus.TalusError, match=message):
            call()
    # Nothing of it changed the scene: it goes on exactly as its twin.
    assert s.save_state() == before
    for scene in (s, twin):
        scene.step(0.02)
    assert bits(s.wall_force("drum")[1]) == bits(twin.wall_force("drum")[1])
    assert s.positions.tobytes() == twin.positions.tobytes()
    with pytest.raises(TypeError):
        s.set_wall_velocity("drum", "fast", [0, 0, 0])


def test_a_restored_state_continues_bit_for_bit():
    s = spun_drum()
    s.step(0.05)
    state = s.save_state()
    assert isinstance(state, bytes)

    def go_on(scene):
        torques = []
        for _ in range(5):
            scene.step(0.01)
            torques += bits(scene.wall_force("drum")[1])
        return torques, scene.positions.tobytes(), scene.orientations.tobytes(), scene.time

    first = go_on(s)
    s.restore_state(state)
    assert s.time == pytest.approx(0.05, abs=1e-15)
    assert go_on(s) == first
    # And in another instance of the same scene (as after a restart).
    other = talus.Scene(DRUM)
    other.initialize(0.0)
    other.restore_state(state)
    assert go_on(other) == first


def test_particle_and_wall_arrays_describe_the_bed():
    s = spun_drum()
    s.step(0.1)
    n = s.particle_count
    assert n == 96
    x, v, w, q, ids = s.positions, s.velocities, s.angular_velocities, s.orientations, s.ids
    assert x.shape == v.shape == w.shape == (n, 3) and q.shape == (n, 4) and ids.shape == (n,)
    assert x.dtype == np.float64 and ids.dtype == np.uint64
    assert sorted(ids) == list(range(n))
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    # Every bead (radius 4 mm) inside the drum (radius 60 mm about the y axis, 30 mm long).
    assert np.all(np.hypot(x[:, 0], x[:, 2]) < 0.06 - 0.004 + 1e-4)
    assert np.all((x[:, 1] > 0.004 - 1e-4) & (x[:, 1] < 0.026 + 1e-4))
    # The kinetic energy output is that of these velocities (spheres: I = 2/5 m r^2).
    mass = 2500.0 * 4.0 / 3.0 * np.pi * 0.004 ** 3
    kinetic = 0.5 * mass * (np.sum(v * v) + 0.4 * 0.004 ** 2 * np.sum(w * w))
    assert s.get("kinetic_energy")[0] == pytest.approx(kinetic, rel=1e-9)
    # Arrays are copies: changing one leaves the scene alone.
    x[:] = 0.0
    assert not np.all(s.positions == 0.0)
    # The wall: its mesh as placed, and facet forces that add up to the wall's force.
    vertices, triangles = s.wall_mesh("drum")
    facets = s.facet_forces("drum")
    assert vertices.shape[1] == 3 and triangles.shape[1] == 3 and triangles.dtype == np.uint32
    assert facets.shape == (len(triangles), 3)
    assert triangles.max() < len(vertices)
    force_end, _ = s.wall_force_end("drum")
    assert np.allclose(facets.sum(axis=0), force_end, rtol=1e-9, atol=1e-12)
    forces, torques = s.wall_forces()
    assert forces.shape == torques.shape == (1, 3)
    assert bits(forces[0]) == bits(s.wall_force(0)[0])


def test_each_particles_fluid_matches_the_flow_it_sits_in():
    # The fluid column at its start flow (2 m/s upward everywhere): each particle's
    # slip plus its velocity is that flow; the drag lifts; the voidage is a fraction.
    s = talus.Scene(str(SCENES["fluid"]))
    s.initialize(0.0)
    s.step(5e-4)
    drag, slip, voidage, v = s.fluid_drag, s.fluid_slip, s.fluid_voidage, s.velocities
    n = s.particle_count
    assert drag.shape == slip.shape == (n, 3) and voidage.shape == (n,)
    assert np.allclose(slip + v, [0.0, 0.0, 2.0], rtol=0, atol=1e-12)
    assert drag[:, 2].sum() > 0.0
    assert np.all((voidage > 0.0) & (voidage <= 1.0))
    with pytest.raises(talus.TalusError, match="no \\[fluid\\] section"):
        spun_drum().fluid_drag


class Recorder:
    def __init__(self):
        self.total, self.closed = 0.0, False

    def update(self, amount):
        self.total += amount

    def close(self):
        self.closed = True


def test_run_lands_on_the_end_with_progress_and_stops_when_asked(capsys):
    s = talus.Scene(DRUM)
    bar = Recorder()
    assert s.run(until=0.05, interval=0.007, progress=bar) == pytest.approx(0.05, abs=1e-15)
    assert bar.closed and bar.total == pytest.approx(0.05, rel=1e-12)
    calls = []
    reached = s.run(until=0.2, interval=0.01, progress=False,
                    each=lambda scene: calls.append(scene.time) or len(calls) < 3)
    assert len(calls) == 3 and reached == pytest.approx(0.08, abs=1e-12)
    # The built-in bar (tqdm in this venv) writes to stderr.
    talus.run(s, until=0.1, interval=0.01)
    assert "0.02/0.02 s" in capsys.readouterr().err  # the span from 0.08 s
    with pytest.raises(ValueError):
        s.run(until=0.2, interval=-1.0, progress=False)


def test_scenes_step_in_parallel_threads_as_they_do_alone():
    """Steps release Python's lock: two scenes stepped from two threads at once give
    the bits each gives alone."""
    import threading

    def torques(scene, out):
        for _ in range(10):
            scene.step(0.01)
            out.extend(bits(scene.wall_force("drum")[1]))

    alone = []
    torques(spun_drum(), alone)
    results = [[], []]
    threads = [threading.Thread(target=torques, args=(spun_drum(), r)) for r in results]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads)
    assert results[0] == alone and results[1] == alone
