"""What a run leaves: the runner that records a run into an output folder or into memory
(`runner`), the time series (`run_files` for timeseries.csv, `series` for memory and Parquet),
summary.json as a typed `RunSummary` (`summary`), plots (`plots`), plausibility warnings
(`plausibility`), output folders claimed for one run (`outdir`) and the objects the Python API
returns (`result_types`).
"""
