"""Run an .ssp archive in Ecos (through ecospy) and report the final values.

Standalone on purpose, like `libcosim_run`: it imports only the standard library and ecospy, so a
test may copy it anywhere and run

    python ecos_run.py FILE.ssp STOP comp.var [comp.var ...]

which prints one JSON object: {"final": {signal: value}, "time": s, "wall_time_s": s}. The step is
the SSD's OSP FixedStepAlgorithm baseStepSize, the start its DefaultExperiment startTime; the
parameter set applied is the one named `PARAMETER_SET` (every SSV this package exports has that
name). Ecos steps every component from the same communication point, then transfers outputs to
inputs (the Jacobi scheme); its variables are named ``component::variable``.

ecospy 0.7 needs libtbb.so.12: the system's (Debian: ``apt-get install libtbb12``) or, where the
system has none, the one PyPI's ``tbb`` wheel installs in ``<sys.prefix>/lib`` (`load_ecospy`).
Its wheel installs the ``ecos`` and ``proxyfmu`` executables without execute permission
(`executable` copies one with it).
"""

import ctypes
import json
import os
import shutil
import stat
import sys
import time
import zipfile
from xml.etree import ElementTree

PARAMETER_SET = "scenario"
SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"
OSP = "{http://opensimulationplatform.com/SSP/OSPAnnotations}"


def experiment(ssp):
    """(start s, step s) of the archive's default experiment."""
    with zipfile.ZipFile(ssp) as archive:
        root = ElementTree.fromstring(archive.read("SystemStructure.ssd"))
    node = root.find(f"{SSD}DefaultExperiment")
    algorithm = node.find(f".//{OSP}FixedStepAlgorithm") if node is not None else None
    if node is None or algorithm is None:
        raise ValueError(f"{ssp}: no default experiment with a fixed step")
    return float(node.get("startTime", "0")), float(algorithm.attrib["baseStepSize"])


def load_ecospy():
    """The ecospy module; when its library finds no libtbb.so.12 on the system, loaded again after
    the one of PyPI's `tbb` package (sys.prefix/lib), made global so that its soname is resolved."""
    try:
        import ecospy
    except OSError:
        tbb = os.path.join(sys.prefix, "lib", "libtbb.so.12")
        if not os.path.isfile(tbb):
            raise
        ctypes.CDLL(tbb, mode=ctypes.RTLD_GLOBAL)
        import ecospy
    return ecospy


def run(ssp, stop, signals):
    """Simulate `ssp` in Ecos from its start to `stop` (s) by its step; the last values of the
    Real `signals` ('component.variable')."""
    ecospy = load_ecospy()
    EcosLib, EcosSimulation = ecospy.EcosLib, ecospy.EcosSimulation
    EcosLib.set_log_level("warn")
    start, step = experiment(ssp)
    wall = time.perf_counter()
    sim = EcosSimulation(step, ssp_path=str(ssp))
    if not sim.init(start, PARAMETER_SET):
        raise RuntimeError(f"Ecos initialization failed: {EcosLib.get_last_error()}")
    sim.step(round((stop - start) / step))
    final = {s: sim.get_real(s.replace(".", "::", 1)) for s in signals}
    result = {"final": final, "time": sim.get_time(), "wall_time_s": time.perf_counter() - wall}
    sim.terminate()
    return result


def executable(name, folder):
    """A copy of ecospy's `name` executable ('ecos', 'proxyfmu') in `folder`, with execute
    permission (the wheel installs it without); None where ecospy has no such binary."""
    source = os.path.join(os.path.dirname(load_ecospy().__file__), "binaries", name)
    if not os.path.isfile(source):
        return None
    target = shutil.copy(source, os.path.join(folder, name))
    os.chmod(target, os.stat(target).st_mode | stat.S_IXUSR)
    return target


if __name__ == "__main__":
    print(json.dumps(run(sys.argv[1], float(sys.argv[2]), sys.argv[3:])))
