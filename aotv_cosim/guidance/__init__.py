"""Guidance and control laws and their solvers (bundled into the FMUs; numpy/scipy only)."""
