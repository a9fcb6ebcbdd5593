"""The theoretical entry corridor of an aerocapture pass: the range of entry flight-path angles
from which the vehicle, flying full lift up or full lift down, still captures.

The scenario's guidance is taken out: every component whose output feeds the actuator's command
is replaced by `ConstantLiftToDrag` (u = L/D * D/m, fmus_src), which flies +L/D (full lift up) or
-L/D (full lift down) from the vehicle's measured drag; the vehicle, atmosphere, actuator, stop
condition and outcome rules are the scenario's. The thesis of seed 000 states no lift limit (the
vehicle's lift acceleration is the control), so L/D is an input the user states. Measured on the
seed-000 pass (benchmark_seed000/time_linear.json, tolerance 100 m): L/D 0.3 gives the corridor
-0.01335 ... -0.01177 rad and L/D 3 gives -0.01967 ... -0.00747 rad, both shallower than the
thesis entry -0.02 rad, which the thesis nominal reaches by flying about L/D 13.8 at entry; L/D 5
gives -0.02575 ... -0.00492 rad (1.19 deg wide); at L/D 10 full lift down never exits from a
descending entry, so there is no shallow bound.

Bounds (bisection on the vehicle's entry flight-path angle, the scenario's `gamma0` start value):

- steep bound: full lift up, the apogee error on the band's lower edge (-band); any steeper entry
  undershoots even with all the lift up;
- shallow bound: full lift down, the apogee error on the band's upper edge (+band); any shallower
  entry skips out even with all the lift down.

Each bisection stops when a run's apogee error is within `tolerance` (m) of its band edge; that
run's gamma0 is the bound. The corridor width is shallow - steep (rad). A run that never climbs
back out counts as below every edge, an unbound exit orbit as above.
"""

import json
import math
from pathlib import Path

from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.model.documents import strict_json
from aotv_cosim.options import CorridorOptions
from aotv_cosim.output.outdir import claimed
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.status import Status

LIFT = "corridor_lift"
"""Name of the component that replaces the guidance."""


def corridor_scenarios(scenario_path, out_dir, lift_to_drag: float) -> dict:
    """{"lift_up": path, "lift_down": path} of the scenario (which classifies its runs) with its
    guidance replaced by ConstantLiftToDrag at +lift_to_drag and -lift_to_drag, written to out_dir."""
    scenario_path = Path(scenario_path).resolve()
    scenario = load_scenario(scenario_path)
    vehicle, actuator = scenario.outcome.vehicle, scenario.outcome.actuator
    doc = strict_json(scenario_path.read_text(encoding="utf-8"))
    wiring_path = scenario.system.path
    wiring = strict_json(Path(wiring_path).read_text(encoding="utf-8"))
    arrows = [tuple(part.strip() for part in c.split("->")) for c in wiring.get("connections", [])]
    removed = {source.split(".")[0] for source, target in arrows if target == f"{actuator}.command"}
    if not removed or vehicle in removed:
        raise InputError(f"no guidance component feeds {actuator}.command", file=wiring_path, entry="connections",
                         fix="connect the guidance's command to the actuator's command input")
    components = {name: _absolute(comp, Path(wiring_path).parent) for name, comp in wiring["components"].items()
                  if name not in removed}
    kept = [f"{s} -> {t}" for s, t in arrows if s.split(".")[0] not in removed and t.split(".")[0] not in removed]
    kept += [f"{vehicle}.drag_acc -> {LIFT}.drag_acc", f"{LIFT}.u -> {actuator}.command"]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {}
    for case, sign in (("lift_up", 1.0), ("lift_down", -1.0)):
        system = {"description": f"{wiring_path} with its guidance replaced by L/D = {sign * lift_to_drag:g}",
                  "components": {**components, LIFT: {"fmu": "ConstantLiftToDrag",
                                                      "parameters": {"lift_to_drag": sign * lift_to_drag}}},
                  "connections": kept}
        (out / f"{case}_wiring.json").write_text(json.dumps(system, indent=2) + "\n")
        flown = {k: v for k, v in doc.items() if k not in ("$schema", "dispersions", "dispersion_set", "expect",
                                                            "expectations", "plots", "system")}
        flown["system"] = f"{case}_wiring.json"
        flown["record"] = [r for r in doc.get("record", []) if r.split(".")[0] not in removed]
        flown["description"] = f"{scenario_path} flown at L/D = {sign * lift_to_drag:g} (corridor bound)"
        (out / f"{case}.json").write_text(json.dumps(flown, indent=2) + "\n")
        paths[case] = out / f"{case}.json"
    return paths


def _absolute(component: dict, base: Path) -> dict:
    """The component with a relative .fmu or .py FMU reference made absolute."""
    ref = component["fmu"]
    if ref.endswith((".fmu", ".py")):
        return {**component, "fmu": str((base / ref).resolve())}
    return component


CORRIDOR_OUTPUTS = ("corridor.json", "corridor.json.part", "corridor.png", "lift_up.json", "lift_down.json",
                    "lift_up_wiring.json", "lift_down_wiring.json")
"""The files a corridor writes in its folder."""


def run_corridor(options: CorridorOptions, max_runs: int = 60) -> dict:
    """The corridor of the module docstring: {"steep": bound, "shallow": bound, "width_rad",
    "width_deg", "nominal_gamma0", "lift_to_drag", "tolerance_m", "band_m", "units", "plots"};
    each bound {"gamma0" rad, "apogee_error" m, "edge" m, "runs", "points": [(gamma0, error)]}.
    Written to `options.out`: corridor.json, corridor.png and the two scenarios flown. The two
    bisections go side by side on the options' backend (local workers or Dask), one run of each
    at a time; each bound is the same whatever runs it. A SIGINT/SIGTERM raises
    `simulation.interrupts.Interrupted` (the two scenarios are kept, no corridor.json)."""
    scenario_path = Path(options.scenario).resolve()
    scenario = load_scenario(scenario_path)
    if scenario.outcome is None:
        raise InputError("the scenario does not classify its runs", file=scenario_path, entry="montecarlo",
                         fix='add "montecarlo": {"outcome": {}} (the band the corridor is bounded by)')
    out = Path(options.out)
    with interrupts.deferred(), claimed(out, CORRIDOR_OUTPUTS):
        paths = corridor_scenarios(scenario_path, out, options.lift_to_drag)
        vehicle, band = scenario.outcome.vehicle, scenario.outcome.band
        signal = f"{vehicle}.gamma0"
        nominal = float(scenario.system.components[vehicle].parameters.get(
            "gamma0", scenario.system.variable(signal).start))
        result = {"scenario": str(scenario_path), "lift_to_drag": options.lift_to_drag,
                  "tolerance_m": options.tolerance, "band_m": band, "nominal_gamma0": nominal,
                  "bracket": list(options.bracket)}
        searches = {bound: _Bisection(case, paths[case], edge, options, max_runs)
                    for bound, case, edge in (("steep", "lift_up", -band), ("shallow", "lift_down", band))}
        result.update(_search(searches, signal, options, scenario))
        result["width_rad"] = result["shallow"]["gamma0"] - result["steep"]["gamma0"]
        result["width_deg"] = math.degrees(result["width_rad"])
        result["units"] = {"gamma0": "rad", "apogee_error": "m", "edge": "m", "width_rad": "rad",
                           "width_deg": "deg", "tolerance_m": "m", "band_m": "m", "lift_to_drag": "1"}
        from aotv_cosim.campaigns.figures import corridor_plot

        result["plots"] = [corridor_plot(out, result)]
        for bound in ("steep", "shallow"):  # summary.json's convention: a non-finite number as text
            result[bound]["points"] = [(g, e if math.isfinite(e) else str(e)) for g, e in result[bound]["points"]]
        write_json_atomically(out / "corridor.json", result)
    return result


class _Bisection:
    """One bound's search: the gamma0 in the bracket whose apogee error is within the tolerance of
    `edge` (errors grow with gamma0: a shallower entry keeps more energy). `next()` gives the
    gamma0 to fly next (None while waiting for a run, or when done), `tell(gamma0, error)` takes a
    run's apogee error (m)."""

    def __init__(self, case, path, edge, options, max_runs):
        from aotv_cosim.campaigns.scenario_ref import ScenarioRef

        self.case, self.path, self.ref, self.edge = case, path, ScenarioRef.of(path.resolve()), edge
        self.tolerance, self.max_runs = options.tolerance, max_runs
        self.low, self.high = options.bracket
        self.points, self.waiting, self.result = [], [self.low, self.high], None

    def next(self):
        return self.waiting.pop(0) if self.waiting else None

    def tell(self, gamma0, error) -> None:
        self.points.append((gamma0, error))
        if len(self.points) == 2:
            self.points.sort()  # the bracket's ends, steep first, in whichever order their runs ended
            (steep, low_error), (shallow, high_error) = self.points
            if not low_error <= self.edge <= high_error:
                raise InputError(f"{self.case}: the apogee error does not cross {self.edge:+g} m between gamma0 = "
                                 f"{steep} and {shallow} rad ({low_error:+.6g} and {high_error:+.6g} m)",
                                 file=self.path, entry="--bracket", fix="widen the bracket, or change --lift-to-drag")
        elif len(self.points) > 2:
            if abs(error - self.edge) <= self.tolerance:
                self.result = {"gamma0": gamma0, "apogee_error": error, "edge": self.edge, "runs": len(self.points),
                               "points": self.points}
                return
            self.low, self.high = (gamma0, self.high) if error < self.edge else (self.low, gamma0)
        if len(self.points) >= 2 and self.result is None:
            if len(self.points) >= self.max_runs:
                raise SimulationError(f"{self.case}: no run within {self.tolerance:g} m of {self.edge:+g} m after "
                                      f"{self.max_runs} runs (gamma0 in [{self.low!r}, {self.high!r}] rad)",
                                      file=str(self.path), fix="the apogee error jumps there (a skip or an impact): "
                                                               "give a larger --tolerance")
            self.waiting.append(0.5 * (self.low + self.high))


def _search(searches: dict, signal, options, scenario) -> dict:
    """{bound: result} of the `_Bisection`s, their runs made on the options' backend."""
    from aotv_cosim.campaigns import backends
    from aotv_cosim.campaigns.worker import columns

    backend = backends.opened(options, options.step_limit(scenario), columns(scenario))
    interrupted = True
    try:
        asked = {}

        def ask(bound):
            gamma0 = searches[bound].next()
            while gamma0 is not None:
                run = len(asked)
                asked[run] = (bound, gamma0)
                backend.submit(searches[bound].ref, [(run, {signal: gamma0})])
                gamma0 = searches[bound].next()

        for bound in searches:
            ask(bound)
        while backend.pending:
            for _, rows in backend.finished():
                for row in rows:
                    bound, gamma0 = asked[row["run"]]
                    searches[bound].tell(gamma0, _apogee_error(row, signal, gamma0, searches[bound].path))
                    ask(bound)
        interrupted = False
    finally:
        backend.close(interrupted)
    return {bound: search.result for bound, search in searches.items()}


def _apogee_error(row, signal, gamma0, path) -> float:
    """The apogee error (m) of the run `row` entered at gamma0: -inf if it never exits or impacts,
    +inf if the exit orbit is unbound; SimulationError if the run failed."""
    if row["status"] not in (Status.COMPLETED, Status.IMPACT):
        raise SimulationError(f"the run at {signal} = {gamma0!r} rad failed: {row['error']}", file=str(path),
                              fix="see the error; narrow --bracket")
    error = float(row["outcome.apogee_error"])
    return -math.inf if row["outcome"] == "impact" or math.isnan(error) else error
