"""Run an .ssp archive in OSP libcosim (through libcosimpy) and report the final values.

Standalone on purpose: it imports only the standard library and libcosimpy, so the clean-room
test copies it into a virtual environment where aotv-cosim is not installed and runs

    python libcosim_run.py FILE.ssp STOP comp.var [comp.var ...] [-- FILE.ssp STOP comp.var ...]

which prints one JSON object per system, one after another in this process, on one line:
{"final": {signal: value}, "time": s, "wall_time_s": s, "steps_wall_s": s, "aotv_cosim_from":
[the files of the bundled runtimes the FMUs imported so far]} (a list of them with several
systems). libcosim reads the step from the SSD's OSP FixedStepAlgorithm annotation,
steps every component from the same communication point (in parallel worker threads) and then
transfers outputs to inputs: the Jacobi scheme. Times are integer nanoseconds in libcosim.
"""

import json
import sys
import time


def run(ssp, stop, signals, log_level="WARNING"):
    """Simulate `ssp` in libcosim until `stop` (s); the last values of the Real `signals`."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel[log_level])
    wall0 = time.perf_counter()
    execution = CosimExecution.from_ssp_file(str(ssp))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {info.name.decode(): info.index for info in execution.slave_infos()}
    references = {name: {v.name.decode(): v.reference for v in execution.slave_variables(i)}
                  for name, i in index.items()}
    wall1 = time.perf_counter()
    if not execution.simulate_until(round(stop * 1e9)):
        from libcosimpy._internal import get_last_error_message

        raise RuntimeError(f"libcosim failed: {get_last_error_message()}")
    wall2 = time.perf_counter()
    final = {}
    for signal in signals:
        comp, var = signal.split(".", 1)
        final[signal] = observer.last_real_values(index[comp], [references[comp][var]])[0]
    return {"final": final, "time": execution.status().current_time / 1e9,
            "wall_time_s": wall2 - wall0, "steps_wall_s": wall2 - wall1,
            "aotv_cosim_from": bundled_runtimes()}


def bundled_runtimes():
    """Files of the FMUs' bundled runtime packages (aotv_cosim_<hash>) imported in this process,
    and of aotv_cosim itself if an FMU imported it."""
    return sorted(getattr(module, "__file__", None) or "" for name, module in list(sys.modules.items())
                  if name == "aotv_cosim" or (name.startswith("aotv_cosim_") and "." not in name))


def systems(argv):
    """[(ssp, stop, signals)] of the command line (groups separated by --)."""
    groups: list[tuple[str, float, list[str]]] = []
    group: list[str] = []
    for arg in [*argv, "--"]:
        if arg == "--":
            groups.append((group[0], float(group[1]), group[2:]))
            group = []
        else:
            group.append(arg)
    return groups


if __name__ == "__main__":
    results = [run(*system) for system in systems(sys.argv[1:])]
    print(json.dumps(results[0] if len(results) == 1 else results))
