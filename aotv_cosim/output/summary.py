"""What a finished run reports (`RunSummary`), written as its summary.json (`as_json`)."""

from dataclasses import dataclass, field, fields

from aotv_cosim.status import Status

OPTIONAL = ("terminate_request", "step_control", "types", "outcome")
"""Fields written to summary.json only when the run has them (not None)."""


@dataclass
class RunSummary:
    """One run's summary; its fields in summary.json's order, which `as_json` keeps."""

    scenario: str
    """The scenario file."""
    system: str
    """The wiring file (or SSP archive)."""
    description: str
    status: Status
    stop_reason: str
    """Why the run ended, one line ("stop time reached", "h crossed 0 down at t = ... s", ...)."""
    warnings: list
    """What the run did not do that the scenario asked for, and the plausibility warnings."""
    error: str | None
    """The failure's one-line message, or None."""
    error_detail: dict | None
    """The failure's component, variable, time (s), message, and the FMU's log; or None."""
    event: dict | None
    """The located stop-condition crossing: signal, threshold, time (s), every value; or None."""
    terminate_request: dict | None
    """An FMU's request to end the run: component, communication_point (s), last_successful_time (s)."""
    algorithm: str
    """"gauss-seidel" or "jacobi"."""
    start: float
    """Start time, s."""
    stop: float
    """Stop time, s."""
    step: float
    """Communication step, s."""
    end_time: float | None
    """Time of the last recorded row, s (None without rows)."""
    steps: int
    """Communication steps made."""
    step_control: dict | None
    """Error-controlled runs: steps accepted, rejected, smallest and largest step (s), ..."""
    wall_time_s: float
    """Wall-clock time of the run, s."""
    init_time_s: float
    """Wall-clock time of instantiation and initialization, s."""
    us_per_step: float | None
    """Wall-clock time per step after initialization, microseconds."""
    final: dict
    """{column: last value} (a non-finite Real as its text)."""
    min: dict
    """{column: {"value", "time" (s)}} of each column's smallest finite value."""
    max: dict
    """{column: {"value", "time" (s)}} of each column's largest finite value."""
    units: dict
    """{column: unit}."""
    types: dict | None
    """{column: type} of the columns that are not Real; None when all are."""
    expectations: list
    """Each expectation checked: signal, at, expected, measured, error, allowed_error, passed."""
    fmi_calls: str
    """How the master called the FMUs: "direct" (this package's FMUs called in its own
    interpreter) or "c" (every FMU through its FMI C library); per FMU in `fmus`."""
    fmus: dict
    """{component: {"fmu", "file", "guid", "fmi_calls", "wrapper"}}; wrapper: the FMI wrapper in
    the FMU's Linux binary as its build recorded it, "lean" (this package's fmi2_lean.c) or
    "stock" (pythonfmu's), None for an FMU not built by this package."""
    versions: dict
    """{"aotv_cosim", "python"} versions."""
    plots: list = field(default_factory=list)
    """The PNG files drawn into the output folder."""
    outcome: dict | None = None
    """The run classified as a campaign row would be (montecarlo.outcome), or None."""

    def as_json(self) -> dict:
        """summary.json's document: every field in order, the optional ones only when set."""
        doc = {f.name: getattr(self, f.name) for f in fields(self)
               if f.name not in OPTIONAL or getattr(self, f.name) is not None}
        doc["status"] = Status(self.status).value
        return doc
