"""What the Python API returns: one run (`Result`) or one Monte Carlo campaign (`Campaign`).

Both carry their numbers as pandas DataFrames and the unit of every column as the FMUs'
modelDescriptions declare it (SI; "1" for dimensionless), in `.units` and in each DataFrame's
`attrs["units"]`.
"""

import pandas as pd

from aotv_cosim.output.summary import RunSummary
from aotv_cosim.status import Status


class Result:
    """One co-simulation run.

    timeseries: DataFrame indexed by time (s), one column per recorded signal 'comp.var' (float64;
    int32 for an Integer or Enumeration, bool for a Boolean, text for a String);
    units: {'time': 's', signal: unit}; summary: the summary dict (as in summary.json);
    run_summary: the same as a `summary.RunSummary`;
    status: 'completed', 'terminated' (an FMU asked to end the run), 'failed' or 'interrupted'; event: the located
    stop-condition crossing ({'signal', 'threshold', 'time', 'values'}) or None; expectations: the checked numbers
    (measured, expected, allowed error, passed, source); outcome: the run classified (see the
    property); out: the output folder or None.
    """

    def __init__(self, summary: RunSummary, columns, times, rows, decoder=None, out=None):
        self.run_summary = summary
        self.summary = summary.as_json()
        self.units = dict(summary.units)
        self.out = out
        frame = pd.DataFrame(rows, index=pd.Index(times, name="time"), columns=list(columns))
        if decoder is not None:  # Integer, Boolean, Enumeration and String columns of their type
            for name in decoder.types:
                if name in frame:
                    frame[name] = decoder.column(name, frame[name].to_numpy())
        frame.attrs["units"] = self.units
        self.timeseries = frame

    @property
    def status(self) -> Status:
        return self.run_summary.status

    @property
    def event(self):
        return self.run_summary.event

    @property
    def expectations(self) -> list:
        return self.run_summary.expectations

    @property
    def outcome(self):
        """The run classified as a campaign would (class, reason, apogee, perigee, apogee_error,
        dv_total... in SI, their "units"), when the scenario declares montecarlo.outcome; else None."""
        return self.run_summary.outcome

    @property
    def passed(self) -> bool:
        """True if the run completed (or ended at an FMU's terminate request) and every
        expectation it checked passed."""
        return self.status.ended_cleanly and all(e["passed"] for e in self.expectations)

    def __repr__(self):
        n = len(self.timeseries)
        end = f", ended at t = {self.timeseries.index[-1]:g} s" if n else ""
        return (f"<Result {self.status} ({self.run_summary.stop_reason}){end}, {n} rows x "
                f"{self.timeseries.shape[1]} signals, {len(self.expectations)} expectations>")


class Campaign:
    """One Monte Carlo campaign.

    rows: DataFrame indexed by run, one column per row field (status, error, dispersed.*,
    end_time, steps, final.*, min.*, max.*, exit.*); units: {column: unit}; statistics:
    {column: {n, mean, std, min, max, p1..p99}} over the completed runs; summary: the campaign
    summary dict; out: the campaign folder, or None when it was a temporary one.
    """

    def __init__(self, summary, rows: pd.DataFrame, out=None):
        self.summary = summary
        self.units = dict(summary["units"])
        self.statistics = summary["statistics"]
        self.out = out
        frame = rows.set_index("run")
        frame.attrs["units"] = self.units
        self.rows = frame

    def __repr__(self):
        return f"<Campaign {self.summary['runs']} runs, seed {self.summary['seed']}: {self.summary['statuses']}>"
