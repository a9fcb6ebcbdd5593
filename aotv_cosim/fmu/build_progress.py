"""FMU builds made visible on the terminal: one message when the first build starts, then a bar.

A build takes a few seconds per FMU (pythonfmu, the reproducible rewrite, `fmpy validate`); the
first run after installing or changing the sources builds the FMUs it needs. `BuildProgress`
registers itself in `fmu_build.BUILD_HOOKS` for the duration of a `with` block and prints only
if a build happens. With `total` (build-fmus knows how many are stale) the bar has an end;
without it (a run builds what its wiring names) it counts FMUs built and the time spent.
"""

import sys

from aotv_cosim.fmu import build as fmu_build


class BuildProgress:
    """Context manager showing the builds made inside it on `file` (stderr)."""

    def __init__(self, total=None, file=None):
        self.total = total
        self.file = file or sys.stderr
        self.bar = None
        self.built = []

    def __enter__(self):
        fmu_build.BUILD_HOOKS.append(self)
        return self

    def __exit__(self, *exc):
        fmu_build.BUILD_HOOKS.remove(self)
        if self.bar is not None:
            self.bar.close()

    def __call__(self, name, stage):
        if self.bar is None:
            from tqdm import tqdm

            print("building FMUs from fmus_src (new or changed sources; a few seconds each, "
                  "cached afterwards)", file=self.file, flush=True)
            self.bar = tqdm(total=self.total, unit="FMU", desc="building", file=self.file,
                            bar_format=None if self.total else "{desc}: {n} FMU built [{elapsed}{postfix}]")
        if stage == "start":
            self.bar.set_postfix_str(name)
        else:
            self.built.append(name)
            self.bar.update(1)

    def echo(self, line):
        """Print a line on stdout without breaking the bar."""
        if self.bar is None:
            print(line, flush=True)
        else:
            self.bar.write(line, file=sys.stdout)
