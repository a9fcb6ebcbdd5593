"""The contract of one FMU instance in a run (`FmuInstance`), whatever calls it.

Three implementations satisfy it: an FMI 2.0 FMU through its C library (`fmi2_instance`), an FMI
3.0 co-simulation FMU through its C library (`fmi3_instance`), and a pythonfmu slave of this
package called in this interpreter (`direct_instance`). The master and the coupling use only what
is declared here, so they step any mix of them without asking which kind an instance is.

Lifecycle (FMI's order): the constructor instantiates the FMU for a run from `start_time` to
`stop_time` (s; `tolerance` is given to the FMU when not None), `set_values` sets parameters and
inputs by name, `enter_initialization`/`exit_initialization` frame the initialization,
`step`/`stepper` advance it, `save_state`/`restore_state`/`free_state` keep and bring back its
state, `reset` makes it as just instantiated for another run, `close` terminates and frees it.

Values between the FMUs travel through the master's buffer, a ctypes array of float64 (Real and
Float values as they are, integers and Booleans as numbers, a String or Binary as the number of
its text in the run's `variable_types.Strings`). For the stepping loop an instance gives bound
callables, built once per run over that buffer: `getter` and `setter` (one FMI get or set of a
`Slots` set of variables of one FMI type) and `stepper` (set the fresh inputs, step, read the
outputs: one component's part of a sweep). They raise what the FMU's answer means
(`SimulationError`, `TerminateRequest`), so the loop has no status to look at.
"""

import collections
import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

from aotv_cosim.errors import SimulationError, TerminateRequest

STATUS = {0: "ok", 1: "warning", 2: "discard", 3: "error", 4: "fatal", 5: "pending"}
"""FMI status codes (the same in FMI 2.0 and 3.0, 5 only in 2.0) -> the words of messages."""

MESSAGES_KEPT = 50
"""Log messages of an FMU kept for a failure's report (the last ones)."""

Bound = Callable[[float], None]
"""f(t): a prepared get or set, t the time (s) named by a failure."""

Stepper = Callable[[float, float, float], None]
"""f(t, h, t_new): one component's part of a sweep from t over h (s), t_new for a failure."""


@dataclass(frozen=True)
class Slots:
    """Variables of one FMU exchanged with the master's buffer in one FMI call: their value
    references and the buffer position of each value, sorted by position (when the positions
    are consecutive an implementation may pass a view of the buffer itself)."""

    vrs: tuple
    positions: tuple

    @classmethod
    def of(cls, vrs, positions) -> "Slots":
        """The slots of value references `vrs` whose values are at `positions`, sorted by position
        (variables at one position keep the order they are given in)."""
        ranked = sorted(zip(positions, vrs), key=lambda pair: pair[0])  # stable: ties keep their order
        return cls(tuple(v for _, v in ranked), tuple(p for p, _ in ranked))

    @property
    def n(self) -> int:
        return len(self.vrs)

    @property
    def consecutive(self) -> bool:
        """True when the positions are first, first + 1, ... (none counts as consecutive)."""
        return not self.vrs or self.positions == tuple(range(self.positions[0], self.positions[0] + self.n))


NO_SLOTS = Slots((), ())


@dataclass(frozen=True)
class StepResult:
    """What one `FmuInstance.step` came to.

    outcome: "ok" (the step reached t + h; warnings included), "terminate" (the FMU asks to end
    the simulation), "discard" (the step was refused without a terminate request) or "error"
    (error, fatal or pending: the instance can no longer be used); time: the step's start (s);
    status: the FMI status the step function returned (0 ok ... 4 fatal, 5 pending; None when it
    answered ok against the protocol, e.g. an early return the master did not allow);
    last_successful_time: with "terminate", the time the FMU reached (s; None if it does not
    say); message: the FMU's last log message (one line)."""

    outcome: str
    time: float
    status: int | None = 0
    last_successful_time: float | None = None
    message: str = ""

    @property
    def ok(self) -> bool:
        return self.outcome == "ok"


class FmuInstance(ABC):
    """One FMU instantiated for a run (module docstring): the lifecycle, typed values by name,
    and the bound calls of the stepping loop.

    Attributes every implementation keeps: name (the component), info (its `FmuInfo`), time (s,
    of the last call, for messages), broken (True once the FMU answered error or fatal: its
    state cannot be used and it is not freed), messages (its last `MESSAGES_KEPT` log messages,
    (status word, text)); `calls` says how it is called ("c" or "direct", recorded per FMU in
    summary.json)."""

    calls = "c"

    @property
    def step_call(self) -> str:
        """The name of the FMI function that steps the FMU, for messages."""
        return "fmi2DoStep"

    def __init__(self, name: str, info, start_time: float):
        self.name = name
        self.info = info
        self.time = start_time
        self.broken = False
        self.messages: collections.deque[tuple[str, str]] = collections.deque(maxlen=MESSAGES_KEPT)

    # ---- reporting (shared) -----------------------------------------------------------------
    def last_message(self) -> str:
        """The FMU's last error-level log message (else its last message), one line."""
        errors = (text for status, text in reversed(self.messages) if status in ("error", "fatal"))
        text = next(errors, self.messages[-1][1] if self.messages else "")
        lines = [line.strip() for line in text.splitlines() if line.strip()]
        return lines[-1] if lines else "no message from the FMU"

    def failure(self, call: str, time: float, status=None, variable=None) -> SimulationError:
        """A SimulationError naming this component, the call, the time and the FMU's message;
        the instance counts as broken unless the status was warning or discard."""
        what = f"{call} returned {STATUS.get(status, status)}" if status is not None else call
        where = f"{self.name}.{variable}" if variable else self.name
        self.broken = status is None or status > 2
        return SimulationError(f"{what} at t = {time:.6g} s: {self.last_message()}",
                               file=self.info.path.name, entry=where,
                               fix="the results up to this time are saved; the FMU's log is in summary.json "
                                   "(error_detail.fmu_log)",
                               component=self.name, variable=variable, time=time)

    def terminate_request(self, time: float, last_successful_time) -> TerminateRequest:
        """The TerminateRequest of a step from `time` (s) after which this FMU asks to end the
        simulation, having reached `last_successful_time` (s; None or NaN: it does not say)."""
        known = last_successful_time is not None and math.isfinite(last_successful_time)
        return TerminateRequest(self.name, time, last_successful_time if known else None)

    # ---- lifecycle ----------------------------------------------------------------------------
    @abstractmethod
    def reset(self, start_time: float, stop_time: float, tolerance: float | None = None) -> None:
        """Back to the state just after instantiation, for a run from start_time to stop_time (s)."""

    @abstractmethod
    def set_values(self, values: dict) -> None:
        """Set parameters, start values or inputs by name, each a Python value of its variable's
        type (a number, an Enumeration's integer, a bool, a String's text, a Binary's hex text)."""

    @abstractmethod
    def get_value(self, name: str):
        """The current value of variable `name` as `set_values` takes it."""

    @abstractmethod
    def enter_initialization(self) -> None:
        """Enter initialization mode (FMI 3.0: with the run's start and stop times)."""

    @abstractmethod
    def exit_initialization(self) -> None:
        """Leave initialization mode: the instance is ready to step."""

    @abstractmethod
    def step(self, t: float, h: float) -> StepResult:
        """One step from t over h (s), its outcome typed (never raises for what the FMU answers)."""

    @abstractmethod
    def save_state(self):
        """A handle on the FMU's current state (valid until `free_state`)."""

    @abstractmethod
    def restore_state(self, handle, time: float) -> None:
        """Back to the state of `handle` (it stays valid); time (s) for a failure's message."""

    @abstractmethod
    def free_state(self, handle) -> None:
        """Release a `save_state` handle."""

    @abstractmethod
    def close(self) -> None:
        """Terminate and free the instance, a failure to do so ignored (the run is over); an
        instance that is broken is left as it is."""

    # ---- bound calls of the stepping loop ------------------------------------------------------
    @abstractmethod
    def getter(self, call_type: str, slots: Slots, buffer, strings) -> Bound:
        """f(t) reading the variables of `slots` (all of FMI call type `call_type`,
        `FmuInfo.call_type`) into their positions of `buffer`; SimulationError if the FMU refuses."""

    @abstractmethod
    def setter(self, call_type: str, slots: Slots, buffer, strings) -> Bound:
        """f(t) setting the variables of `slots` to the values at their positions of `buffer`."""

    @abstractmethod
    def stepper(self, fresh: Slots, outputs: Slots, buffer, rollback: bool) -> Stepper:
        """f(t, h, t_new): set the Float64 (Real) inputs `fresh` from the buffer, step from t over h,
        read the Float64 outputs `outputs` (consecutive positions) into the buffer. A refused step raises what it means
        (`StepResult` as an exception: TerminateRequest or SimulationError). rollback: the master
        may restore a state saved before the current time (FMI's noSetFMUStatePriorToCurrentPoint
        false)."""

    def refusal(self, result: StepResult) -> Exception:
        """The exception the stepping loop raises for a step that did not end "ok"."""
        if result.outcome == "terminate":
            return self.terminate_request(result.time, result.last_successful_time)
        return self.failure(self.step_call, result.time, result.status)
