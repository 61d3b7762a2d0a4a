"""A proxy FMU (`talus fmu --remote KEY`) under fmpy: every FMI call forwarded over
zenoh to a `talus serve` node on two MPI ranks. It validates, simulates with the
outputs of the local FMU (wall torques summed over two ranks: to round-off), saves
and restores states on the node, and a node that is gone or never came is an FMI
error with a logged message within the timeout, never a hang."""
import subprocess
import time

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from conftest import SCENES, TALUS
from servers import Server
from test_fmu import (Log, drum_io, outputs, set_spin, slave, spin_input, start, torque_y,
                      vrs)


def proxy(server, version, path, timeout=60.0):
    """The proxy FMU of the drum for `server`."""
    subprocess.run([str(TALUS), "fmu", str(SCENES["drum"]), "-o", str(path), "--fmi", str(version),
                    "--remote", server.key, "--connect", server.endpoint,
                    "--timeout", str(timeout)], check=True, capture_output=True)
    return path


@pytest.fixture
def ranks_server(tmp_path, proto_dir):
    server = Server(SCENES["drum"], tmp_path / "out", ranks=2)
    server.client(proto_dir).close()  # until it serves
    yield server
    server.kill()


@pytest.mark.parametrize("version", [2, 3])
def test_the_proxy_fmu_simulates_on_two_ranks_as_the_local_fmu(fmus, ranks_server, version, tmp_path):
    fmu = proxy(ranks_server, version, tmp_path / f"proxy{version}.fmu")
    assert validate_fmu(str(fmu)) == []
    out = ["drum.torque[2]" if version == 2 else "drum.torque", "particles", "kinetic_energy"]
    kwargs = dict(stop_time=0.1, output_interval=0.02, output=out,
                  start_values={"dt": 2e-5}, input=spin_input(version, 0.05, 0.1))
    remote = simulate_fmu(str(fmu), **kwargs)
    local = simulate_fmu(str(fmus[("drum", version)]), **kwargs)
    assert list(remote["time"]) == list(local["time"]) and len(local["time"]) >= 6
    assert np.all(remote["particles"] == 96)
    for got, want in [(torque_y(remote, version), torque_y(local, version)),
                      (remote["kinetic_energy"], local["kinetic_energy"])]:
        scale = np.abs(want).max()
        assert scale > 0 and np.all(np.abs(got - want) <= 1e-12 * scale), (got, want)
    # The master terminated the node's component; the node still stops cleanly.
    ranks_server.stop()
    out, err = ranks_server.process.communicate()
    assert "stopped at t = 0.1" in out and "MPI_ABORT" not in err, (out, err)


def test_states_of_the_node_roll_back_through_the_proxy(ranks_server, tmp_path):
    fmu = proxy(ranks_server, 2, tmp_path / "proxy.fmu")
    md, _, s = slave(fmu, 2, tmp_path / "unzipped")
    log = Log()
    start(2, s, log)
    spin, out = drum_io(md, 2)
    set_spin(s, 2, spin, 3.0)
    s.doStep(0.0, 0.02)
    state = s.getFMUstate()
    s.doStep(0.02, 0.02)
    first = outputs(s, 2, out)
    s.setFMUstate(state)
    assert s.getReal(vrs(md, "time")) == [0.02]
    s.doStep(0.02, 0.02)
    assert outputs(s, 2, out) == first
    # Serialised, the same.
    data = s.serializeFMUstate(state)
    s.setFMUstate(s.deSerializeFMUstate(data))
    s.doStep(0.02, 0.02)
    assert outputs(s, 2, out) == first
    s.freeFMUstate(state)
    # The node's errors come back as the call's.
    with pytest.raises(FMICallException):
        s.doStep(0.5, 0.02)
    assert "starts at" in log.last()
    s.terminate()
    s.freeInstance()


def test_a_node_gone_or_never_there_is_an_fmi_error_within_the_timeout(tmp_path, proto_dir):
    server = Server(SCENES["drum"], tmp_path / "out")
    server.client(proto_dir).close()
    fmu = proxy(server, 2, tmp_path / "proxy.fmu", timeout=2.0)
    md, _, s = slave(fmu, 2, tmp_path / "unzipped")
    log = Log()
    start(2, s, log)
    s.doStep(0.0, 0.01)
    server.kill()
    began = time.time()
    with pytest.raises(FMICallException):
        s.doStep(0.01, 0.01)
    assert time.time() - began < 10.0
    assert "no answer from the talus node" in log.last(), log.messages
    s.freeInstance()
    # Never there: instantiation fails, with the reason logged.
    md, _, s = slave(fmu, 2, tmp_path / "again")
    log = Log()
    began = time.time()
    with pytest.raises(Exception):
        s.instantiate(callbacks=log.fmi2())
    assert time.time() - began < 10.0
    assert "no answer from the talus node" in log.last(), log.messages
