"""Every law of a benchmark scored against its set's oracle, run by run.

A set may hold one oracle: a scenario marked `"montecarlo": {"oracle": true}` (`Scenario.oracle`)
that flies, in each dispersed run, the best pass that run allows with perfect knowledge (the
aerocapture sets' oracle.json: OracleBankGuidance, the minimum-dv pass found with the run's own
vehicle, atmosphere and actuator). The benchmark flies it like a law (its rows stored and reused
the same way) and, since run k of every law flies the same draws, joins its rows to every law's
by the row's "run":

- `oracle.dv_total` (m/s): the oracle's correction dv in that run (its row's `outcome.dv_total`,
  as it is);
- `oracle.dv_penalty` (m/s): the law's `outcome.dv_total` minus the oracle's, in a run both
  captured; nan otherwise. A run the law did not capture (skip out, undershoot, impact, failed)
  has no finite penalty: it counts against the law in its capture rate and outcome classes, not
  in the penalty; a run the oracle did not capture has no reference to be scored against. The
  oracle's own rows have no penalty (nan).

The scorecard gains `role` ("oracle" for the oracle's row, the bound, "law" for the competitors)
and `dv_penalty_p50`, `dv_penalty_p99.865` (m/s): the penalty's percentiles over the runs with a
finite one (`METRIC`, scored like every `benchmark.METRICS` entry); the oracle's row has none. A
negative penalty is a run where the law spent less dv than the oracle's pass: the oracle's profile
family (two arcs) is a bound only to its own accuracy (docs/benchmark.md, "The oracle").

Why a `--law` cannot be the oracle: the oracle is the set's yardstick, like its dispersions. The
penalties of the set's laws are measured against it and their scorecards compared across
benchmarks of the set; a law given on the command line is a competitor scored against that bound,
and if it could declare itself the oracle it would change every other law's penalty (or be refused
as a second oracle in the shipped sets). A set of your own names its oracle in its folder.
"""

import math

from aotv_cosim.errors import InputError

ORACLE_DV = "oracle.dv_total"
"""Row column: the oracle's correction dv in the same run, m/s."""
PENALTY = "oracle.dv_penalty"
"""Row column: the law's correction dv minus the oracle's in a run both captured, m/s (else nan)."""
COLUMNS = ((ORACLE_DV, "m/s"), (PENALTY, "m/s"))
"""(row column, unit) joined to every law's rows."""
METRIC = (PENALTY, "dv penalty against the oracle", "m/s", (50.0, 99.865))
"""The penalty's scorecard entry, as `benchmark.METRICS` gives them: its p50 and p99.865 over the
runs with a finite penalty (both captured)."""
ROLE, ORACLE, LAW = "role", "oracle", "law"
"""The scorecard's role column and its values."""


def of_set(set_scenarios) -> "str | None":
    """The law name (file stem) of the oracle of a set's [(path, loaded Scenario)], None when the
    set has none; InputError naming the second oracle's file when there are two."""
    oracles = [path for path, scenario in set_scenarios if scenario.oracle]
    if len(oracles) > 1:
        raise InputError(f"a second oracle: {oracles[0].name} is the set's oracle already", file=oracles[1],
                         entry="montecarlo.oracle", fix='keep "oracle": true in one scenario of the set: the '
                                                        "others are laws scored against it")
    return oracles[0].stem if oracles else None


def first_law(set_scenarios):
    """The set's first (path, Scenario) that is not its oracle (the first one if all are): the
    scenario a `--law` wiring is flown in and the set's contract is read from."""
    return next(((path, s) for path, s in set_scenarios if not s.oracle), set_scenarios[0])


def refuse_as_law(scenario, law_file) -> None:
    """InputError when a `--law` scenario declares itself an oracle (module docstring: why)."""
    if scenario.oracle:
        raise InputError("a law given with --law cannot be the set's oracle (the yardstick every law of the set "
                         "is scored against)", file=law_file, entry="montecarlo.oracle",
                         fix='drop "oracle": true to benchmark it as a law, or put it in a set of your own as '
                             "that set's oracle")


def joined(rows_by_law: dict, oracle: str) -> dict:
    """{law: its rows with `ORACLE_DV` and `PENALTY` added} of {law: campaign rows} (every law of
    one benchmark, the oracle's rows among them), joined by the rows' "run"."""
    reference = {row["run"]: row for row in rows_by_law[oracle]}
    return {law: [{**row, **_against(row, reference.get(row["run"]), law == oracle)} for row in rows]
            for law, rows in rows_by_law.items()}


def _against(row, reference, is_oracle) -> dict:
    """The joined columns of one row, given the oracle's row of the same run (None: none)."""
    dv = math.nan if reference is None else float(reference["outcome.dv_total"])
    scored = not is_oracle and reference is not None and _captured(row) and _captured(reference)
    return {ORACLE_DV: dv, PENALTY: float(row["outcome.dv_total"]) - dv if scored else math.nan}


def _captured(row) -> bool:
    return row.get("outcome") == "captured"


def with_penalty(metrics) -> tuple:
    """`metrics` (`benchmark.METRICS`) with the penalty's entry after the correction dv's."""
    at = next((k + 1 for k, entry in enumerate(metrics) if entry[0] == "outcome.dv_total"), len(metrics))
    return (*metrics[:at], METRIC, *metrics[at:])
