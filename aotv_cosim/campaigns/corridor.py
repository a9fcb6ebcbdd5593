"""`aotv-cosim corridor`: the theoretical entry corridor of a scenario that classifies its runs,
its passes flown on local workers or Dask, written to its folder (corridor.json, corridor.png,
the two scenarios flown). What is flown and how the bounds are found is `studies.corridor`'s (the
aerocapture study uses the same code in-process).
"""

import math
from pathlib import Path
from typing import Any, cast

from aotv_cosim.errors import InputError
from aotv_cosim.options import CorridorOptions
from aotv_cosim.output.outdir import claimed
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.studies import corridor as core

CORRIDOR_OUTPUTS = ("corridor.json", "corridor.json.part", "corridor.png", "lift_up.json", "lift_down.json",
                    "lift_up_wiring.json", "lift_down_wiring.json")
"""The files a corridor writes in its folder."""

UNITS = {"gamma0": "rad", "apogee_error": "m", "edge": "m", "bracket": "rad", "bracket_errors": "m",
         "width_rad": "rad", "width_deg": "deg", "tolerance_m": "m", "angle_tolerance_rad": "rad", "band_m": "m",
         "lift_to_drag": "1", "step_s": "s", "nominal_gamma0": "rad"}
"""The unit of every number of corridor.json."""


def run_corridor(options: CorridorOptions) -> dict:
    """The corridor of `studies.corridor` (its docstring: the plant, the passes, the bisection):
    {"scenario", "plant" (bank or lift), "control", "removed", "lift_to_drag" (the vehicle's own
    for a bank-angle vehicle, the user's for a lift-acceleration one), "sets" (the --set values),
    "undispersed" (every dispersed value of the scenario as flown), "aim", "steep", "shallow",
    "width_rad", "width_deg", "nominal_gamma0", "step_s", "tolerance_m", "angle_tolerance_rad",
    "band_m", "bracket", "units", "plots"}; each bound {"gamma0" rad, "apogee_error" m, "edge" (the
    apogee error aimed at) m, "runs", "bracket" [rad, rad] holding the edge, "bracket_errors" [m, m],
    "points": [(gamma0, error)]}. Written to `options.out`: corridor.json, corridor.png and the two
    scenarios flown. The two bisections go side by side on the options' backend (local workers or
    Dask), one run of each at a time; each bound is the same whatever runs it. Bad input (no
    outcome, a plant it cannot read, --lift-to-drag where it would be ignored or is missing) is
    refused before any run. A SIGINT/SIGTERM raises `simulation.interrupts.Interrupted` (the two
    scenarios are kept, no corridor.json)."""
    scenario_path = Path(options.scenario).resolve()
    scenario = load_scenario(scenario_path, options.overrides or None)
    if scenario.outcome is None:
        raise InputError("the scenario does not classify its runs", file=scenario_path, entry="montecarlo",
                         fix='add "montecarlo": {"outcome": {}} (the band the corridor is bounded by)')
    plant = core.plant_of(scenario)
    lift_to_drag = core.lift_to_drag_flown(plant, options.lift_to_drag, scenario_path)
    core.check_flyable(scenario, plant, options.overrides)
    signal, step = core.gamma0_signal(scenario), core.step_flown(scenario, options.step)
    out = Path(cast(Path, options.out))  # the API gives a temporary folder when the caller gives none
    with interrupts.deferred(), claimed(out, CORRIDOR_OUTPUTS):
        paths = core.write_scenarios(scenario, plant, ("lift_up", "lift_down"), lift_to_drag, step, out,
                                     options.overrides)
        found = core.searches(plant, paths, core.bounds(options.aim, scenario.outcome.band),
                              core.nominal_gamma0(scenario), options.angle_tolerance, options.tolerance,
                              options.bracket)
        result: dict[str, Any] = {"scenario": str(scenario_path), "plant": plant.kind, "control": plant.control,
                  "removed": list(plant.removed),
                  "lift_to_drag": plant.lift_to_drag if plant.kind == core.BANK else lift_to_drag,
                  "aim": options.aim, "tolerance_m": options.tolerance, "angle_tolerance_rad": options.angle_tolerance,
                  "step_s": step, "band_m": scenario.outcome.band, "nominal_gamma0": core.nominal_gamma0(scenario),
                  "bracket": list(options.bracket) if options.bracket is not None else None,
                  "sets": options.overrides,
                  "undispersed": core.undispersed(scenario)}
        result.update(_search(found, signal, options, load_scenario(paths["lift_up"])))
        result["width_rad"] = result["shallow"]["gamma0"] - result["steep"]["gamma0"]
        result["width_deg"] = math.degrees(result["width_rad"])
        result["units"] = UNITS
        from aotv_cosim.campaigns.figures import corridor_plot

        result["plots"] = [corridor_plot(out, result)]
        for bound in ("steep", "shallow"):  # summary.json's convention: a non-finite number as text
            b = result[bound]
            b["points"] = [(g, e if math.isfinite(e) else str(e)) for g, e in b["points"]]
            if b["bracket_errors"] is not None:
                b["bracket_errors"] = [e if math.isfinite(e) else str(e) for e in b["bracket_errors"]]
        write_json_atomically(out / "corridor.json", result)
    return result


def _search(searches: dict, signal, options, flown) -> dict:
    """{bound: result} of the `studies.corridor.EdgeSearch`es, their runs made on the options'
    backend (`flown`: one of the passes, loaded: the rows' columns)."""
    from aotv_cosim.campaigns import backends
    from aotv_cosim.campaigns.scenario_ref import ScenarioRef
    from aotv_cosim.campaigns.worker import columns

    backend = backends.opened(options, options.step_limit(flown), columns(flown))
    refs = {bound: ScenarioRef.of(search.path.resolve()) for bound, search in searches.items()}
    interrupted = True
    try:
        asked: dict = {}

        def ask(bound):
            gamma0 = searches[bound].next()
            while gamma0 is not None:
                run = len(asked)
                asked[run] = (bound, gamma0)
                backend.submit(refs[bound], [(run, {signal: gamma0})])
                gamma0 = searches[bound].next()

        for bound in searches:
            ask(bound)
        while backend.pending:
            for _, rows in backend.finished():
                for row in rows:
                    bound, gamma0 = asked[row["run"]]
                    searches[bound].tell(gamma0, core.apogee_error(row["status"], row["outcome"],
                                                                   row["outcome.apogee_error"], row["error"],
                                                                   searches[bound].path, signal, gamma0))
                    ask(bound)
        interrupted = False
    finally:
        backend.close(interrupted)
    return {bound: search.result for bound, search in searches.items()}
