"""The project's error types. The CLI turns each into one line and an exit status."""


class AotvError(Exception):
    """Base of every error the CLI reports without a traceback.

    Rendered as ``FILE: ENTRY: CAUSE; FIX``; `exit_status` is the CLI's exit code.
    """

    exit_status = 1

    def __init__(self, cause, *, file=None, entry=None, fix=None):
        super().__init__(cause)
        self.cause = cause
        self.file = file
        self.entry = entry
        self.fix = fix

    def __str__(self):
        """One line: a multi-line cause (an FMU's traceback, a validator's report) is joined."""
        parts = [str(p) for p in (self.file, self.entry) if p]
        text = ": ".join([*parts, " ".join(str(self.cause).split())])
        return f"{text}; {self.fix}" if self.fix else text


class InputError(AotvError):
    """A scenario, wiring or FMU file that cannot be used as given (exit status 2)."""

    exit_status = 2


class BuildError(AotvError):
    """An FMU could not be built from fmus_src or does not validate."""


class SimulationError(AotvError):
    """A run failed midway: an FMU raised, returned an error status or produced NaN/inf.

    `component` and `variable` name where it failed (None when no component is to blame, e.g. a
    result file that could not be written) and `time` is the communication point, s."""

    def __init__(self, cause, *, file=None, entry=None, fix=None, component: str | None = None,
                 variable: str | None = None, time: float | None = None):
        super().__init__(cause, file=file, entry=entry, fix=fix)
        self.component = component
        self.variable = variable
        self.time = time


class ValidationFailed(InputError):
    """Several problems found in one file; `problems` holds one InputError per problem."""

    def __init__(self, problems):
        super().__init__(f"{len(problems)} problem(s)")
        self.problems = list(problems)

    def __str__(self):
        return "\n".join(str(p) for p in self.problems)


def raise_if_any(problems):
    """Raise the single problem, or ValidationFailed for several; do nothing if none. A problem
    found again with the same message (one cause met by every component, e.g. a bad environment
    variable of the FMU build) is reported once."""
    unique: dict[str, Exception] = {}
    for p in problems:
        unique.setdefault(str(p), p)
    problems = list(unique.values())
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise ValidationFailed(problems)


class TerminateRequest(Exception):
    """An FMU asked to end the simulation: fmi2DoStep returned fmi2Discard and
    fmi2GetBooleanStatus(fmi2Terminated) is true. Not a failure: the run ends cleanly at the last
    communication point every component reached (`time`, s); `last_successful_time` (s) is the
    FMU's fmi2LastSuccessfulTime, None when it does not give one."""

    def __init__(self, component: str, time: float, last_successful_time):
        super().__init__(f"{component} asked to terminate")
        self.component, self.time, self.last_successful_time = component, time, last_successful_time
