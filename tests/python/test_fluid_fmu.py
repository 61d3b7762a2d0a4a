"""The fluid's per-cell fields through the FMUs (FMI 3.0 arrays, FMI 2.0 scalars) give
the numbers of the native C API (pointer and length) to the last bit."""
import ctypes
import math
import os

import pytest

from test_fmu import Log, slave, start

CELLS = 54


def swirl(phase):
    out = []
    for c in range(CELLS):
        out += [0.3 * math.sin(c + phase), -0.2 * math.cos(0.5 * c), 2.0 + 0.05 * c + phase]
    return out


@pytest.mark.parametrize("version", [2, 3])
def test_the_fluid_fields_cross_the_fmu_as_through_the_c_api(fmus, library, version, tmp_path):
    md, unzipped, s = slave(fmus[("fluid", version)], version, tmp_path / "fmu")
    by_name = {v.name: v.valueReference for v in md.modelVariables}
    start(version, s, Log())
    lib = ctypes.CDLL(str(library))
    lib.talus_create.restype = ctypes.c_void_p
    lib.talus_create.argtypes = [ctypes.c_char_p]
    handle = ctypes.c_void_p(lib.talus_create(os.path.join(unzipped, "resources", "scene.toml").encode()))
    assert handle.value
    assert lib.talus_initialize(handle, ctypes.c_double(0.0)) == 0

    def fmu_vrs(name, size):
        if version == 3:
            return [by_name[name]]
        return [by_name[f"{name}[{k + 1}]"] for k in range(size)]

    def fmu_set(name, values):
        vr = fmu_vrs(name, len(values))
        (s.setFloat64 if version == 3 else s.setReal)(vr, values)

    def fmu_get(name, size):
        vr = fmu_vrs(name, size)
        return list(s.getFloat64(vr, size) if version == 3 else s.getReal(vr))

    def c_get(name, size):
        out = (ctypes.c_double * size)()
        assert lib.talus_get_real(handle, name.encode(), out, ctypes.c_size_t(size)) == 0
        return list(out)

    h, t = 13 * 2e-5, 0.0
    for k in range(2):
        u = swirl(0.7 * k)
        fmu_set("fluid.velocity", u)
        assert lib.talus_set_real(handle, b"fluid.velocity", (ctypes.c_double * len(u))(*u),
                                  ctypes.c_size_t(len(u))) == 0
        s.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        assert lib.talus_step(handle, ctypes.c_double(t), ctypes.c_double(h)) == 0
        t += h
    for name, size in [("fluid.momentum_source", 3 * CELLS), ("fluid.solid_fraction", CELLS),
                       ("fluid.particle_velocity", 3 * CELLS), ("fluid.velocity", 3 * CELLS)]:
        assert fmu_get(name, size) == c_get(name, size), name
    source = fmu_get("fluid.momentum_source", 3 * CELLS)
    assert sum(source[2::3]) < 0.0, "the particles take momentum from the gas"
    lib.talus_free(handle)
    s.terminate()
    s.freeInstance()
