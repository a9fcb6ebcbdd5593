"""Equations of the seeds, in SI units, as plain functions of floats.

Used by the FMU adapters in ``fmus_src``, by the guidance solvers and by the monolithic reference
simulation, so every user integrates exactly the same equations. Only the standard library, numpy
and scipy may be imported here (the modules are bundled into the FMUs).
"""
