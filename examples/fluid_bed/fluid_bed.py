"""A gas-fluidised bed: talus's particles coupled to a 1-D plug-flow gas model
through the FMI 3.0 FMU of fluid_bed.toml, the superficial gas velocity raised in
steps and lowered again; plots the bed's pressure drop against the gas velocity.

    fluid_bed.py FLUID_BED.fmu [--out DIR] [--hold 0.03]

The gas model stands in for a CFD code. At every communication step (1 ms) it reads
each slab's solid fraction and momentum source, and sets the interstitial velocity
U / eps and the pressure gradient of the slab's steady momentum balance (model A),
grad p = rho_f g - sum(f_d) / (eps V), with f_d the drag the particles took (minus the
momentum source). The frictional pressure drop across the bed is sum_k D_k / (eps_k A).
"""

import argparse
import math
import pathlib

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave

RHO_P, RHO_F, MU, D, G = 2500.0, 1.2, 1.8e-5, 2e-3, 9.81
AREA, SLAB = 0.024 * 0.024, 0.004


def wen_yu():
    ar = RHO_F * (RHO_P - RHO_F) * G * D**3 / MU**2
    return (math.sqrt(33.7**2 + 0.0408 * ar) - 33.7) * MU / (RHO_F * D)


def ergun(u, eps):
    """Ergun's pressure gradient, Pa/m."""
    return (150 * MU * (1 - eps) ** 2 * u / (eps**3 * D**2)
            + 1.75 * RHO_F * (1 - eps) * u * u / (eps**3 * D))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu")
    parser.add_argument("--out", default=".")
    parser.add_argument("--hold", type=float, default=0.03, help="seconds per gas velocity")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    md = read_model_description(args.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(args.fmu),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bed")
    fmu.instantiate()
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    slabs = 15
    volume = AREA * SLAB
    solid = lambda: np.array(fmu.getFloat64([vr["fluid.solid_fraction"]], slabs))
    source = lambda: np.array(fmu.getFloat64([vr["fluid.momentum_source"]], 3 * slabs)).reshape(-1, 3)
    particles = fmu.getInt32([vr["particles"]])[0]
    weight = particles * math.pi / 6 * D**3 * (RHO_P - RHO_F) * G / AREA

    u_wy = wen_yu()
    up = list(np.linspace(0.1, 1.5, 15) * u_wy)
    levels = up + up[-2::-3]
    h = 1e-3
    t = 0.0
    drag = np.zeros((slabs, 3))
    rows = []
    for u in levels:
        drops, heights = [], []
        steps = int(round(args.hold / h))
        for k in range(steps):
            eps = 1.0 - solid()
            velocity = np.zeros((slabs, 3))
            velocity[:, 2] = u / eps
            gradient = np.zeros((slabs, 3))
            gradient[:, 2] = -RHO_F * G
            gradient -= drag / (eps[:, None] * volume)
            fmu.setFloat64([vr["fluid.velocity"]], list(velocity.ravel()))
            fmu.setFloat64([vr["fluid.pressure_gradient"]], list(gradient.ravel()))
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t += h
            drag = -source()
            if k >= steps // 2:
                phi = solid()
                eps = 1.0 - phi
                drops.append(np.sum(drag[:, 2] / eps) / AREA)
                z = (np.arange(slabs) + 0.5) * SLAB
                heights.append(2.0 * np.sum(phi * z) / np.sum(phi))
        rows.append((u, np.mean(drops), np.mean(heights)))
        print(f"t = {t:.3f} s  U = {u:.3f} m/s  dp = {rows[-1][1]:7.2f} Pa "
              f"({rows[-1][1] / weight:.3f} of the weight)  bed height {1e3 * rows[-1][2]:.2f} mm",
              flush=True)
    fmu.terminate()
    fmu.freeInstance()

    rows = np.array(rows)
    np.savetxt(out / "pressure_drop.csv", rows, delimiter=",",
               header="superficial_velocity_m_s,pressure_drop_Pa,bed_height_m", comments="")
    n_up = len(up)
    # U_mf by the pressure-drop method: the fixed-bed branch (the rising velocities
    # up to the first drop above 90 % of the weight), fitted by Ergun's form
    # a U + b U², meets the weight.
    rising = rows[:n_up]
    above = np.nonzero(rising[:, 1] >= 0.9 * weight)[0]
    fixed = rising[: above[0] if len(above) else n_up]
    a, b = np.linalg.lstsq(np.column_stack([fixed[:, 0], fixed[:, 0] ** 2]), fixed[:, 1], rcond=None)[0]
    fit = np.array([b, a, 0.0])
    roots = [r.real for r in np.roots(fit - np.array([0, 0, weight])) if abs(r.imag) < 1e-9 and r.real > 0]
    u_mf = min(roots) if roots else float("nan")
    print(f"U_mf from the pressure drop: {u_mf:.3f} m/s; Wen-Yu {u_wy:.3f} m/s "
          f"({100 * (u_mf / u_wy - 1):+.1f} %)")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(rows[:n_up, 0], rows[:n_up, 1], "o-", label="talus, velocity rising")
    ax.plot(rows[n_up - 1:, 0], rows[n_up - 1:, 1], "s--", label="talus, velocity falling")
    ax.axhline(weight, color="k", lw=0.8, label="bed weight per area (less buoyancy)")
    ax.axvline(u_wy, color="C3", lw=0.8, label=f"Wen-Yu U_mf = {u_wy:.2f} m/s")
    uu = np.linspace(0, u_wy, 50)
    eps0 = 1 - particles * math.pi / 6 * D**3 / (AREA * float(rows[0, 2]))
    ax.plot(uu, ergun(uu, eps0) * rows[0, 2], ":", color="C2",
            label=f"Ergun, fixed bed (eps = {eps0:.3f})")
    ax.set_xlabel("superficial gas velocity U (m/s)")
    ax.set_ylabel("frictional pressure drop across the bed (Pa)")
    ax.set_title(f"1000 glass beads of 2 mm in air: U_mf = {u_mf:.2f} m/s")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "pressure_drop.png", dpi=120)
    print(f"wrote {out / 'pressure_drop.png'} and {out / 'pressure_drop.csv'}")


if __name__ == "__main__":
    main()
