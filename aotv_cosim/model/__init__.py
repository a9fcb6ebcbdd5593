"""What a run is, as read from its files: documents and their JSON schemas (`documents`), the
system from a wiring file or an SSP archive (`system`, `ssp_load`, `ssp_units`, `ssp_names`), the
FMU files and their variables (`fmu_file`, `archives`, `variable_types`), the scenario with its
times, stop conditions, expectations and dispersions (`scenario`, `dispersion_sets`), declared
ranges (`ranges`), step settings (`step_control`), what the FMUs allow (`capabilities`) and the
size of a run (`run_size`).

Loading takes an FMU resolver and never builds: `simulation.loading` gives it the one that
builds this package's FMUs on first use.
"""
