"""How a run or a campaign ended (`Status`): the text summary.json, rows.csv and the console show."""

from enum import StrEnum


class Status(StrEnum):
    """A run's status; a str, so a member is written (JSON, CSV, Parquet), shown and compared as its
    text."""

    COMPLETED = "completed"
    """The stop time or a stop condition was reached (a campaign: every run was made)."""
    TERMINATED = "terminated"
    """An FMU asked to end the run (fmi2Terminated); not a failure."""
    FAILED = "failed"
    """An FMU failed, an output was not finite, a result file could not be written, a step passed
    its time limit, or a campaign's worker was lost."""
    INTERRUPTED = "interrupted"
    """SIGINT or SIGTERM ended the run (or the campaign) early; what was done is kept."""
    IMPACT = "impact"
    """The vehicle reached the ground (an altitude below its declared minimum 0)."""
    OUT_OF_RANGE = "out_of_range"
    """An output left the range its FMU declares."""
    ERROR = "error"
    """A campaign run that raised before or outside the master (e.g. a draw the FMU rejects)."""

    @property
    def ended_cleanly(self) -> bool:
        """True for the statuses that are no failure: completed and terminated."""
        return self in (Status.COMPLETED, Status.TERMINATED)
