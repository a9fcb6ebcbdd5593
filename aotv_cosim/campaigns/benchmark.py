"""Guidance benchmark: every law of a scenario set through the same dispersions.

A set is a folder of scenario files (e.g. scenarios/benchmark_seed000/), one law each, that share
one dispersion set and classify their runs (`montecarlo.outcome`). Each law is a campaign of N
runs with the same campaign seed, so run k of every law flies the same draws (`dispersion_sets`).
Written in the output folder: one campaign folder per law (rows, summary.json, report.md, plots),
`rows.csv` / `rows.parquet` with every law's rows and a `law` column, `scorecard.csv` and
`scorecard.json` (one row per law, units beside), `benchmark.png` (overlaid distributions) and
`report.md`. A set with an oracle (`oracle_score`) flies it first like a law, joins its per-run dv
to every law's rows by run and scores each law's dv penalty against it; `penalty.png` draws it.

CPU per run is the CPU time (user + system) of the local worker processes, read from
`resource.getrusage(RUSAGE_CHILDREN)` once their pool is shut down, plus this process's, divided
by the runs; on a Dask cluster the workers' CPU is not seen from here and it is None.
"""

import hashlib
import json
import resource
from pathlib import Path
from typing import cast

import numpy as np

from aotv_cosim.campaigns import limits as limits_of_runs
from aotv_cosim.campaigns import oracle_score
from aotv_cosim.campaigns.campaign import fly
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.statistics import completed_values
from aotv_cosim.campaigns.store import write_parquet
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.errors import InputError, ValidationFailed
from aotv_cosim.mission.outcome import OUTCOMES
from aotv_cosim.options import BenchmarkOptions
from aotv_cosim.options.checks import check_fits, law_name
from aotv_cosim.output.outdir import claimed, remove_written, written
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.loading import load_scenario, load_system
from aotv_cosim.status import Status

LAWS = "laws"
"""The folder of the output folder holding the scenarios generated for --law wirings."""
BENCHMARK_OUTPUTS = ("rows.csv", "rows.parquet", "rows.parquet.part", "scorecard.csv", "scorecard.json",
                     "scorecard.json.part", "report.md", "benchmark.png", "penalty.png")
"""The files a benchmark writes in its folder (besides laws/ and one campaign folder per law)."""
FLOWN = (Status.COMPLETED, Status.TERMINATED, Status.IMPACT)
"""The statuses of a run the law flew to an outcome the scorecard classifies (a pass, a terminate
request, the ground); the others (failed, error, out of range) are failures of the run, and a law
with nothing but those is reported failed (exit 1) and its rows not stored."""

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
convective (Sutton-Graves: peak_heat_rate, heat_load) and total (plus Tauber-Sutton radiative).
A per-run figure from elsewhere joins as a row column by the row's "run" (run k of every law
flies the same draws), then scores and plots as one more entry here and in
`benchmark_report.PANELS` (`score`, `score_columns` and `benchmark_report.plots` take them): the
dv penalty against the set's oracle does (`oracle_score.METRIC`, after the correction dv)."""


def shipped_sets() -> list:
    """Names of the sets shipped with the package (folders of scenarios under its scenarios/ whose
    name starts with "benchmark"), e.g. benchmark_seed000, benchmark_aerocapture/afe."""
    from aotv_cosim.studies.shipped import scenarios_dir

    base = scenarios_dir()
    folders = list(base.glob("benchmark*/")) + list(base.glob("benchmark*/*/"))
    return sorted(str(f.relative_to(base)) for f in folders
                  if f.is_dir() and f.name not in ("systems", "dispersions") and any(f.glob("*.json")))


def set_path(set_dir) -> Path:
    """SET as given when it exists, else the set of that name shipped with the package, from any
    folder: "benchmark_seed000" or "scenarios/benchmark_aerocapture/afe" (the clone's path) name
    scenarios/benchmark_seed000 and scenarios/benchmark_aerocapture/afe of the installed package."""
    from aotv_cosim.studies.shipped import scenarios_dir

    given = Path(set_dir)
    if given.exists() or given.is_absolute():
        return given
    parts = given.parts[1:] if given.parts[:1] == ("scenarios",) else given.parts
    shipped = scenarios_dir().joinpath(*parts) if parts else None
    return shipped if shipped is not None and shipped.exists() else given


def scenarios_of(set_dir) -> list:
    """The set's scenarios [(file, loaded Scenario)], sorted by file, checked before any run: each
    classifies its runs, all give the same campaign columns, each file name can name a law
    (`options.checks.law_name`) and at most one is the set's oracle (`oracle_score.of_set`). A set
    is a folder of scenarios or one scenario file. InputError for an empty or unusable set; an
    unknown one lists the shipped sets."""
    folder = set_path(set_dir)
    if folder.is_file() and _is_wiring(folder):
        raise InputError("a wiring, not a scenario set", file=folder,
                         fix=f"give it as --law {folder.name}, with a set as SET (e.g. benchmark_seed000)")
    if folder.is_file():
        paths = [folder]
    elif not folder.is_dir():
        raise InputError("not found, neither here nor among the shipped sets", file=folder,
                         fix="give a folder of scenario files, one law each, one scenario file, or the name of "
                             f"a shipped set: {', '.join(shipped_sets())}")
    else:  # not the files a command wrote there (a benchmark with --out SET: its scorecard.json)
        ours = written(folder)
        paths = [p for p in sorted(folder.glob("*.json")) if p.name not in ours]
    if not paths:
        raise InputError("the folder holds no scenario file", file=folder, fix="put one *.json scenario per law in it")
    for path in paths:
        law_name(path.stem, path, "SET")
    loaded = [(path, load_scenario(path)) for path in paths]
    _check_alike(loaded)
    oracle_score.of_set(loaded)
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


def law_scenarios(set_scenarios, law_files, work_dir, set_name="the set") -> dict:
    """{law: (scenario path, loaded Scenario)}: the set's oracle if it has one, the laws of the
    set's `scenarios_of` (file names), then each of `law_files` flown through the set's
    dispersions. A law file is a wiring (the set's first scenario that is not its oracle is flown
    with its "system" replaced by it: written to work_dir/laws/<law>.json; a problem found there is
    reported naming the law file) or a scenario whose dispersions and columns are the set's and
    which is no oracle (`oracle_score.refuse_as_law`); either is first checked against the set's
    contract (`contract`: every missing piece named in the law's own file). InputError for a clash
    of names, a name that would alias the output folder's own files (`options.checks.law_name`) or
    a law that does not fit."""
    from aotv_cosim.campaigns import contract

    needs = contract.of_set(set_scenarios) if law_files else []
    oracle = oracle_score.of_set(set_scenarios)
    laws = {path.stem: (path, scenario) for path, scenario in set_scenarios if path.stem == oracle}
    laws.update({path.stem: (path, scenario) for path, scenario in set_scenarios})
    set_names = {name.casefold() for name in laws}
    template, reference = oracle_score.first_law(set_scenarios)
    for law_file in map(Path, law_files):
        law = law_name(law_file.stem, law_file)
        if law.casefold() in {name.casefold() for name in laws}:  # a law is named by its file name
            where = "in the set" if law.casefold() in set_names else "given by another --law file"
            raise InputError(f"a law named {law!r} is already {where}", file=law_file, entry="--law",
                             fix="rename the law file")
        if not law_file.is_file():
            raise InputError("file not found", file=law_file, entry="--law",
                             fix="give a wiring or scenario file of your law")
        if _is_wiring(law_file):
            contract.check(needs, load_system(law_file), law_file, set_name)
            scenario_path = _flown_with(template, law_file, work_dir)
            scenario = _loaded_for(law_file, scenario_path, template)
        else:
            scenario_path = law_file.resolve()
            scenario = load_scenario(scenario_path)
            oracle_score.refuse_as_law(scenario, law_file)
            contract.check(needs, scenario.system, law_file, set_name,
                           entry_prefix=f"system ({Path(scenario.system.path).name}): ")
        if [d.__dict__ for d in scenario.dispersions] != [d.__dict__ for d in reference.dispersions]:
            raise InputError(f"its dispersions differ from those of {template.name}", file=law_file,
                             entry="dispersions", fix=f"use the dispersion_set of {template.name}, or give "
                                                      "the law's wiring instead of a scenario")
        _check_alike([(template, reference), (law_file, scenario)])
        laws[law] = (scenario_path, scenario)
    return laws


def _loaded_for(law_file: Path, generated: Path, template: Path):
    """The generated scenario `generated` (the set's `template` flown by the wiring `law_file`)
    loaded; a problem it has is reported naming the user's wiring, with the set's need said, and
    the generated file is removed (the package wrote it)."""
    try:
        return load_scenario(generated)
    except InputError as exc:
        generated.unlink(missing_ok=True)
        problems = [InputError(f"{p.cause} (the set's scenario {template.name} asks for it: a law flown in this set "
                               "must provide it)", file=law_file, entry=p.entry, fix=p.fix)
                    if str(p.file) == str(generated) else p for p in getattr(exc, "problems", [exc])]
        raise (problems[0] if len(problems) == 1 else ValidationFailed(problems)) from None


def _is_wiring(path: Path) -> bool:
    """True if the JSON file `path` is a wiring (it has components), not a scenario."""
    from aotv_cosim.model.documents import strict_json

    try:
        doc = strict_json(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False  # the scenario loader reports what is wrong with it
    return isinstance(doc, dict) and "components" in doc


def _flown_with(template: Path, wiring: Path, out: Path) -> Path:
    """The template scenario with its "system" replaced by `wiring`, written to out/laws/<law>.json
    (every relative path of the template made absolute); a file there the package did not write is
    refused, not overwritten."""
    from aotv_cosim.model.documents import strict_json

    doc = strict_json(template.read_text(encoding="utf-8"))
    doc.pop("$schema", None)
    doc.get("montecarlo", {}).pop("oracle", None)  # a set holding only its oracle: the law is no oracle
    if "dispersion_set" in doc:
        doc["dispersion_set"] = str((template.parent / doc["dispersion_set"]).resolve())
    doc["system"] = str(wiring.resolve())
    doc["description"] = f"{wiring.stem}: the scenario {template.resolve()} flown by the wiring {wiring.resolve()}"
    folder = out / LAWS
    name = f"{LAWS}/{wiring.stem}.json"
    if (folder / f"{wiring.stem}.json").exists() and name not in written(out):
        raise InputError(f"{name} is there and was not written by aotv-cosim: it would be overwritten", file=out,
                         entry="--out", fix=f"move {out / name} away or choose another --out")
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


def score_columns(metrics=METRICS, roles=False) -> list:
    """(column, unit) of the scorecard of `metrics` (`METRICS`), in order; with `roles`, the role
    of each row after the law (`oracle_score.ROLE`: the set's oracle or a law)."""
    cols = [("law", "")] + ([(oracle_score.ROLE, "")] if roles else []) + \
        [("runs", "1"), ("capture_rate", "%")] + [(o, "1") for o in OUTCOMES]
    for column, _, unit, percents in metrics:
        cols += [(f"{column.split('.', 1)[1]}_p{p:g}", unit) for p in percents]
    return [*cols, ("cpu_per_run", "s")]


def score(law, rows, cpu_per_run, metrics=METRICS) -> dict:
    """The scorecard row of one law's campaign rows over `metrics` (`METRICS`; None: a figure the
    runs do not give)."""
    counts = {o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES}
    card = {"law": law, "runs": len(rows), "capture_rate": 100.0 * counts["captured"] / len(rows), **counts}
    for column, _, _, percents in metrics:
        x = completed_values(rows, column)
        for p in percents:
            card[f"{column.split('.', 1)[1]}_p{p:g}"] = float(np.percentile(x, p)) if len(x) else None
    card["cpu_per_run"] = cpu_per_run
    return card


def run_benchmark(options: BenchmarkOptions, echo=None) -> dict:
    """Fly every law of `options.scenario_set`, and each of `options.laws` (`law_scenarios`), for
    `options.runs` runs into `options.out`; returns (and writes as scorecard.json) the set, runs,
    seed, "status", "oracle" (the law name of the set's oracle, None without one), "scorecard" (one
    dict per law, the oracle's first), its "units", "wall_time_s" of the campaigns flown now,
    "laws" ({law: {scenario, wall_time_s, reused, completed, first_failure}}), "failed_laws"
    (those whose runs all failed) and "plots". With an oracle, every law's rows get its dv and the
    dv penalty by run, and the scorecard a role and the penalty's percentiles (`oracle_score`).

    A law whose scenario, FMUs, dispersions, seed and N are those of a campaign finished before
    (`campaign_key`) is not flown again: its rows are read from `stored_rows_dir()` (unless
    `options.reuse` is False). A campaign flown to the end is stored, unless no run of it
    completed or a run was lost with its worker (a crash, a hang, the memory limit: causes of this
    machine, not of the law). echo(text), if given, is told which laws are reused and which are
    flown. SIGINT/SIGTERM stop the benchmark after the law being flown (its campaign folder keeps
    its finished runs): the result has status "interrupted", the laws done so far, and the
    folder's scorecard files are not written. `options.fmi_calls` does not change the rows, so it
    is not part of the key."""
    out = Path(cast(Path, options.out))  # the API gives a temporary folder when the caller gives none
    set_scenarios = scenarios_of(options.scenario_set)
    created = not out.exists()
    try:
        with interrupts.deferred(), claimed(out, BENCHMARK_OUTPUTS):
            flown = law_scenarios(set_scenarios, options.laws, out, str(options.scenario_set))  # checked before any run
            limits = limits_of_runs.of_set(set_scenarios)  # the set's stated limits, for every law
            oracle = oracle_score.of_set(set_scenarios)
            # every law's rows are kept for the scorecard, beside those of the law being flown
            joined = len(oracle_score.COLUMNS) if oracle else 0
            check_fits(options.runs * (len(flown) + 1), len(columns(set_scenarios[0][1])) + 1 + joined,
                       options.scenario_set)
            return _benchmark(options, out, flown, limits, oracle, echo)
    except InputError:
        if created:  # refused before any run: leave no folder behind
            remove_written(out)
        raise


def _benchmark(options, out, flown, limits, oracle, echo) -> dict:
    summaries: dict = {}
    rows_by_law: dict = {}
    cpu: dict = {}
    units: dict = {}
    status = Status.COMPLETED
    for law, (path, scenario) in flown.items():
        key = campaign_key(path, scenario, options.runs, options.seed)
        stored = _stored(key) if options.reuse else None
        if stored is not None:
            rows, record = stored
            if echo:
                echo(f"{law}: {options.runs} stored runs reused (same scenario, FMUs, dispersions, seed and N)")
        else:
            if echo:
                echo(f"{law}: flying {options.runs} runs")
            rows, record = _fly(law, path, scenario, out, options)
            if record["status"] == Status.INTERRUPTED:
                status = Status.INTERRUPTED
                summaries[law] = _law_summary(path, record, rows, reused=False)
                break
            if _storable(rows, options.runs):
                _store(key, rows, list(rows[0]), record)
        summaries[law] = _law_summary(path, record, rows, reused=stored is not None)
        rows_by_law[law], cpu[law] = rows, record["card"].get("cpu_per_run")
        units = units or {"law": "", **record["units"]}
    scored = oracle in rows_by_law  # an interruption before the oracle was flown leaves none to score against
    if scored:
        rows_by_law = oracle_score.joined(rows_by_law, oracle)
        units.update(oracle_score.COLUMNS)
    metrics = oracle_score.with_penalty(METRICS) if scored else METRICS
    cards = [_card(law, rows, cpu[law], metrics, limits, flown[law][1], oracle) for law, rows in rows_by_law.items()]
    band = next(iter(flown.values()))[1].outcome.band
    result = {"set": str(set_path(options.scenario_set).resolve()), "runs": options.runs, "seed": options.seed,
              "status": status.value, "oracle": oracle, "scorecard": cards,
              "units": dict(score_columns(metrics, roles=oracle is not None) + limits_of_runs.columns(limits)),
              "wall_time_s": sum(s["wall_time_s"] for s in summaries.values()), "laws": summaries,
              "failed_laws": [law for law, s in summaries.items() if not s["flown"] and s["runs"]],
              "plots": []}
    if status == Status.INTERRUPTED:
        result["interrupted_law"] = law
        return result
    return _write_results(out, result, rows_by_law, units, band)


def _card(law, rows, cpu_per_run, metrics, limits, scenario, oracle) -> dict:
    """The scorecard row of a law (`score` over `metrics`, the limits' figures), its role when the
    set has an `oracle`."""
    card = {**score(law, rows, cpu_per_run, metrics), **limits_of_runs.score(rows, limits, scenario.outcome.vehicle)}
    if oracle is not None:
        card[oracle_score.ROLE] = oracle_score.ORACLE if law == oracle else oracle_score.LAW
    return card


def _law_summary(path, record, rows, reused) -> dict:
    """A law's entry of the result: its scenario, wall time, whether its rows were reused, its runs,
    how many completed, how many were flown to an outcome (`FLOWN`), and its first failed run {run,
    status, error, where: the user's file and line when flown now} (None if every run was flown)."""
    failed = [r for r in rows if r["status"] not in FLOWN]
    first = None
    if failed:
        first = {"run": failed[0]["run"], "status": str(failed[0]["status"]), "error": failed[0]["error"]}
        found = record.get("failures")
        if found and found["first"]["run"] == first["run"]:
            first["where"] = found["first"]["where"]
    return {"scenario": str(path), "wall_time_s": 0.0 if reused else record["wall_time_s"], "reused": reused,
            "runs": len(rows), "completed": sum(r["status"] == Status.COMPLETED for r in rows),
            "flown": len(rows) - len(failed), "first_failure": first}


def _storable(rows, runs) -> bool:
    """Rows worth reusing: all `runs` of them, at least one flown to an outcome (`FLOWN`), none lost
    with its worker."""
    lost = ("crash: ", "step timeout: ", "memory: ")
    return len(rows) == runs and any(r["status"] in FLOWN for r in rows) and \
        not any(str(r["error"]).startswith(lost) for r in rows)


def _fly(law, path, scenario, out, options):
    """(rows, record) of a campaign of the law (its file `path`, loaded as `scenario`) flown now
    into out/<law>: what an earlier benchmark wrote there is removed first, nothing else."""
    import pyarrow.parquet as pq

    folder = out / law
    if folder.is_dir():
        remove_written(folder)
    cpu0 = _cpu_seconds()
    summary = fly(ScenarioRef.of(Path(path).resolve()), scenario, options, folder)
    rows = pq.read_table(folder / "rows.parquet").to_pylist()
    cpu = (_cpu_seconds() - cpu0) / len(rows) if options.scheduler is None and rows else None
    record = {"card": score(law, rows, cpu) if rows else {"law": law, "runs": 0},
              "units": summary["units"], "wall_time_s": summary["wall_time_s"], "status": summary["status"],
              "failures": summary["failures"]}
    return rows, record


def _write_results(out, result, rows_by_law, units, band) -> dict:
    from aotv_cosim.campaigns import benchmark_report

    cards, units_of_scores = result["scorecard"], result["units"]
    _write_scorecard(out, cards, units_of_scores)
    every_row = [{"law": law, **r} for law, rows in rows_by_law.items() for r in rows]
    names = list(every_row[0])
    write_parquet(every_row, names, out / "rows.parquet", units)
    _write_rows_csv(out / "rows.csv", every_row, names)
    oracle = result["oracle"] if result["oracle"] in rows_by_law else None
    result["plots"] = benchmark_report.plots(out, rows_by_law, band, benchmark_report.panels_of(rows_by_law, oracle),
                                             oracle)
    if oracle is not None:
        result["plots"].append(benchmark_report.penalty_plot(out, rows_by_law, oracle))
    elif "penalty.png" in written(out):  # an earlier benchmark's, of a set with an oracle: not this one's
        (out / "penalty.png").unlink(missing_ok=True)
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

    from aotv_cosim.campaigns.store import (
        csv_cell,  # the campaign rows' own cell format
    )

    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(names)
        w.writerows([[csv_cell(n, r[n]) for n in names] for r in rows])
