"""The FMUs under fmpy: validation, simulation with time-varying inputs, rollback,
serialised states, agreement with the native C API, misuse, repeated loading."""
import ctypes
import os
import shutil
import threading

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
from fmpy.fmi3 import FMU3Slave
from fmpy import calloc, free
from fmpy.validation import validate_fmu

OMEGA = 3.0  # rad/s, about the drum axis (y)


def spin_input(version, t_reverse, t_end):
    """Drum angular velocity +OMEGA until t_reverse, then -OMEGA."""
    rows = [(0.0, OMEGA), (t_reverse, OMEGA), (t_reverse, -OMEGA), (t_end, -OMEGA)]
    if version == 2:
        dtype = [("time", np.float64), ("drum.angular_velocity[2]", np.float64)]
        return np.array(rows, dtype=dtype)
    dtype = [("time", np.float64), ("drum.angular_velocity", np.float64, (3,))]
    return np.array([(t, [0.0, w, 0.0]) for t, w in rows], dtype=dtype)


def torque_y(result, version):
    if version == 2:
        return result["drum.torque[2]"]
    return result["drum.torque"][:, 1]


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scene", ["drum", "tube", "fluid"])
def test_fmpy_validation_finds_no_problem(fmus, scene, version):
    assert validate_fmu(str(fmus[(scene, version)])) == []


@pytest.mark.parametrize("version", [2, 3])
def test_drum_torque_follows_the_rotation_input(fmus, version):
    out = ["drum.torque[2]" if version == 2 else "drum.torque", "particles", "kinetic_energy"]
    kwargs = dict(stop_time=0.6, output_interval=0.02, output=out,
                  start_values={"dt": 2e-5}, input=spin_input(version, 0.3, 0.6))
    empty = simulate_fmu(str(fmus[("empty_drum", version)]), **kwargs)
    assert np.all(torque_y(empty, version) == 0.0)
    full = simulate_fmu(str(fmus[("drum", version)]), **kwargs)
    assert np.all(full["particles"] == 96)
    tau = torque_y(full, version)
    t = full["time"]
    # The bed lifted by the drum pulls back: the torque opposes the rotation once the
    # bed has been carried up, and changes sign when the rotation reverses.
    forward = tau[(t > 0.15) & (t <= 0.3)].mean()
    backward = tau[t > 0.45].mean()
    assert forward < -1e-4, tau
    assert backward > 1e-4, tau


def slave(fmu_path, version, unzipdir, name="talus", logger=None):
    """An FMU slave unzipped into `unzipdir` (a test's tmp_path: pytest removes it with
    its old runs, where fmpy's own temporary directory would stay behind)."""
    md = read_model_description(str(fmu_path))
    unzipped = extract(str(fmu_path), unzipdir=str(unzipdir))
    cls = FMU2Slave if version == 2 else FMU3Slave
    token = md.guid
    s = cls(guid=token, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name)
    return md, unzipped, s


class Log:
    """Captures the FMU's log messages (FMI 2 callbacks or FMI 3 logMessage)."""

    def __init__(self):
        self.messages = []

    def fmi2(self):
        def logger(env, name, status, category, message):
            self.messages.append((status, message.decode()))
        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        return cb

    def fmi3(self):
        def log_message(env, status, category, message):
            self.messages.append((status, message.decode()))
        return log_message

    def last(self):
        return self.messages[-1][1] if self.messages else ""


def start(version, s, log):
    if version == 2:
        s.instantiate(callbacks=log.fmi2())
        s.setupExperiment(startTime=0.0)
    else:
        s.instantiate(logMessage=log.fmi3())
    s.enterInitializationMode()
    s.exitInitializationMode()


def vrs(md, *names):
    by_name = {v.name: v.valueReference for v in md.modelVariables}
    return [by_name[n] for n in names]


def drum_io(md, version):
    if version == 2:
        return (vrs(md, "drum.angular_velocity[2]"), vrs(md, "drum.torque[1]", "drum.torque[2]",
                "drum.torque[3]", "drum.force[1]", "drum.force[2]", "drum.force[3]", "kinetic_energy"))
    return vrs(md, "drum.angular_velocity"), vrs(md, "drum.torque", "drum.force", "kinetic_energy")


def set_spin(s, version, vr, omega):
    if version == 2:
        s.setReal(vr, [omega])
    else:
        s.setFloat64(vr, [0.0, omega, 0.0])


def outputs(s, version, vr):
    return s.getReal(vr) if version == 2 else s.getFloat64(vr, 7)


@pytest.mark.parametrize("version", [2, 3])
def test_rollback_and_serialised_states_give_identical_outputs(fmus, version, tmp_path):
    md, unzipped, s = slave(fmus[("drum", version)], version, tmp_path / "first")
    log = Log()
    start(version, s, log)
    spin, out = drum_io(md, version)
    set_spin(s, version, spin, OMEGA)
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.05)
    if version == 2:
        state = s.getFMUstate()
        blob = s.serializeFMUstate(state)
    else:
        state = s.getFMUState()
        blob = s.serializeFMUState(state)
    s.doStep(currentCommunicationPoint=0.05, communicationStepSize=0.05)
    first = outputs(s, version, out)
    (s.setFMUstate if version == 2 else s.setFMUState)(state)
    s.doStep(currentCommunicationPoint=0.05, communicationStepSize=0.05)
    assert outputs(s, version, out) == first
    (s.freeFMUstate if version == 2 else s.freeFMUState)(state)
    s.terminate()
    s.freeInstance()

    # Bytes into a new instance.
    md, unzipped2, s2 = slave(fmus[("drum", version)], version, tmp_path / "second", name="second")
    start(version, s2, Log())
    restored = s2.deSerializeFMUstate(blob) if version == 2 else s2.deserializeFMUState(blob)
    (s2.setFMUstate if version == 2 else s2.setFMUState)(restored)
    s2.doStep(currentCommunicationPoint=0.05, communicationStepSize=0.05)
    assert outputs(s2, version, out) == first
    s2.terminate()
    s2.freeInstance()


def test_the_fmu_and_the_native_c_api_give_the_same_numbers(fmus, library, tmp_path):
    md, unzipped, s = slave(fmus[("drum", 2)], 2, tmp_path / "fmu")
    start(2, s, Log())
    spin, out = drum_io(md, 2)
    lib = ctypes.CDLL(str(library))
    lib.talus_create.restype = ctypes.c_void_p
    lib.talus_create.argtypes = [ctypes.c_char_p]
    c = lib.talus_create(os.path.join(unzipped, "resources", "scene.toml").encode())
    assert c, lib.talus_last_error
    handle = ctypes.c_void_p(c)
    assert lib.talus_initialize(handle, ctypes.c_double(0.0)) == 0
    zero = (ctypes.c_double * 3)(0, 0, 0)
    f = (ctypes.c_double * 3)()
    m = (ctypes.c_double * 3)()
    t = 0.0
    for k, omega in enumerate([OMEGA, OMEGA, -OMEGA, 0.5 * OMEGA]):
        s.setReal(spin, [omega])
        assert lib.talus_set_wall_velocity(handle, ctypes.c_size_t(0), zero,
                                           (ctypes.c_double * 3)(0, omega, 0)) == 0
        h = 0.013 + 0.01 * k
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        assert lib.talus_step(handle, ctypes.c_double(t), ctypes.c_double(h)) == 0
        t += h
        assert lib.talus_get_wall_force(handle, ctypes.c_size_t(0), f, m) == 0
        fmu = s.getReal(out)
        assert fmu[:3] == list(m) and fmu[3:6] == list(f), (fmu, list(m), list(f))
    lib.talus_free(handle)
    s.terminate()
    s.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_misuse_gets_an_error_status_and_a_logged_message(fmus, version, tmp_path):
    md, unzipped, s = slave(fmus[("drum", version)], version, tmp_path / "fmu")
    log = Log()
    spin, out = drum_io(md, version)
    get = s.getReal if version == 2 else s.getFloat64
    if version == 2:
        s.instantiate(callbacks=log.fmi2())
        s.setupExperiment(startTime=0.0)
    else:
        s.instantiate(logMessage=log.fmi3())

    def refused(call, *words):
        with pytest.raises(FMICallException):
            call()
        for w in words:
            assert w in log.last(), log.messages

    refused(lambda: s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01), "instantiated")
    refused(lambda: get(out[-1:]), "getting an output")  # kinetic_energy
    s.enterInitializationMode()
    s.exitInitializationMode()
    refused(lambda: set_spin(s, version, spin, float("nan")), "not finite")
    refused(lambda: set_spin(s, version, spin, float("inf")), "not finite")
    refused(lambda: s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.0), "positive")
    refused(lambda: s.doStep(currentCommunicationPoint=0.0, communicationStepSize=-0.01), "positive")
    refused(lambda: get([10_000]), "unknown value reference")
    # Nothing changed: the next valid step works from time 0.
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    s.terminate()
    s.freeInstance()

    # A wrong guid, and resources without the scene: instantiation fails with a message.
    for token, directory, words in [("{not-the-guid}", unzipped, "does not match"),
                                    (md.guid, str(tmp_path), "scene.toml")]:
        os.makedirs(os.path.join(directory, "resources"), exist_ok=True)
        if not os.path.exists(os.path.join(directory, "binaries")):
            shutil.copytree(os.path.join(unzipped, "binaries"), os.path.join(directory, "binaries"))
        bad = (FMU2Slave if version == 2 else FMU3Slave)(
            guid=token, unzipDirectory=directory, modelIdentifier="talus", instanceName="bad")
        log = Log()
        with pytest.raises(Exception):
            if version == 2:
                bad.instantiate(callbacks=log.fmi2())
            else:
                bad.instantiate(logMessage=log.fmi3())
        assert words in log.last(), log.messages
        bad.freeLibrary()


@pytest.mark.parametrize("version", [2, 3])
def test_a_time_step_far_above_the_suggested_one_warns_and_diverges_with_an_error(fmus, version, tmp_path):
    # dt = 5e-3 s, 230 times the suggested step: the same warning as `talus check`
    # is logged at initialisation, and the first step, whose energy balance breaks,
    # is refused and leaves the state as it was.
    md, unzipped, s = slave(fmus[("drum", version)], version, tmp_path / "fmu")
    log = Log()
    if version == 2:
        s.instantiate(callbacks=log.fmi2())
        s.setupExperiment(startTime=0.0)
        s.setReal(vrs(md, "dt"), [5e-3])
    else:
        s.instantiate(logMessage=log.fmi3())
        s.setFloat64(vrs(md, "dt"), [5e-3])
    s.enterInitializationMode()
    warned = [m for status, m in log.messages if status == 1]
    assert len(warned) == 1 and "above the suggested" in warned[0], log.messages
    s.exitInitializationMode()
    spin, out = drum_io(md, version)
    set_spin(s, version, spin, OMEGA)
    before = outputs(s, version, out)
    with pytest.raises(FMICallException):
        s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.05)
    assert "energy balance" in log.last(), log.messages
    assert outputs(s, version, out) == before
    s.terminate()
    s.freeInstance()


def threads():
    return len(os.listdir("/proc/self/task"))


@pytest.mark.parametrize("version", [2, 3])
def test_the_fmu_simulates_again_and_again_in_one_process(fmus, version):
    before = threads()
    results = []
    for _ in range(3):
        r = simulate_fmu(str(fmus[("drum", version)]), stop_time=0.05, output_interval=0.01,
                         start_values={"threads": 2},
                         output=["kinetic_energy"])
        results.append(r["kinetic_energy"][-1])
        # No worker thread of the library outlives its instance.
        assert threads() == before
    assert results[0] == results[1] == results[2] > 0.0


@pytest.mark.parametrize("version", [2, 3])
def test_a_pose_driven_tube_follows_its_pose_input(fmus, version, tmp_path):
    """Tap the tube: lift it 1 mm and put it back; the pellets feel it."""
    md, unzipped, s = slave(fmus[("tube", version)], version, tmp_path / "fmu")
    start(version, s, Log())
    if version == 2:
        z = vrs(md, "tube.position[3]")
        fz = vrs(md, "tube.force[3]")
        set_z = lambda v: s.setReal(z, [v])
        get_fz = lambda: s.getReal(fz)[0]
    else:
        pos = vrs(md, "tube.position")
        f = vrs(md, "tube.force")
        set_z = lambda v: s.setFloat64(pos, [0.0, 0.0, v])
        get_fz = lambda: s.getFloat64(f, 3)[2]
    t = 0.0
    for _ in range(10):  # settle for 20 ms
        s.doStep(currentCommunicationPoint=t, communicationStepSize=0.002)
        t += 0.002
    resting = get_fz()
    set_z(0.001)
    s.doStep(currentCommunicationPoint=t, communicationStepSize=0.002)
    t += 0.002
    lifting = get_fz()
    # Lifting the tube pushes the pellets up: the force on the tube grows downwards.
    assert resting < 0.0 and lifting < resting, (resting, lifting)
    s.terminate()
    s.freeInstance()
