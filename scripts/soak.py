"""Soak tests: a long stretch of wall-clock time of stepping, watching resident memory
and threads.

    python scripts/soak.py fmu   drum.fmu        --minutes 30 --out soak_fmu.csv
    python scripts/soak.py serve --talus target/release/talus --minutes 30 --out soak_serve.csv

`fmu`: one instance of the drum FMU (FMI 2) stepped by 10 ms at 30 rpm, its state
saved, serialised, restored and freed every 50 steps, in this process: the RSS and the
threads of this process are sampled every 10 s.

`serve`: `talus serve` of the drum scene in a child process; a client connects, steps
20 times, saves and restores the state, and disconnects, again and again: the RSS and
the threads of the server are sampled every 10 s.

Prints, and writes to --out, the samples (elapsed s, RSS MiB, threads, simulated s,
steps), then a summary line: RSS after the first minute (warm-up) and at the end, the
largest after it, and the thread counts seen after it. Exit status 1 when the RSS grew
by more than 10 % after the first minute or the threads piled up (the second half of
the run holding more than the first).
"""
import argparse
import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OMEGA = 30 * 2 * math.pi / 60


def status(pid):
    """(RSS in MiB, threads) of a process."""
    rss, threads = 0.0, 0
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1]) / 1024
            elif line.startswith("Threads:"):
                threads = int(line.split()[1])
    return rss, threads


def soak_fmu(args, sample):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(args.target)
    unzipped = extract(args.target)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="soak")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["drum.angular_velocity[2]"]], [OMEGA])
    t, steps, h = 0.0, 0, 0.01
    start = time.monotonic()
    while not sample(os.getpid(), t, steps, start):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        steps += 1
        if steps % 50 == 0:
            state = fmu.getFMUstate()
            blob = fmu.serializeFMUstate(state)
            fmu.freeFMUstate(state)
            again = fmu.deSerializeFMUstate(blob)
            fmu.setFMUstate(again)
            fmu.freeFMUstate(again)
        fmu.getReal([vr["drum.torque[2]"], vr["kinetic_energy"]])
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


def soak_serve(args, sample):
    sys.path.insert(0, str(ROOT / "interfaces" / "python"))
    from talus_client import connect

    work = Path(tempfile.mkdtemp(prefix="talus-soak-"))
    subprocess.run([args.talus, "proto", "--python-out", str(work / "gen")], check=True)
    endpoint = "tcp/127.0.0.1:7461"
    server = subprocess.Popen([args.talus, "serve", str(ROOT / "examples/drum_fmu/drum.toml"),
                               "--key", "talus/soak", "--listen", endpoint],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        t, steps = 0.0, 0
        start = time.monotonic()
        while not sample(server.pid, t, steps, start):
            with connect("talus/soak", endpoint, str(work / "gen")) as drum:
                drum.wait_until_served()
                t = drum.info().time
                for _ in range(20):
                    reply = drum.step(t, 0.01, {"drum": {"angular_velocity": (0.0, OMEGA, 0.0)}})
                    t = reply.time
                    steps += 1
                state = drum.save()
                drum.restore(state)
    finally:
        server.terminate()
        server.wait(timeout=30)
        shutil.rmtree(work, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=["fmu", "serve"])
    parser.add_argument("target", nargs="?", help="the FMU (mode fmu)")
    parser.add_argument("--talus", default=str(ROOT / "target/release/talus"))
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()

    rows = []
    last = [-1e9]

    def sample(pid, t, steps, start):
        """Records a sample every 10 s; True when the time is up."""
        elapsed = time.monotonic() - start
        if elapsed - last[0] >= 10.0:
            last[0] = elapsed
            rss, threads = status(pid)
            rows.append((round(elapsed, 1), round(rss, 1), threads, round(t, 3), steps))
            print(*rows[-1], flush=True)
        return elapsed >= args.minutes * 60

    (soak_fmu if args.mode == "fmu" else soak_serve)(args, sample)

    if args.out:
        with open(args.out, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["elapsed_s", "rss_mib", "threads", "simulated_s", "steps"])
            w.writerows(rows)
    # The first minute is warm-up (the server starting, the first connection).
    after_minute = next((r for r in rows if r[0] >= 60), rows[-1])
    steady = [r for r in rows if r[0] >= after_minute[0]]
    peak = max(r[1] for r in steady)
    threads = [r[2] for r in steady]
    half = len(threads) // 2
    growth = rows[-1][1] / after_minute[1] - 1
    # Threads may come and go (a runtime's blocking pool); they must not pile up: the
    # second half of the run holds no more than the first.
    piling = max(threads[half:]) > max(threads[:half] or threads)
    print(f"{args.mode}: {rows[-1][0] / 60:.1f} min, {rows[-1][4]} steps, {rows[-1][3]:.1f} s "
          f"simulated; RSS {after_minute[1]:.1f} MiB after 1 min, {rows[-1][1]:.1f} MiB at the "
          f"end ({growth:+.1%}), largest {peak:.1f} MiB; threads {min(threads)}-{max(threads)} "
          f"(first half up to {max(threads[:half] or threads)}, second half up to "
          f"{max(threads[half:])})")
    sys.exit(0 if growth < 0.10 and not piling else 1)


if __name__ == "__main__":
    main()
