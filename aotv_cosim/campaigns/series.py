"""A campaign's kept trajectories (`--keep-series`): series.parquet and the Monte Carlo overlay.

series.parquet is long: one row per kept time of each run (columns run, time and the recorded
signals, units in the field metadata), about 200 rows a run (`worker.SERIES_POINTS`). A resumed
campaign keeps the series of the runs of earlier sessions. trajectories.png draws every run faint
and the nominal (the scenario without dispersions, flown once more here) bold: altitude against
speed and against time, in km and km/s.
"""

from pathlib import Path

from aotv_cosim.output.run_files import replaced_atomically
from aotv_cosim.output.series import TIME_UNIT


def write_series(out: Path, series: dict, scenario, ref, options, make_plots) -> list:
    """Write series.parquet from {run: {"time": [...], signal: [...]}} (merged with the file a
    resumed campaign left); returns the plot files written. `scenario`: the campaign's, loaded
    from `ref` (`scenario_ref.ScenarioRef`), flown with the campaign's `options`."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from aotv_cosim.campaigns.worker import Runner

    signals = [s for s in next(iter(series.values()), {}) if s != "time"]
    path = out / "series.parquet"
    if path.is_file():  # a resumed campaign: the earlier sessions' runs
        earlier = pq.read_table(path).to_pydict()
        for k in sorted(set(earlier["run"]) - set(series)):
            picks = [i for i, run in enumerate(earlier["run"]) if run == k]
            series[k] = {name: [earlier[name][i] for i in picks] for name in ["time", *signals]}
    runs = sorted(k for k in series if series[k])
    columns = {"run": [k for k in runs for _ in series[k]["time"]]}
    for name in ["time", *signals]:
        columns[name] = [x for k in runs for x in series[k][name]]
    units = {"run": "", "time": TIME_UNIT, **{s: scenario.system.variable(s).unit for s in signals}}
    schema = pa.schema([pa.field(n, pa.int64() if n == "run" else pa.float64(), metadata={b"unit": units[n].encode()})
                        for n in columns])
    with replaced_atomically(path) as tmp:
        pq.write_table(pa.table(columns, schema=schema), tmp)
    vehicle = scenario.outcome.vehicle if scenario.outcome is not None else "vehicle"
    if not make_plots or not {f"{vehicle}.h", f"{vehicle}.v"} <= set(signals):
        return []
    nominal = Runner(ref, options).run(-1, {}).get("series", {})
    return [trajectories(out, [series[k] for k in runs], nominal, vehicle)]


def trajectories(out: Path, runs: list, nominal: dict, vehicle: str) -> str:
    """trajectories.png: altitude (km) against speed (km/s) and against time (s), every run faint,
    the nominal bold."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aotv_cosim.campaigns.figures import axes_style

    h, v = f"{vehicle}.h", f"{vehicle}.v"
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    alpha = max(0.03, min(0.4, 8.0 / max(1, len(runs))))
    for run in runs:
        left.plot([x / 1e3 for x in run[v]], [x / 1e3 for x in run[h]], color="tab:blue", lw=0.6, alpha=alpha)
        right.plot(run["time"], [x / 1e3 for x in run[h]], color="tab:blue", lw=0.6, alpha=alpha)
    if nominal:
        left.plot([x / 1e3 for x in nominal[v]], [x / 1e3 for x in nominal[h]], color="black", lw=2, label="nominal")
        right.plot(nominal["time"], [x / 1e3 for x in nominal[h]], color="black", lw=2, label="nominal")
    left.plot([], [], color="tab:blue", lw=0.6, label=f"{len(runs)} dispersed runs")
    left.set_xlabel(f"{v} [km/s]", fontsize=9)
    right.set_xlabel("time [s]", fontsize=9)
    for ax in (left, right):
        ax.set_ylabel(f"{h} [km]", fontsize=9)
        axes_style(ax)
    left.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "trajectories.png", dpi=90)
    plt.close(fig)
    return "trajectories.png"
