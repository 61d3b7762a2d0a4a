#!/usr/bin/env python3
"""talus against LIGGGHTS 3.8.0 on the same sphere pour, runs interleaved.

The scene (talus issue 21): 5000 Hertz spheres (r = 5 mm, Y = 1e7 Pa, nu = 0.3,
e = 0.5, mu = 0.5, rho = 2500 kg/m3) inserted at rest by LIGGGHTS's insert/pack in
the block 0.006-0.194 x 0.006-0.194 x 0.15-0.58 m, poured into an open-top box of
STL walls (box.stl: 0.2 x 0.2 x 0.6 m, floor and four sides), gravity 9.81 m/s2,
dt = 2e-5 s, skin 0.002 m, 50 000 steps (the pour), then 10 000 steps of the settled
bed. LIGGGHTS runs pour.in (pair gran hertz tangential history, wall/gran on the
mesh, nve/sphere); talus runs the same law (`[contact] law = "hertz_mindlin"`) from
the positions LIGGGHTS dumps at step 1, and the settled bed from LIGGGHTS's positions
after the pour, so both codes step the same bed.

Each round runs LIGGGHTS once and talus once per thread count, alternating, so that
the machine's drift falls on both. Figures: particle-steps per second of the stepping
loop (LIGGGHTS's "Loop time", talus's summary.json), over the pour and the settled
bed; the ratio talus / LIGGGHTS on one thread; talus's speed-up on two threads.

    benches/peers/liggghts_pour.py [--install] [--rounds 2] [--threads 1 2]
                                   [--liggghts-procs 1 2]
                                   [--steps 50000] [--settled-steps 10000] [--pgo]

--liggghts-procs 1 2 also runs LIGGGHTS on 2 MPI processes (`mpirun -np 2`, the box
cut across x into one slab per process), interleaved in each round: how far an
established code scales on the same machine, beside talus's threads.

--pgo also builds talus with scripts/build-pgo.sh (profile-guided) and measures
that build beside the plain release build, interleaved in each round.

--install installs the Debian package `liggghts` when it is missing (apt-get, as
root). LIGGGHTS must never be run with `-screen none`: that build crashes with it.
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
DT = 2e-5

TALUS_SCENE = """\
# The pour of benches/peers/pour.in in talus (written by liggghts_pour.py).
[simulation]
dt = {dt}
end_time = {end_time}
gravity = [0.0, 0.0, -9.81]

[contact]
law = "hertz_mindlin"
skin = 0.002

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[shapes.ball]
kind = "sphere"
radius = 0.005

[[wall]]
name = "box"
material = "glass"
geometry = {{ kind = "mesh", file = "{stl}" }}

[[particles]]
kind = "file"
shape = "ball"
material = "glass"
file = "{poses}"

# Frames of points, as LIGGGHTS's dumps (id x y z): icospheres are 45 MB a frame
# of 5000 spheres, written inside talus's timed run.
[output]
frame_interval = {end_time}
csv_interval = {end_time}
spheres = "points"
"""


def last_frame(dump: Path) -> list:
    """Positions of the last frame of a LIGGGHTS `custom id x y z` dump, by id."""
    frames = dump.read_text().split("ITEM: TIMESTEP")
    lines = frames[-1].strip().splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS")) + 1
    rows = sorted((int(l.split()[0]), l.split()[1:4]) for l in lines[start:] if l.strip())
    return [xyz for _, xyz in rows]


def write_poses(positions: list, path: Path) -> None:
    with path.open("w") as f:
        f.write("x,y,z,qw,qx,qy,qz\n")
        for x, y, z in positions:
            f.write(f"{x},{y},{z},1,0,0,0\n")


def liggghts(work: Path, steps: int, settled: int, procs: int = 1) -> dict:
    """Runs the deck on `procs` MPI processes; returns the particle-steps per second
    of the pour and of the settled bed."""
    deck = (HERE / "pour.in").read_text()
    deck = deck.replace("run 49999", f"run {steps - 1}").replace("run 10000", f"run {settled}")
    if procs > 1:
        # Cut the box across x, not along its height (LIGGGHTS's choice for a tall
        # box): the bed settles in the lowest sixth, which a cut along z leaves to one
        # process.
        deck = deck.replace("units           si\n", f"units           si\nprocessors      {procs} 1 1\n")
    (work / "pour.in").write_text(deck)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    command = ["liggghts", "-in", "pour.in", "-var", "dir", str(work), "-var", "stl", str(HERE / "box.stl")]
    if procs > 1:
        command = ["mpirun", "-np", str(procs)] + command
    out = subprocess.run(command, cwd=work, env=env, capture_output=True, text=True, check=True).stdout
    loops = [(float(t), int(s), int(a)) for t, s, a in
             re.findall(rf"Loop time of ([\d.e+-]+) on {procs} procs for (\d+) steps with (\d+) atoms", out)]
    if len(loops) != 4:
        sys.exit(f"LIGGGHTS printed {len(loops)} loop times, expected 4:\n{out[-3000:]}")
    pour = loops[:3]
    return {
        "pour": sum(s * a for _, s, a in pour) / sum(t for t, _, _ in pour),
        "settled": loops[3][1] * loops[3][2] / loops[3][0],
    }


def talus(binary: Path, work: Path, poses: Path, steps: int, threads: int, name: str) -> dict:
    scene = work / f"{name}.toml"
    scene.write_text(TALUS_SCENE.format(dt=DT, end_time=steps * DT, stl=HERE / "box.stl", poses=poses))
    out = work / f"{name}_out"
    shutil.rmtree(out, ignore_errors=True)
    subprocess.run([str(binary), "run", "--quiet", "--threads", str(threads), "--out", str(out), str(scene)],
                   check=True)
    return json.loads((out / "summary.json").read_text())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--install", action="store_true", help="apt-get install liggghts when missing")
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    p.add_argument("--liggghts-procs", type=int, nargs="+", default=[1],
                   help="MPI process counts LIGGGHTS runs on (1 is always run: its dumps start talus)")
    p.add_argument("--steps", type=int, default=50000)
    p.add_argument("--settled-steps", type=int, default=10000)
    p.add_argument("--pgo", action="store_true",
                   help="also measure the profile-guided build of scripts/build-pgo.sh, interleaved")
    args = p.parse_args()
    if shutil.which("liggghts") is None:
        if not args.install:
            sys.exit("liggghts is not installed: run with --install (Debian package liggghts)")
        subprocess.run(["apt-get", "install", "-y", "liggghts"], check=True,
                       env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"))
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    builds = {"talus": ROOT / "target" / "release" / "talus"}
    if args.pgo:
        subprocess.run([str(ROOT / "scripts" / "build-pgo.sh")], cwd=ROOT, check=True,
                       stdout=subprocess.DEVNULL)
        builds["talus pgo"] = ROOT / "target" / "pgo" / "talus"
    work = Path(tempfile.mkdtemp(prefix="talus-peers-"))
    runs = [(f"{name} {t}", binary, t) for t in args.threads for name, binary in builds.items()]
    procs = sorted(set(args.liggghts_procs) - {1})
    results = ({"liggghts": []} | {f"liggghts {n} procs": [] for n in procs}
               | {key: [] for key, _, _ in runs})
    contacts = {}
    for round_ in range(args.rounds):
        results["liggghts"].append(liggghts(work, args.steps, args.settled_steps))
        write_poses(last_frame(work / "start.dump"), work / "start.csv")
        write_poses(last_frame(work / "settled.dump"), work / "settled.csv")
        for n in procs:
            results[f"liggghts {n} procs"].append(liggghts(work, args.steps, args.settled_steps, n))
        for key, binary, t in runs:
            pour = talus(binary, work, work / "start.csv", args.steps, t, "pour")
            settled = talus(binary, work, work / "settled.csv", args.settled_steps, t, "settled")
            results[key].append({"pour": pour["particle_steps_per_s"],
                                 "settled": settled["particle_steps_per_s"]})
            contacts = {"pour end": pour["contacts"], "settled": settled["contacts"]}
        print(f"round {round_ + 1}: " + json.dumps(results), file=sys.stderr)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"machine: {cpu}, {os.cpu_count()} logical cores; {args.rounds} rounds interleaved")
    print(f"scene: 5000 spheres poured for {args.steps} steps of {DT} s, then {args.settled_steps} "
          f"steps of the settled bed; talus contacts at the end: {contacts}")
    print(f"{'code':<16} {'pour particle-steps/s':>22} {'settled particle-steps/s':>25}")
    median = {k: {s: statistics.median(r[s] for r in v) for s in ("pour", "settled")}
              for k, v in results.items()}
    for k, m in median.items():
        print(f"{k:<16} {m['pour']:>22.3e} {m['settled']:>25.3e}")
    lig = median["liggghts"]
    for name in builds:
        for t in args.threads:
            m = median[f"{name} {t}"]
            print(f"{name} on {t} thread(s) / LIGGGHTS on 1: pour {m['pour'] / lig['pour']:.2f}, "
                  f"settled {m['settled'] / lig['settled']:.2f}")
        if 1 in args.threads and 2 in args.threads:
            one, two = median[f"{name} 1"], median[f"{name} 2"]
            print(f"{name} 2 threads / 1 thread: pour {two['pour'] / one['pour']:.2f}, "
                  f"settled {two['settled'] / one['settled']:.2f}")
    for n in procs:
        m = median[f"liggghts {n} procs"]
        print(f"LIGGGHTS {n} processes / 1 process: pour {m['pour'] / lig['pour']:.2f}, "
              f"settled {m['settled'] / lig['settled']:.2f}")
        if f"talus {n}" in median:
            t = median[f"talus {n}"]
            print(f"talus on {n} threads / LIGGGHTS on {n} processes: pour {t['pour'] / m['pour']:.2f}, "
                  f"settled {t['settled'] / m['settled']:.2f}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
