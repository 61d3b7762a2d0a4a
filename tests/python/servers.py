"""`talus serve` nodes for the tests: in one process or under `mpirun -np N`, on a
loopback port of their own (a block of ports per test process)."""
import os
import signal
import subprocess
import sys
import time

from conftest import ROOT, TALUS

sys.path.insert(0, str(ROOT / "interfaces" / "python"))
from talus_client import connect  # noqa: E402

PORT_BASE = 17500 + (os.getpid() % 150) * 32
_ports = iter(range(PORT_BASE, PORT_BASE + 32))


def launcher(ranks):
    """The command line that starts `ranks` processes of talus (one: talus itself)."""
    if ranks == 1:
        return [], None
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return ["mpirun", "--oversubscribe", "-np", str(ranks)], env


class Server:
    def __init__(self, scene, out, ranks=1):
        self.port = next(_ports)
        self.endpoint = f"tcp/127.0.0.1:{self.port}"
        self.key = f"talus/test{self.port}"
        self.out = out
        self.ranks = ranks
        prefix, env = launcher(ranks)
        self.process = subprocess.Popen(
            prefix + [str(TALUS), "serve", str(scene), "--key", self.key, "--listen",
                      self.endpoint, "--out", str(out)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)

    def client(self, proto_dir, timeout=60.0):
        deadline = time.time() + 60
        while True:
            c = connect(self.key, self.endpoint, proto_dir, timeout)
            try:
                c.wait_until_served(timeout=2.0)
                return c
            except TimeoutError:
                c.close()
                if time.time() > deadline or self.process.poll() is not None:
                    raise RuntimeError(f"server did not come up: {self.process.communicate()}")

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.process.wait(timeout=60)

    def kill(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
