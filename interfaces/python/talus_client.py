"""A small client for a talus scene served over zenoh (`talus serve`).

    from talus_client import connect
    with connect("talus/drum", "tcp/127.0.0.1:7447", proto_dir="gen") as drum:
        print(drum.info().walls)
        reply = drum.step(0.0, 0.01, walls={"drum": {"angular_velocity": (0, 3.0, 0)}})
        print(reply.walls[0].torque.y)

`proto_dir` holds the Python classes generated from proto/talus/v1/talus.proto
(`talus proto --python-out DIR`). Needs eclipse-zenoh and protobuf
(interfaces/python/requirements.txt).
"""
import importlib.util
import json
import sys
import time
from pathlib import Path

import zenoh


class TalusError(RuntimeError):
    """A request the node answered with an error status."""


_MODULE = "talus_v1_talus_pb2"


def _messages(proto_dir):
    """The message classes generated into `proto_dir` (talus/v1/talus_pb2.py), loaded
    from their file: the `talus` Python package, when installed, owns the name
    `talus`, so they cannot be imported as `talus.v1.talus_pb2`."""
    if _MODULE in sys.modules:
        return sys.modules[_MODULE]
    path = Path(proto_dir or ".") / "talus" / "v1" / "talus_pb2.py"
    if not path.is_file():
        raise ImportError(f"no {path}: generate the message classes first with "
                          "talus proto --python-out DIR, and pass proto_dir=DIR")
    spec = importlib.util.spec_from_file_location(_MODULE, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[_MODULE] = module
    spec.loader.exec_module(module)
    return module


class Client:
    """One connection to one served scene."""

    def __init__(self, key, connect=None, proto_dir=None, timeout=60.0):
        self.pb = _messages(proto_dir)
        self.key = key.rstrip("/")
        self.timeout = timeout
        conf = zenoh.Config()
        conf.insert_json5("mode", '"peer"')
        conf.insert_json5("scouting/multicast/enabled", "false")
        if connect:
            endpoints = [connect] if isinstance(connect, str) else list(connect)
            conf.insert_json5("connect/endpoints", json.dumps(endpoints))
        self.session = zenoh.open(conf)
        self._subscribers = []

    def close(self):
        for s in self._subscribers:
            s.undeclare()
        self._subscribers = []
        self.session.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _query(self, endpoint, request, reply_type, check=True):
        payload = request if isinstance(request, (bytes, bytearray)) else request.SerializeToString()
        replies = self.session.get(f"{self.key}/{endpoint}", payload=bytes(payload), timeout=self.timeout)
        for r in replies:
            if r.ok is None:
                raise TalusError(f"{endpoint}: zenoh error reply")
            reply = reply_type()
            reply.ParseFromString(r.ok.payload.to_bytes())
            if check and reply.status != self.pb.STATUS_OK:
                raise TalusError(f"{endpoint}: {reply.error}")
            return reply
        raise TimeoutError(f"no reply from {self.key}/{endpoint} within {self.timeout} s")

    def wait_until_served(self, timeout=30.0):
        """Waits for the node's liveliness token."""
        end = time.time() + timeout
        while time.time() < end:
            if list(self.session.liveliness().get(self.key, timeout=1.0)):
                return
            time.sleep(0.1)
        raise TimeoutError(f"{self.key} is not served")

    def info(self):
        return self._query("info", self.pb.InfoRequest(), self.pb.InfoReply)

    def walls(self, names=(), facet_forces=False):
        req = self.pb.WallsRequest(walls=list(names), facet_forces=facet_forces)
        return self._query("walls", req, self.pb.WallsReply)

    def step(self, time, step, walls=None, check=True, fluid_velocity=None, pressure_gradient=None):
        """Steps from `time` by `step`. `walls` maps a wall name to
        {"velocity": (x, y, z), "angular_velocity": (x, y, z)} or
        {"position": (x, y, z), "orientation": (w, x, y, z)}. `fluid_velocity` and
        `pressure_gradient` (scenes with [fluid]): x y z per cell, flat, in the grid's
        order; None leaves the input as it was."""
        req = self.pb.StepRequest(time=time, step=step)
        if fluid_velocity is not None:
            req.fluid.velocity.extend(float(x) for x in fluid_velocity)
        if pressure_gradient is not None:
            req.fluid.pressure_gradient.extend(float(x) for x in pressure_gradient)
        for name, motion in (walls or {}).items():
            m = req.walls.add(wall=name)
            if "position" in motion or "orientation" in motion:
                p = motion.get("position", (0.0, 0.0, 0.0))
                q = motion.get("orientation", (1.0, 0.0, 0.0, 0.0))
                m.pose.position.x, m.pose.position.y, m.pose.position.z = p
                o = m.pose.orientation
                o.w, o.x, o.y, o.z = q
            else:
                v = motion.get("velocity", (0.0, 0.0, 0.0))
                w = motion.get("angular_velocity", (0.0, 0.0, 0.0))
                m.velocity.linear.x, m.velocity.linear.y, m.velocity.linear.z = v
                m.velocity.angular.x, m.velocity.angular.y, m.velocity.angular.z = w
        return self._query("step", req, self.pb.StepReply, check)

    def fluid(self, particles=False):
        """The fluid's grid and per-cell fields (FluidReply); with `particles`, also
        each particle's id, drag, slip and local voidage."""
        return self._query("fluid", self.pb.FluidRequest(particles=particles), self.pb.FluidReply)

    def save(self):
        return self._query("state", self.pb.StateRequest(save=True), self.pb.StateReply).state

    def restore(self, state):
        return self._query("state", self.pb.StateRequest(restore=bytes(state)), self.pb.StateReply)

    def raw(self, endpoint, payload, reply_type):
        """Sends raw bytes (for testing the node's answers to malformed requests)."""
        return self._query(endpoint, payload, reply_type, check=False)

    def subscribe(self, callback):
        """Calls `callback(StepReply)` for every step the node publishes."""
        def on_sample(sample):
            reply = self.pb.StepReply()
            reply.ParseFromString(sample.payload.to_bytes())
            callback(reply)
        self._subscribers.append(self.session.declare_subscriber(f"{self.key}/forces", on_sample))


def connect(key, connect=None, proto_dir=None, timeout=60.0):
    """Opens a client session to the scene served under `key`."""
    return Client(key, connect, proto_dir, timeout)
