"""aotv-cosim: FMI co-simulation for aeroassisted orbital transfer and entry guidance.

The public Python API (``aotv_cosim.api``): ``run``, ``montecarlo``, ``benchmark``, ``sweep``, ``corridor``,
``describe``, ``build_fmus``, ``validate``, ``export_ssp`` and the ``Result`` they return; see the README's
"From Python".

This top-level module must stay import-free: the FMUs bundle ``aotv_cosim/__init__.py`` together
with the ``physics``, ``guidance`` and ``fmu`` subpackages (see ``aotv_cosim.fmu.build.RUNTIME``),
and must run where only numpy and scipy are installed. So the API is looked up on first use
(PEP 562 module ``__getattr__``), not imported here.
"""

__version__ = "0.1.0"

_API = ("run", "montecarlo", "benchmark", "sweep", "corridor", "describe", "build_fmus", "validate", "export_ssp",
        "Result")
"""The names of the Python API (`aotv_cosim.api`)."""
__all__ = ["Result", "__version__", "benchmark", "build_fmus", "corridor", "describe", "export_ssp", "montecarlo",
           "run", "sweep", "validate"]


def __getattr__(name):
    """The API names, imported on first use."""
    if name in _API:
        from aotv_cosim import api

        return getattr(api, name)
    raise AttributeError(f"module 'aotv_cosim' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
