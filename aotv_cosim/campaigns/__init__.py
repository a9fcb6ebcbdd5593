"""Monte Carlo campaigns: dispersed runs of one scenario on local processes or a Dask cluster.

- `draws`: the dispersed values of run k come from its own seed, SeedSequence(campaign seed,
  spawn_key=(k,)) (numpy's `spawn` children), so they do not depend on workers or backend.
- `worker`: a worker instantiates the scenario's FMUs once and resets them between runs; a run
  becomes one row (dispersed values, final values, extrema, exit values, status, error).
- `backends`, `pool`: local worker processes (default) or Dask distributed; a run whose local
  worker crashes, hangs or outgrows its memory limit is a 'failed' row with the cause and the
  worker is replaced; on Dask a batch whose worker dies is retried run by run.
- `store`: rows appended to rows.csv as they finish; resume skips finished runs; the final
  rows.csv and rows.parquet are sorted by run, identical to an uninterrupted campaign's.
- `statistics`: percentiles (summary.json `statistics`) and the 3-sigma ellipse.
- `units`: the unit of every column (summary.json `units`, rows.parquet field metadata).
- `report`, `figures`: the runs classified (`aotv_cosim.mission`), the 3-sigma table and outcome
  counts (console, summary.json, report.md) and the labelled plots.
- `benchmark`, `benchmark_report`: every law of a scenario set through the same draws, scorecard.
"""

from aotv_cosim.campaigns.campaign import run_campaign

__all__ = ["run_campaign"]

