"""The regime map of a Froude sweep: the regime talus names in each run (drum.json's
`regime`, at its `froude`) against the bands of Mellmann (2001), as a PNG.

    python regime_map.py OUT.png "LABEL=DIR DIR ..." ["LABEL=DIR ..."]

Each group is one set of runs (one marker); DIRs are talus output directories
holding drum.json. `froude_sweep.sh` runs the sweep and calls this.
"""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

REGIMES = ["slipping", "slumping", "rolling", "cascading", "cataracting", "centrifuging"]
# Mellmann (2001), Powder Technology 118: the Froude ranges of the forms of
# transverse motion (slipping at any Froude number below 1e-4 on a smooth shell).
MELLMANN = {
    "slipping": (1e-6, 1e-4),
    "slumping": (1e-5, 1e-3),
    "rolling": (1e-4, 1e-2),
    "cascading": (1e-3, 1e-1),
    "cataracting": (1e-1, 1.0),
    "centrifuging": (1.0, 10.0),
}
MARKERS = ["o", "s", "^", "D"]


def runs(dirs):
    out = []
    for d in dirs:
        summary = json.loads((Path(d) / "drum.json").read_text())
        if summary.get("regime"):
            out.append((summary["froude"], summary["regime"]))
    return out


def main():
    png = sys.argv[1]
    fig, ax = plt.subplots(figsize=(8, 4.2), dpi=100)
    for row, name in enumerate(REGIMES):
        lo, hi = MELLMANN[name]
        ax.barh(row, hi - lo, left=lo, height=0.5, color="0.85",
                label="Mellmann (2001)" if row == 0 else None)
    for k, group in enumerate(sys.argv[2:]):
        label, dirs = group.split("=", 1)
        points = runs(dirs.split())
        ax.scatter([f for f, _ in points], [REGIMES.index(r) for _, r in points],
                   marker=MARKERS[k % len(MARKERS)], s=60, zorder=3,
                   facecolors="none" if k else None, edgecolors=f"C{k}", color=f"C{k}",
                   label=f"talus: {label}")
    ax.set_xscale("log")
    ax.set_xlim(1e-6, 10.0)
    ax.set_yticks(range(len(REGIMES)), REGIMES)
    ax.set_xlabel("Froude number ω²R/g")
    ax.set_title("Flow regime against Froude number: quasi-2D drum")
    ax.grid(axis="x", which="major", color="0.9")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(png)


if __name__ == "__main__":
    main()
