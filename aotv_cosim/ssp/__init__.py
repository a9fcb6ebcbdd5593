"""SSP 1.0 (System Structure and Parameterization) export and import of aotv-cosim systems.

`export.export_ssp` writes a scenario's system as an .ssp archive (the FMUs under resources/,
SystemStructure.ssd, one .ssv parameter set per component, the default experiment) that OSP
libcosim and FMPy's SSP simulator run; `load.read_ssp` turns an .ssp back into the wiring
document that `system.load_system` validates, so a system built in another SSP tool runs in
this master with every check of a wiring file.
"""
