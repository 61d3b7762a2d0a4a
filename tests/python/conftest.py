"""Shared fixtures: FMUs packed by the `talus` program of this checkout."""
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TALUS = Path(os.environ.get("TALUS_BIN", ROOT / "target" / "debug" / "talus"))

SCENES = {
    "drum": ROOT / "examples" / "drum_fmu" / "drum.toml",
    "empty_drum": ROOT / "examples" / "drum_fmu" / "empty_drum.toml",
    "tube": ROOT / "tests" / "scenes" / "tube_bed.toml",
    "fluid": ROOT / "tests" / "scenes" / "fluid_column.toml",
}


@pytest.fixture(scope="session")
def library():
    """The shared library next to the talus program."""
    lib = TALUS.with_name("libtalus.so")
    assert lib.is_file(), f"build first: {lib} is missing"
    return lib


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """FMUs of every scene in both FMI versions: fmus[(scene, version)] -> path."""
    out = tmp_path_factory.mktemp("fmus")
    paths = {}
    for name, scene in SCENES.items():
        for version in (2, 3):
            path = out / f"{name}{version}.fmu"
            subprocess.run([str(TALUS), "fmu", str(scene), "-o", str(path), "--fmi", str(version)],
                           check=True, capture_output=True)
            paths[(name, version)] = path
    return paths


@pytest.fixture(scope="session")
def proto_dir(tmp_path_factory):
    """The Python classes of the zenoh messages, written by `talus proto`."""
    out = tmp_path_factory.mktemp("proto")
    subprocess.run([str(TALUS), "proto", "--python-out", str(out)], check=True, capture_output=True)
    return out
