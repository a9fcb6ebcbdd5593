"""Guidance benchmark: every law of a scenario set through the same dispersions.

A set is a folder of scenario files (e.g. scenarios/benchmark_seed000/), one law each, that share
one dispersion set and classify their runs (`montecarlo.outcome`). Each law is a campaign of N
runs with the same campaign seed, so run k of every law flies the same draws (`dispersion_sets`).
Written in the output folder: one campaign folder per law (rows, summary.json, report.md, plots),
`rows.csv` / `rows.parquet` with every law's rows and a `law` column, `scorecard.csv` and
`scorecard.json` (one row per law, units beside), `benchmark.png` (overlaid distributions) and
`report.md`.

CPU per run is the CPU time (user + system) of the local worker processes, read from
`resource.getrusage(RUSAGE_CHILDREN)` once their pool is shut down, plus this process's, divided
by the runs; on a Dask cluster the workers' CPU is not seen from here and it is None.
"""

import hashlib
import json
import resource
from pathlib import Path

import numpy as np

from aotv_cosim.campaigns import limits as limits_of_runs
from aotv_cosim.campaigns.campaign import CampaignOptions, fly
from aotv_cosim.campaigns.statistics import completed_values
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.mission.outcome import OUTCOMES
from aotv_cosim.campaigns.store import write_parquet
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.errors import InputError
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.status import Status

PERCENT = (0.135, 50.0, 99.865)

METRICS = (("outcome.apogee_error", "apogee error", "m", PERCENT),
           ("outcome.dv_total", "correction dv", "m/s", PERCENT),
           ("outcome.peak_heat_rate", "peak heat rate", "W/m2", (50.0, 99.865)),
           ("outcome.heat_load", "heat load", "J/m2", (50.0, 99.865)),
           ("outcome.peak_heat_rate_total", "peak total heat rate", "W/m2", (50.0, 99.865)),
           ("outcome.heat_load_total", "total heat load", "J/m2", (50.0, 99.865)),
           ("outcome.peak_load_factor", "peak load factor", "1", (50.0, 99.865)),
           ("outcome.int_abs_u", "int |u| dt", "m/s", (50.0, 99.865)),
           ("outcome.int_u2", "int u^2 dt", "m2/s3", (50.0,)))
"""(row column, label, unit, percentiles) of the scorecard; percentiles over the completed runs
whose value is finite (an unbound exit orbit has no finite apogee error). The heating is shown
convective (Sutton-Graves: peak_heat_rate, heat_load) and total (plus Tauber-Sutton radiative)."""


def set_path(set_dir) -> Path:
    """SET as given when it exists, else the set of that name shipped with the package (e.g.
    "benchmark_seed000": scenarios/benchmark_seed000 of the installed package)."""
    from aotv_cosim.studies.shipped import scenarios_dir

    given = Path(set_dir)
    shipped = scenarios_dir() / given
    return shipped if not given.exists() and not given.is_absolute() and shipped.exists() else given


def scenarios_of(set_dir) -> list:
    """The set's scenarios [(file, loaded Scenario)], sorted by file, checked before any run: each
    classifies its runs and all give the same campaign columns. A set is a folder of scenarios or
    one scenario file. InputError for an empty or unusable set."""
    folder = set_path(set_dir)
    if folder.is_file() and _is_wiring(folder):
        raise InputError("a wiring, not a scenario set", file=folder,
                         fix=f"give it as --law {folder.name}, with a set as SET (e.g. benchmark_seed000)")
    if folder.is_file():
        paths = [folder]
    elif not folder.is_dir():
        raise InputError("not found", file=folder,
                         fix="give a folder of scenario files, one law each, one scenario file, or the "
                             "name of a shipped set (benchmark_seed000)")
    else:
        paths = sorted(folder.glob("*.json"))
    if not paths:
        raise InputError("the folder holds no scenario file", file=folder, fix="put one *.json scenario per law in it")
    loaded = [(path, load_scenario(path)) for path in paths]
    _check_alike(loaded)
    return loaded


def _check_alike(loaded) -> None:
    """InputError unless every (path, scenario) classifies its runs and gives the first's columns."""
    first = None
    for path, scenario in loaded:
        if scenario.outcome is None:
            raise InputError("the scenario does not classify its runs", file=path, entry="montecarlo",
                             fix='add "montecarlo": {"outcome": {}} (and record the vehicle h, v, gamma)')
        first = first or (loaded[0][0], columns(scenario))
        if columns(scenario) != first[1]:
            raise InputError(f"its campaign columns differ from those of {first[0].name}", file=path,
                             entry="record", fix="record the same signals and disperse the same values in every law")


def law_scenarios(set_scenarios, law_files, work_dir) -> dict:
    """{law: (scenario path, loaded Scenario)}: the laws of the set's `scenarios_of` (file names),
    then each of `law_files` flown through the set's dispersions. A law file is a wiring (the
    set's first scenario is flown with its "system" replaced by it: written to
    work_dir/laws/<law>.json) or a scenario whose dispersions and columns are the set's.
    InputError for a clash of names or a law that does not fit."""
    laws = {path.stem: (path, scenario) for path, scenario in set_scenarios}
    set_names = set(laws)
    template, reference = set_scenarios[0]
    for law_file in map(Path, law_files):
        law = law_file.stem
        if law in laws:  # a law is named by its file name: two --law files may clash too
            where = "in the set" if law in set_names else "given by another --law file"
            raise InputError(f"a law named {law!r} is already {where}", file=law_file, entry="--law",
                             fix="rename the law file")
        if not law_file.is_file():
            raise InputError("file not found", file=law_file, entry="--law",
                             fix="give a wiring or scenario file of your law")
        scenario_path = _flown_with(template, law_file, work_dir / "laws") if _is_wiring(law_file) \
            else law_file.resolve()
        scenario = load_scenario(scenario_path)
        if [d.__dict__ for d in scenario.dispersions] != [d.__dict__ for d in reference.dispersions]:
            raise InputError(f"its dispersions differ from those of {template.name}", file=law_file,
                             entry="dispersions", fix=f"use the dispersion_set of {template.name}, or give "
                                                      "the law's wiring instead of a scenario")
        _check_alike([(template, reference), (law_file, scenario)])
        laws[law] = (scenario_path, scenario)
    return laws


def _is_wiring(path: Path) -> bool:
    """True if the JSON file `path` is a wiring (it has components), not a scenario."""
    from aotv_cosim.model.documents import strict_json

    try:
        doc = strict_json(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False  # the scenario loader reports what is wrong with it
    return isinstance(doc, dict) and "components" in doc


def _flown_with(template: Path, wiring: Path, folder: Path) -> Path:
    """The template scenario with its "system" replaced by `wiring`, written to folder/<law>.json
    (every relative path of the template made absolute)."""
    from aotv_cosim.model.documents import strict_json

    doc = strict_json(template.read_text(encoding="utf-8"))
    doc.pop("$schema", None)
    if "dispersion_set" in doc:
        doc["dispersion_set"] = str((template.parent / doc["dispersion_set"]).resolve())
    doc["system"] = str(wiring.resolve())
    doc["description"] = f"{wiring.stem}: the scenario {template.resolve()} flown by the wiring {wiring.resolve()}"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{wiring.stem}.json"
    path.write_text(json.dumps(doc, indent=2) + "\n")
    return path.resolve()


def campaign_key(scenario_path, scenario, runs: int, seed: int) -> str:
    """SHA-256 of what a law's campaign rows depend on: the scenario's settings (not its file
    paths or description), each component's FMU GUID, parameter values and the connections,
    the dispersions, the seed and N (`scenario`: the file `scenario_path` loaded). Equal keys give
    equal rows, so stored rows are reused."""
    from aotv_cosim.model.documents import strict_json

    doc = strict_json(Path(scenario_path).read_text(encoding="utf-8"))
    settings = {k: v for k, v in doc.items() if k not in ("$schema", "description", "system", "dispersion_set")}
    system = scenario.system
    key = {"scenario": settings, "runs": runs, "seed": seed,
           "components": {name: {"guid": c.fmu.guid, "parameters": c.parameters}
                          for name, c in system.components.items()},
           "connections": sorted(map(str, system.connections)),
           "dispersions": [d.__dict__ for d in scenario.dispersions]}
    return hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()


def stored_rows_dir() -> Path:
    """Where finished law campaigns are kept for reuse: <FMU cache>/benchmark-rows."""
    from aotv_cosim.fmu.build import cache_dir

    return cache_dir() / "benchmark-rows"


def _stored(key):
    """(rows, record) of a stored campaign with this key, or None."""
    import pyarrow.parquet as pq

    base = stored_rows_dir() / key[:32]
    try:
        record = json.loads(base.with_suffix(".json").read_text())
        rows = pq.read_table(base.with_suffix(".parquet")).to_pylist()
    except (OSError, ValueError):
        return None
    return (rows, record) if record.get("key") == key else None


def _store(key, rows, names, record) -> None:
    """Keep a finished campaign's rows (Parquet) and record (JSON: card, units, wall time)."""
    base = stored_rows_dir() / key[:32]
    base.parent.mkdir(parents=True, exist_ok=True)
    write_parquet(rows, names, base.with_suffix(".parquet"), record["units"])
    write_json_atomically(base.with_suffix(".json"), {**record, "key": key})


def _cpu_seconds():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def score_columns() -> list:
    """(column, unit) of the scorecard, in order."""
    cols = [("law", ""), ("runs", "1"), ("capture_rate", "%")] + [(o, "1") for o in OUTCOMES]
    for column, _, unit, percents in METRICS:
        cols += [(f"{column.split('.', 1)[1]}_p{p:g}", unit) for p in percents]
    return cols + [("cpu_per_run", "s")]


def score(law, rows, cpu_per_run) -> dict:
    """The scorecard row of one law's campaign rows (None: a figure the runs do not give)."""
    counts = {o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES}
    card = {"law": law, "runs": len(rows), "capture_rate": 100.0 * counts["captured"] / len(rows), **counts}
    for column, _, _, percents in METRICS:
        x = completed_values(rows, column)
        for p in percents:
            card[f"{column.split('.', 1)[1]}_p{p:g}"] = float(np.percentile(x, p)) if len(x) else None
    card["cpu_per_run"] = cpu_per_run
    return card


def run_benchmark(set_dir, runs, out_dir, workers=1, seed=0, scheduler=None, progress=True, laws=(),
                  echo=None, reuse=True, fmi_calls=None) -> dict:
    """Fly every law of the set, and each of the `laws` files (`law_scenarios`), for `runs` runs;
    returns (and writes as scorecard.json) the set, runs, seed, "scorecard" (one dict per law),
    its "units", "wall_time_s" of the campaigns flown now, "laws" ({law: {scenario, wall_time_s,
    reused}}) and "plots".

    A law whose scenario, FMUs, dispersions, seed and N are those of a campaign finished before
    (`campaign_key`) is not flown again: its rows are read from `stored_rows_dir()` (unless
    `reuse` is False; every campaign flown to the end is stored). echo(text),
    if given, is told which laws are reused and which are flown. fmi_calls: how the runs call the
    FMUs (`CampaignOptions`); the rows do not depend on it, so it is not part of the key."""
    out = Path(out_dir)
    set_scenarios = scenarios_of(set_dir)
    flown = law_scenarios(set_scenarios, laws, out)  # every law checked before anything is written
    limits = limits_of_runs.of_set(set_scenarios)  # the set's stated limits, for every law
    out.mkdir(parents=True, exist_ok=True)
    cards, summaries, every_row, names, units = [], {}, [], None, None
    for law, (path, scenario) in flown.items():
        key = campaign_key(path, scenario, runs, seed)
        stored = _stored(key) if reuse else None
        if stored is not None:
            rows, record = stored
            if echo:
                echo(f"{law}: {runs} stored runs reused (same scenario, FMUs, dispersions, seed and N)")
            summaries[law] = {"scenario": str(path), "wall_time_s": 0.0, "reused": True}
        else:
            if echo:
                echo(f"{law}: flying {runs} runs")
            options = CampaignOptions(workers, seed, scheduler, progress=progress, fmi_calls=fmi_calls)
            rows, record = _fly(law, path, scenario, runs, out, options)
            summaries[law] = {"scenario": str(path), "wall_time_s": record["wall_time_s"], "reused": False}
            if record["status"] == Status.COMPLETED and len(rows) == runs:
                _store(key, rows, list(rows[0]), record)
        cards.append({**record["card"], "law": law, **limits_of_runs.score(rows, limits)})
        names = names or ["law"] + list(rows[0])
        units = units or {"law": "", **record["units"]}
        every_row += [{"law": law, **r} for r in rows]
    band = next(iter(flown.values()))[1].outcome.get("band", 10e3)
    return _write_results(set_dir, runs, seed, out, cards, summaries, every_row, names, units, float(band),
                          limits_of_runs.columns(limits))


def _fly(law, path, scenario, runs, out, options):
    """(rows, record) of a campaign of the law (its file `path`, loaded as `scenario`) flown now
    into out/<law> (an earlier benchmark's campaign there is replaced)."""
    import shutil

    import pyarrow.parquet as pq

    folder = out / law
    if (folder / "campaign.json").is_file():
        shutil.rmtree(folder)
    cpu0 = _cpu_seconds()
    summary = fly(ScenarioRef.of(Path(path).resolve()), scenario, runs, folder, options)
    cpu = (_cpu_seconds() - cpu0) / runs if options.scheduler is None else None
    rows = pq.read_table(folder / "rows.parquet").to_pylist()
    record = {"card": score(law, rows, cpu), "units": summary["units"], "wall_time_s": summary["wall_time_s"],
              "status": summary["status"]}
    return rows, record


def _write_results(set_dir, runs, seed, out, cards, summaries, every_row, names, units, band,
                   limit_columns) -> dict:
    from aotv_cosim.campaigns import benchmark_report

    units_of_scores = dict(score_columns() + limit_columns)
    result = {"set": str(set_path(set_dir).resolve()), "runs": runs, "seed": seed, "scorecard": cards,
              "units": units_of_scores, "wall_time_s": sum(s["wall_time_s"] for s in summaries.values()),
              "laws": summaries}
    _write_scorecard(out, cards, units_of_scores)
    write_parquet(every_row, names, out / "rows.parquet", units)
    _write_rows_csv(out / "rows.csv", every_row, names)
    result["plots"] = benchmark_report.plots(out, {law: [r for r in every_row if r["law"] == law]
                                                   for law in summaries}, band)
    (out / "report.md").write_text(benchmark_report.markdown(result, cards, units_of_scores))
    write_json_atomically(out / "scorecard.json", result)
    return result


def _write_scorecard(out, cards, units):
    import csv

    with open(out / "scorecard.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow([f"{c} [{u}]" if u else c for c, u in units.items()])
        w.writerows([["" if card[c] is None else repr(card[c]) if isinstance(card[c], float) else card[c]
                     for c in units] for card in cards])


def _write_rows_csv(path, rows, names):
    import csv

    from aotv_cosim.campaigns.store import csv_cell  # the campaign rows' own cell format

    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(names)
        w.writerows([[csv_cell(n, r[n]) for n in names] for r in rows])
