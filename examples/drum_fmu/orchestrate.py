"""A co-simulation master for the drum FMU: ramps the drum speed up, holds it,
reverses it, and records the drive torque the bed puts on the drum.

    python orchestrate.py drum.fmu [--out DIR]

Writes DIR/drum_torque.csv (time, angular velocity, mean torque about the axis, mean
power) and DIR/drum_torque.png. Works with the FMI 2.0 and 3.0 FMUs of talus.
"""
import argparse
import csv
import math
import shutil
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

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
    parser.add_argument("fmu")
    parser.add_argument("--out", default=".")
    parser.add_argument("--stop", type=float, default=3.0)
    parser.add_argument("--step", type=float, default=0.005)
    args = parser.parse_args()

    md = read_model_description(args.fmu)
    unzipped = extract(args.fmu)
    by_name = {v.name: v.valueReference for v in md.modelVariables}
    fmi3 = md.fmiVersion.startswith("3")
    cls = FMU3Slave if fmi3 else FMU2Slave
    fmu = cls(guid=md.guid, unzipDirectory=unzipped,
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="drum")
    fmu.instantiate()
    if fmi3:
        spin, torque, power = (by_name["drum.angular_velocity"], by_name["drum.torque"],
                               by_name["drum.power"])
        set_spin = lambda w: fmu.setFloat64([spin], [0.0, w, 0.0])
        get = lambda: (fmu.getFloat64([torque], 3)[1], fmu.getFloat64([power])[0])
    else:
        fmu.setupExperiment(startTime=0.0)
        spin, torque, power = (by_name["drum.angular_velocity[2]"], by_name["drum.torque[2]"],
                               by_name["drum.power"])
        set_spin = lambda w: fmu.setReal([spin], [w])
        get = lambda: tuple(fmu.getReal([torque, power]))
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()

    rows = []
    t, h = 0.0, args.step
    while t < args.stop - 1e-12:
        w = speed(t + 0.5 * h)  # held over the step
        set_spin(w)
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        tau, p = get()
        rows.append((t, w, tau, p))
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

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
    fig.suptitle("talus drum FMU driven by an fmpy master")
    fig.tight_layout()
    fig.savefig(out / "drum_torque.png", dpi=120)
    hold = [r[2] for r in rows if 1.0 < r[0] <= 1.5]
    back = [r[2] for r in rows if r[0] > 2.5]
    print(f"mean torque at +30 rpm: {sum(hold) / len(hold) * 1e3:.3f} mN m, "
          f"at -30 rpm: {sum(back) / len(back) * 1e3:.3f} mN m")
    print(f"wrote {out / 'drum_torque.csv'} and {out / 'drum_torque.png'}")


if __name__ == "__main__":
    main()
