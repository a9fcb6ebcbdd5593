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

from aotv_cosim.model.documents import strict_json
from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.status import Status

LIFT = "corridor_lift"
"""Name of the component that replaces the guidance."""


def corridor_scenarios(scenario_path, out_dir, lift_to_drag: float) -> dict:
    """{"lift_up": path, "lift_down": path} of the scenario with its guidance replaced by
    ConstantLiftToDrag at +lift_to_drag and -lift_to_drag, written to out_dir."""
    scenario_path = Path(scenario_path).resolve()
    scenario = load_scenario(scenario_path)
    if scenario.outcome is None:
        raise InputError("the scenario does not classify its runs", file=scenario_path, entry="montecarlo",
                         fix='add "montecarlo": {"outcome": {}} (the band the corridor is bounded by)')
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


def run_corridor(scenario_path, out_dir, lift_to_drag: float, tolerance: float = 100.0,
                 bracket=(-0.08, -0.002), max_runs: int = 60) -> dict:
    """The corridor of the module docstring: {"steep": bound, "shallow": bound, "width_rad",
    "width_deg", "nominal_gamma0", "lift_to_drag", "tolerance_m", "band_m", "units", "plots"};
    each bound {"gamma0" rad, "apogee_error" m, "edge" m, "runs", "points": [(gamma0, error)]}.
    Written to out_dir/corridor.json with corridor.png. bracket: the gamma0 range searched (rad)."""
    from aotv_cosim.campaigns.scenario_ref import ScenarioRef
    from aotv_cosim.campaigns.worker import Runner

    check_options(scenario_path, lift_to_drag, tolerance, bracket)
    out = Path(out_dir)
    paths = corridor_scenarios(scenario_path, out, lift_to_drag)
    scenario = load_scenario(scenario_path)
    vehicle = scenario.outcome.vehicle
    band = scenario.outcome.band
    signal = f"{vehicle}.gamma0"
    nominal = float(scenario.system.components[vehicle].parameters.get(
        "gamma0", scenario.system.variable(signal).start))
    result = {"scenario": str(Path(scenario_path).resolve()), "lift_to_drag": lift_to_drag, "tolerance_m": tolerance,
              "band_m": band, "nominal_gamma0": nominal, "bracket": list(bracket)}
    for bound, case, edge in (("steep", "lift_up", -band), ("shallow", "lift_down", band)):
        runner = Runner(ScenarioRef.of(paths[case]))
        result[bound] = _bisect(lambda g: _apogee_error(runner, signal, g), edge, tolerance, bracket, max_runs,
                                case, paths[case])
    result["width_rad"] = result["shallow"]["gamma0"] - result["steep"]["gamma0"]
    result["width_deg"] = math.degrees(result["width_rad"])
    result["units"] = {"gamma0": "rad", "apogee_error": "m", "edge": "m", "width_rad": "rad", "width_deg": "deg",
                       "tolerance_m": "m", "band_m": "m", "lift_to_drag": "1"}
    from aotv_cosim.campaigns.figures import corridor_plot

    result["plots"] = [corridor_plot(out, result)]
    for bound in ("steep", "shallow"):  # summary.json's convention: a non-finite number as text
        result[bound]["points"] = [(g, e if math.isfinite(e) else str(e)) for g, e in result[bound]["points"]]
    write_json_atomically(out / "corridor.json", result)
    return result


def check_options(scenario_path, lift_to_drag: float, tolerance: float, bracket) -> None:
    """Refuse, before any run, a non-finite or non-positive L/D or tolerance (an infinite one
    cannot be written to corridor.json) and a bracket that is not finite or whose steep bound is
    not below its shallow one (a reversed or empty bracket cannot hold a crossing)."""
    if not (math.isfinite(lift_to_drag) and lift_to_drag > 0.0 and math.isfinite(tolerance) and tolerance > 0.0):
        raise InputError(f"lift_to_drag and tolerance must be finite and positive, got {lift_to_drag!r} and "
                         f"{tolerance!r}", file=str(scenario_path), entry="--lift-to-drag/--tolerance",
                         fix="give L/D > 0 and a tolerance in m > 0")
    steep, shallow = bracket
    if not (math.isfinite(steep) and math.isfinite(shallow) and steep < shallow):
        raise InputError(f"the bracket ({steep!r}, {shallow!r}) rad is not a finite range from steep to shallow",
                         file=str(scenario_path), entry="--bracket",
                         fix="give STEEP SHALLOW with STEEP < SHALLOW (rad), e.g. --bracket -0.08 -0.002")


def _apogee_error(runner, signal, gamma0) -> float:
    """The apogee error (m) of the pass entered at gamma0: -inf if it never exits or impacts,
    +inf if the exit orbit is unbound; SimulationError if the run fails."""
    row = runner.run(0, {signal: gamma0})
    if row["status"] not in (Status.COMPLETED, Status.IMPACT):
        raise SimulationError(f"the run at {signal} = {gamma0!r} rad failed: {row['error']}",
                              file=str(runner.scenario.path), fix="see the error; narrow --bracket")
    error = float(row["outcome.apogee_error"])
    return -math.inf if row["outcome"] == "impact" or math.isnan(error) else error


def _bisect(error_of, edge, tolerance, bracket, max_runs, case, path) -> dict:
    """gamma0 in `bracket` whose apogee error is within tolerance of `edge` (errors grow with
    gamma0: a shallower entry keeps more energy)."""
    steep, shallow = bracket
    points = [(steep, error_of(steep)), (shallow, error_of(shallow))]
    if not points[0][1] <= edge <= points[1][1]:
        raise InputError(f"{case}: the apogee error does not cross {edge:+g} m between gamma0 = {steep} and "
                         f"{shallow} rad ({points[0][1]:+.6g} and {points[1][1]:+.6g} m)", file=path,
                         entry="--bracket", fix="widen the bracket, or change --lift-to-drag")
    low, high = steep, shallow
    while len(points) < max_runs:
        middle = 0.5 * (low + high)
        error = error_of(middle)
        points.append((middle, error))
        if abs(error - edge) <= tolerance:
            return {"gamma0": middle, "apogee_error": error, "edge": edge, "runs": len(points), "points": points}
        low, high = (middle, high) if error < edge else (low, middle)
    raise SimulationError(f"{case}: no run within {tolerance:g} m of {edge:+g} m after {max_runs} runs "
                          f"(gamma0 in [{low!r}, {high!r}] rad)", file=str(path),
                          fix="the apogee error jumps there (a skip or an impact): give a larger --tolerance")
