"""Pours the bed of the fluidised-bed example (pour.toml) with the talus Python
module and writes its poses to bed.csv (the `kind = "file"` format of a scene).

    examples/fluid_bed/pour.py [--out bed.csv]
"""

import argparse
import pathlib

import talus

HERE = pathlib.Path(__file__).resolve().parent


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default=str(HERE / "bed.csv"))
    args = parser.parse_args()
    sim = talus.Scene(str(HERE / "pour.toml"))
    sim.initialize(0.0)
    while sim.time < sim.end_time - 1e-9:
        sim.step(0.05)
        speed = max((v @ v) ** 0.5 for v in sim.velocities)
        print(f"t = {sim.time:.2f} s: {sim.particle_count} beads, largest speed {speed:.2e} m/s")
        if sim.particle_count == 1000 and sim.time > 0.3 and speed < 5e-3:
            break
    x = sim.positions
    q = sim.orientations
    with open(args.out, "w") as out:
        out.write(f"# examples/fluid_bed/pour.py: {len(x)} beads poured and settled by talus "
                  f"(t = {sim.time:.2f} s, largest speed {speed:.1e} m/s)\n")
        out.write("x,y,z,qw,qx,qy,qz\n")
        for p, r in zip(x, q):
            out.write(",".join(f"{v:.9e}" for v in (*p, *r)) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
