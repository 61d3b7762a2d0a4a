"""A drum stepped from Python: talus's Python module, the torque plotted with
matplotlib, the bed shown with pyvista (when it is installed).

    examples/python/run.sh           # builds the module into .venv, then runs this

or, with the module installed: python examples/python/drum.py [--rpm 30] [--end 3]

The scene is the drum of examples/drum_fmu (12 cm across, 96 beads, its rotation an
input). Cell by cell, as in a notebook:
"""
# %% The scene, its walls and variables.
import argparse
from pathlib import Path

import numpy as np

import talus

HERE = Path(__file__).resolve().parent
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--rpm", type=float, default=30.0, help="drum speed (default 30)")
parser.add_argument("--end", type=float, default=3.0, help="simulated seconds (default 3)")
parser.add_argument("--out", type=Path, default=HERE / "drum_out", help="output directory")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

drum = talus.Scene(str(HERE.parent / "drum_fmu" / "drum.toml"))
print(drum, "walls:", drum.walls)
drum.initialize()

# %% Spin up over 0.5 s, then hold: 5 ms communication steps, the torque of each.
omega = args.rpm * 2 * np.pi / 60
h = 0.005
times, torques = [], []


def record(scene):
    _, torque = scene.wall_force("drum")
    times.append(scene.time)
    torques.append(torque[1])  # about the drum axis (y)
    ramp = min(1.0, scene.time / 0.5)
    scene.set_wall_velocity("drum", [0, 0, 0], [0, ramp * omega, 0])


record(drum)
drum.run(until=args.end, interval=h, each=record)  # with a progress bar
times, torques = np.array(times), np.array(torques)
settled = min(1.0, 0.5 * args.end)  # the spin-up and the bed's lift are over by 1 s
held = times > settled
print(f"mean torque of the bed on the drum after {settled:g} s: "
      f"{1e3 * torques[held].mean():.2f} mN m at {args.rpm:g} rpm")

# %% The torque over time.
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, ax = plt.subplots(figsize=(8, 4.5))
ax.plot(times, 1e3 * torques, lw=1)
ax.axhline(1e3 * torques[held].mean(), color="tab:red", ls="--",
           label=f"mean after {settled:g} s: {1e3 * torques[held].mean():.1f} mN m")
ax.set_xlabel("time (s)")
ax.set_ylabel("torque of the bed on the drum, about its axis (mN m)")
ax.set_title(f"Drum of 12 cm with 96 beads, spun up to {args.rpm:g} rpm in 0.5 s")
ax.legend()
fig.tight_layout()
fig.savefig(args.out / "drum_torque.png", dpi=100)
print("wrote", args.out / "drum_torque.png")

# %% The bed and the drum, with pyvista (optional).
try:
    import pyvista as pv
except ImportError:
    print("pyvista is not installed: no 3-D view (pip install pyvista)")
else:
    vertices, triangles = drum.wall_mesh("drum")
    faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).astype(np.int64).ravel()
    shell = pv.PolyData(vertices, faces)
    beads = pv.PolyData(drum.positions)
    beads["speed"] = np.linalg.norm(drum.velocities, axis=1)
    spheres = beads.glyph(geom=pv.Sphere(radius=0.004), scale=False, orient=False)
    plotter = pv.Plotter(off_screen=True, window_size=(800, 600))
    plotter.add_mesh(shell, style="wireframe", color="grey", opacity=0.4)
    plotter.add_mesh(spheres, scalars="speed", cmap="viridis",
                     scalar_bar_args={"title": "speed (m/s)"})
    plotter.view_xz()
    plotter.enable_parallel_projection()
    plotter.screenshot(str(args.out / "drum_bed.png"))
    print("wrote", args.out / "drum_bed.png")
