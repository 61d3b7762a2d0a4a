"""The zenoh node (`talus serve`) driven by the Python client: forces equal to the
component's, published steps in order, bad requests answered, disconnects, two
clients, and a clean stop on SIGTERM. Every drum test and the fluid test run
against one process and against `mpirun -np 2 talus serve` (rank 0 the node, both
ranks stepping): the client cannot tell them apart, except that wall forces and
momentum sources summed over two ranks agree with one process's to round-off. Loopback only, one port per test."""
import ctypes
import sys
import threading
import time

import pytest

from conftest import ROOT, SCENES, TALUS
from servers import Server

sys.path.insert(0, str(ROOT / "interfaces" / "python"))
from talus_client import TalusError  # noqa: E402


@pytest.fixture(params=[1, 2], ids=["one-process", "mpirun-np-2"])
def drum_server(request, tmp_path):
    server = Server(SCENES["drum"], tmp_path / "out", ranks=request.param)
    yield server
    server.kill()


def spin(omega):
    return {"drum": {"angular_velocity": (0.0, omega, 0.0)}}


def test_the_client_gets_the_forces_of_the_component_stepped_directly(drum_server, proto_dir):
    with drum_server.client(proto_dir) as client:
        info = client.info()
        assert [w.name for w in info.walls] == ["drum"] and info.walls[0].drive == "velocity"
        assert any(v.name == "drum.torque" and v.unit == "N.m" for v in info.variables)
        lib = ctypes.CDLL(str(TALUS.with_name("libtalus.so")))
        lib.talus_create.restype = ctypes.c_void_p
        handle = ctypes.c_void_p(lib.talus_create(str(SCENES["drum"]).encode()))
        assert handle.value and lib.talus_initialize(handle, ctypes.c_double(0.0)) == 0
        f, m = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        t = 0.0
        for k, omega in enumerate([3.0, 3.0, -3.0, 1.5]):
            h = 0.013 + 0.01 * k
            reply = client.step(t, h, spin(omega))
            assert lib.talus_set_wall_velocity(handle, ctypes.c_size_t(0), (ctypes.c_double * 3)(),
                                               (ctypes.c_double * 3)(0.0, omega, 0.0)) == 0
            assert lib.talus_step(handle, ctypes.c_double(t), ctypes.c_double(h)) == 0
            t += h
            assert lib.talus_get_wall_force(handle, ctypes.c_size_t(0), f, m) == 0
            w = reply.walls[0]
            assert reply.time == t and reply.sequence == k + 1
            torque, force = [w.torque.x, w.torque.y, w.torque.z], [w.force.x, w.force.y, w.force.z]
            if drum_server.ranks == 1:
                assert torque == list(m) and force == list(f)
            else:
                # Sums grouped by rank: round-off of the largest component.
                for got, want in [(torque, list(m)), (force, list(f))]:
                    scale = max(abs(x) for x in want)
                    assert all(abs(a - b) <= 1e-12 * scale for a, b in zip(got, want)), (got, want)
            assert reply.globals.particles == 96
        lib.talus_free(handle)
        mesh = client.walls(facet_forces=True).walls[0]
        assert len(mesh.vertices) % 3 == 0 and len(mesh.facet_forces) == len(mesh.triangles)
        # Save, step, restore, step: the same reply.
        state = client.save()
        a = client.step(t, 0.01, spin(3.0))
        client.restore(state)
        b = client.step(t, 0.01, spin(3.0))
        assert a.walls[0].torque == b.walls[0].torque and a.time == b.time


def test_a_subscriber_receives_every_step_in_order(drum_server, proto_dir):
    with drum_server.client(proto_dir) as stepper, drum_server.client(proto_dir) as watcher:
        seen = []
        done = threading.Event()

        def on_step(reply):
            seen.append((reply.sequence, reply.time))
            if len(seen) == 20:
                done.set()

        watcher.subscribe(on_step)
        time.sleep(0.5)
        t = 0.0
        for _ in range(20):
            stepper.step(t, 0.002, spin(3.0))
            t += 0.002
        assert done.wait(30), seen
        assert [s for s, _ in seen] == list(range(1, 21))
        assert all(b > a for (_, a), (_, b) in zip(seen, seen[1:]))


def test_bad_requests_get_error_replies_and_change_nothing(drum_server, proto_dir):
    with drum_server.client(proto_dir) as client:
        pb = client.pb
        client.step(0.0, 0.005, spin(3.0))
        bad = [
            ("step", b"\xff\xff\xff\xff", pb.StepReply, "malformed"),
            ("walls", b"\x0a\xff", pb.WallsReply, "malformed"),
            ("state", b"\x12\x05abc", pb.StateReply, "malformed"),
            ("state", pb.StateRequest(restore=b"garbage").SerializeToString(), pb.StateReply, "not a talus state"),
            ("state", b"", pb.StateReply, "save or restore"),
        ]
        for endpoint, payload, reply_type, words in bad:
            reply = client.raw(endpoint, payload, reply_type)
            assert reply.status == pb.STATUS_ERROR and words in reply.error, (endpoint, reply)
        for h in (0.0, float("nan"), -0.01):
            reply = client.step(0.005, h, spin(3.0), check=False)
            assert reply.status == pb.STATUS_ERROR and "positive" in reply.error
        reply = client.step(0.005, 0.01, {"lid": {"angular_velocity": (0, 1, 0)}}, check=False)
        assert reply.status == pb.STATUS_ERROR and "lid" in reply.error
        reply = client.step(0.005, 0.01, {"drum": {"position": (0, 0, 0)}}, check=False)
        assert reply.status == pb.STATUS_ERROR and "not driven" in reply.error
        reply = client.step(0.005, 0.01, spin(float("inf")), check=False)
        assert reply.status == pb.STATUS_ERROR and "not finite" in reply.error
        reply = client.step(0.5, 0.01, spin(3.0), check=False)
        assert reply.status == pb.STATUS_ERROR and "starts at" in reply.error
        with pytest.raises(TalusError):
            client.walls(["lid"])
        # Nothing changed: the next valid step goes on from 0.005 with sequence 2.
        reply = client.step(0.005, 0.005, spin(3.0))
        assert reply.time == 0.01 and reply.sequence == 2


def test_clients_that_leave_or_take_turns(drum_server, proto_dir):
    first = drum_server.client(proto_dir)
    # A long step whose client goes away before the reply.
    replies = first.session.get(f"{drum_server.key}/step",
                                payload=first.pb.StepRequest(time=0.0, step=0.2).SerializeToString(),
                                timeout=0.05)
    first.close()
    del replies
    with drum_server.client(proto_dir) as a, drum_server.client(proto_dir) as b:
        t = a.info().time
        assert abs(t - 0.2) < 1e-12  # the abandoned step was still taken
        for k in range(4):
            client = a if k % 2 == 0 else b
            reply = client.step(t, 0.01, spin(3.0))
            t += 0.01
            assert reply.time == t
        assert b.info().time == t


def test_sigterm_stops_the_node_cleanly_with_its_outputs(drum_server, proto_dir):
    with drum_server.client(proto_dir) as client:
        t = 0.0
        for _ in range(3):
            client.step(t, 0.02, spin(3.0))
            t += 0.02
    status = drum_server.stop()
    # Open MPI's mpirun exits with 1 after it forwarded a SIGTERM to the ranks, however
    # they ended; what they wrote says how.
    assert status == 0 or drum_server.ranks > 1
    stdout = drum_server.process.stdout.read()
    assert "stopped at t = 0.06" in stdout, stdout
    walls = (drum_server.out / "walls.csv").read_text().splitlines()
    assert walls[0].startswith("time,drum_fx") and len(walls) >= 7
    assert (drum_server.out / "particles.pvd").is_file()


@pytest.mark.parametrize("ranks", [1, 2], ids=["one-process", "mpirun-np-2"])
def test_the_fluid_fields_over_zenoh_equal_the_c_apis(tmp_path, proto_dir, ranks):
    server = Server(SCENES["fluid"], tmp_path / "out", ranks=ranks)
    try:
        with server.client(proto_dir) as client:
            lib = ctypes.CDLL(str(TALUS.with_name("libtalus.so")))
            lib.talus_create.restype = ctypes.c_void_p
            handle = ctypes.c_void_p(lib.talus_create(str(SCENES["fluid"]).encode()))
            assert handle.value and lib.talus_initialize(handle, ctypes.c_double(0.0)) == 0
            cells = 54
            t, h = 0.0, 3e-4
            for k in range(2):
                u = [x for c in range(cells) for x in (0.01 * c, -0.1 * k, 2.5 - 0.02 * c)]
                client.step(t, h, fluid_velocity=u)
                assert lib.talus_set_real(handle, b"fluid.velocity", (ctypes.c_double * len(u))(*u),
                                          ctypes.c_size_t(len(u))) == 0
                assert lib.talus_step(handle, ctypes.c_double(t), ctypes.c_double(h)) == 0
                t += h
            fields = client.fluid()
            assert list(fields.grid.counts) == [3, 3, 6] and fields.time == t
            for name, size in [("momentum_source", 3 * cells), ("solid_fraction", cells),
                               ("particle_velocity", 3 * cells), ("velocity", 3 * cells)]:
                out = (ctypes.c_double * size)()
                assert lib.talus_get_real(handle, f"fluid.{name}".encode(), out,
                                          ctypes.c_size_t(size)) == 0
                if name == "momentum_source":
                    # Each rank sums its particles' drag: equal to round-off.
                    scale = max(abs(x) for x in out)
                    assert all(abs(a - b) <= 1e-12 * scale
                               for a, b in zip(getattr(fields, name), out)), name
                else:
                    assert list(getattr(fields, name)) == list(out), name
            assert sum(fields.momentum_source[2::3]) < 0.0
            assert len(fields.particle_ids) == 0, "per particle only when asked"
            # Per particle: the same bits as the C API's.
            each = client.fluid(particles=True)
            n = ctypes.c_size_t()
            assert lib.talus_get_particle_count(handle, ctypes.byref(n)) == 0
            n = n.value
            ids, voidage = (ctypes.c_uint64 * n)(), (ctypes.c_double * n)()
            drag, slip = (ctypes.c_double * (3 * n))(), (ctypes.c_double * (3 * n))()
            assert lib.talus_get_particle_fluid(handle, ctypes.c_size_t(n), ids, drag, slip,
                                                voidage) == 0
            assert n > 50 and list(each.particle_ids) == list(ids)
            assert list(each.particle_drag) == list(drag)
            assert list(each.particle_slip) == list(slip)
            assert list(each.particle_voidage) == list(voidage)
            assert all(0.0 < e <= 1.0 for e in voidage)
            with pytest.raises(TalusError, match="162"):
                client.step(t, h, fluid_velocity=[1.0, 2.0])
            assert client.fluid().time == t
            lib.talus_free(handle)
    finally:
        # Open MPI's mpirun exits with 1 after it forwarded the SIGTERM.
        assert server.stop() == 0 or ranks > 1
