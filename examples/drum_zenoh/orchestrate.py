"""A zenoh orchestrator for a served drum: ramps the drum speed, reverses it, and
records the drive torque the bed puts on the drum.

    talus serve examples/drum_fmu/drum.toml --key talus/drum --listen tcp/127.0.0.1:7447 &
    python orchestrate.py --key talus/drum --connect tcp/127.0.0.1:7447 --proto gen

Writes OUT/drum_torque.csv and OUT/drum_torque.png.
"""
import argparse
import csv
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "interfaces" / "python"))
from talus_client import connect  # noqa: E402

RPM = 2 * math.pi / 60


def speed(t):
    """Drum speed (rad/s): ramp to 30 rpm in 0.5 s, hold, reverse over 0.5 s, hold."""
    top = 30 * RPM
    if t < 0.5:
        return top * t / 0.5
    if t < 1.5:
        return top
    if t < 2.0:
        return top * (1 - 2 * (t - 1.5) / 0.5)
    return -top


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--key", default="talus/drum")
    parser.add_argument("--connect", default="tcp/127.0.0.1:7447")
    parser.add_argument("--proto", required=True, help="directory of the generated classes")
    parser.add_argument("--out", default=".")
    parser.add_argument("--stop", type=float, default=3.0)
    parser.add_argument("--step", type=float, default=0.005)
    args = parser.parse_args()

    rows = []
    with connect(args.key, args.connect, args.proto) as drum:
        drum.wait_until_served()
        info = drum.info()
        t = info.time
        print(f"connected to {args.key}: scene {info.scene}, dt {info.dt:.3e} s, t = {t} s")
        while t < args.stop - 1e-12:
            w = speed(t + 0.5 * args.step)
            reply = drum.step(t, args.step, {"drum": {"angular_velocity": (0.0, w, 0.0)}})
            t = reply.time
            rows.append((t, w, reply.walls[0].torque.y, reply.walls[0].power))

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "drum_torque.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["time_s", "angular_velocity_rad_s", "torque_y_N_m", "power_W"])
        writer.writerows(rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    time = [r[0] for r in rows]
    fig, (a, b) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
    a.plot(time, [r[1] / RPM for r in rows], color="tab:blue")
    a.set_ylabel("drum speed (rpm)")
    b.plot(time, [r[2] * 1e3 for r in rows], color="tab:red", lw=0.8)
    b.axhline(0.0, color="k", lw=0.5)
    b.set_ylabel("torque on drum (mN m)")
    b.set_xlabel("time (s)")
    fig.suptitle("talus drum served over zenoh")
    fig.tight_layout()
    fig.savefig(out / "drum_torque.png", dpi=120)
    print(f"wrote {out / 'drum_torque.csv'} and {out / 'drum_torque.png'}")


if __name__ == "__main__":
    main()
