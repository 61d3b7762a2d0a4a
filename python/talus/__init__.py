"""talus for Python: a DEM scene stepped from Python, its walls, particles and states
as numpy arrays.

    import talus
    drum = talus.Scene("examples/drum_fmu/drum.toml")
    drum.initialize()
    drum.set_wall_velocity("drum", [0, 0, 0], [0, 3.0, 0])
    for _ in range(100):
        drum.step(0.01)
        force, torque = drum.wall_force("drum")
    drum.positions          # (n, 3) array of centroids

`Scene` is the co-simulation component of the C API and the FMUs (same calls, same
results bit for bit); a refused call raises `TalusError` with talus's message. Every
array is a copy taken when asked for. `Scene.run` steps to the scene's end with a
progress bar (tqdm's, in notebooks and terminals, when tqdm is installed).
"""
import sys
import time as _time

from . import _talus
from ._talus import TalusError, version

__all__ = ["Scene", "TalusError", "version", "run"]
__version__ = version()


class _TextBar:
    """A one-line progress bar on a stream, for when tqdm is not installed."""

    def __init__(self, total, stream):
        self.total, self.stream, self.done = total, stream, 0.0
        self.start = _time.monotonic()

    def update(self, amount):
        self.done += amount
        fraction = min(1.0, self.done / self.total) if self.total > 0 else 1.0
        filled = int(30 * fraction)
        elapsed = _time.monotonic() - self.start
        self.stream.write(f"\r[{'#' * filled}{'.' * (30 - filled)}] {100 * fraction:5.1f} % "
                          f"of {self.total:g} s simulated, {elapsed:.1f} s")
        self.stream.flush()

    def close(self):
        self.stream.write("\n")
        self.stream.flush()


def _progress_bar(total, progress):
    if progress is False or progress is None:
        return None
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return _TextBar(total, sys.stderr)
        return tqdm(total=total, unit="s", unit_scale=False, desc="simulated",
                    bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]")
    return progress  # any object with update(amount) and close()


class Scene(_talus.Scene):
    __doc__ = _talus.Scene.__doc__

    def run(self, until=None, interval=None, progress=True, each=None):
        """Steps to `until` (default: the scene's end time); see `talus.run`."""
        return run(self, until, interval, progress, each)


def run(scene, until=None, interval=None, progress=True, each=None):
    """Steps `scene` to `until` (default: the scene's end time) in communication steps
    of `interval` seconds (default: 1/100 of the span, at least one DEM step), with a
    progress bar (`progress=False` for none, or any object with `update` and `close`).
    `each(scene)` is called after every step; returning False stops the run. The scene
    is initialised at time 0 first if it is not yet. Returns the time reached."""
    if scene.mode == "instantiated":
        scene.initialize(0.0)
    end = scene.end_time if until is None else float(until)
    span = end - scene.time
    if interval is None:
        interval = span / 100 if span > 0 else 0.0
    if span > 0 and not interval > 0:
        raise ValueError(f"interval must be positive, not {interval}")
    bar = _progress_bar(max(span, 0.0), progress)
    start, shown = scene.time, 0.0
    try:
        # Steps land on the end exactly; the last one is shortened.
        while scene.time < end - 1e-12 * max(1.0, abs(end)):
            scene.step(min(interval, end - scene.time))
            if bar is not None:
                # What is shown adds up to the time simulated, without drift.
                step = (scene.time - start) - shown
                shown += step
                bar.update(step)
            if each is not None and each(scene) is False:
                break
    finally:
        if bar is not None:
            bar.close()
    return scene.time

