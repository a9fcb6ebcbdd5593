"""The front door: one typed, frozen options object per command (`commands`), every value checked
in one module (`checks`), built alike by the command line and the Python API and passed whole to
where the work is done."""

from aotv_cosim.options.commands import (
    BenchmarkOptions,
    BuildOptions,
    CampaignOptions,
    CheckOptions,
    CompareOptions,
    CorridorOptions,
    DescribeOptions,
    ExportOptions,
    RunOptions,
    RunsOptions,
    SweepOptions,
    ValidateOptions,
)

__all__ = ["BenchmarkOptions", "BuildOptions", "CampaignOptions", "CheckOptions", "CompareOptions",
           "CorridorOptions", "DescribeOptions", "ExportOptions", "RunOptions", "RunsOptions", "SweepOptions",
           "ValidateOptions"]
