"""aotv-cosim: FMI co-simulation for aeroassisted orbital transfer and entry guidance.

This top-level module must stay import-free: the FMUs bundle ``aotv_cosim/__init__.py`` together
with the ``physics``, ``guidance`` and ``fmu`` subpackages (see ``aotv_cosim.fmu.build.RUNTIME``),
and must run where only numpy and scipy are installed.
"""

__version__ = "0.1.0"
