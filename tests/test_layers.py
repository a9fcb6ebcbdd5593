"""The package's layers import only downward, so there is no import cycle between them.

Every import of every module counts, also those made inside a function (a lazy import is still
a dependency a maintainer must know of). The package root is left out: it holds the version and
exports the API lazily, so the FMUs that bundle it never import the engine."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "aotv_cosim"

LAYERS = ("errors", "paths", "status", "physics", "guidance", "fmu", "laws", "mission", "model", "simulation", "output",
          "ssp", "variables", "studies", "options", "campaigns", "api", "cli_usage", "cli_console", "cli", "__main__")
"""Bottom to top: each unit (a subpackage or a top-level module) may import its own modules and
the units before it. errors and paths: what every layer reports and checks input files with;
status: how a run ended;
physics and guidance: the equations and laws (FMUs bundle them); fmu: the FMU side (adapter
bases, build); mission: what a run achieved (capture class, apogee, correction dv); model:
systems and scenarios read from wiring JSON or SSP; simulation: instances, coupling and the
master's loops; output: run files, summary and plots; ssp: export and third-party hosts; variables
(the describe table), studies: built on runs; options: every command's options, checked in one
place; campaigns: built on runs, given the options whole; api and cli: the two faces."""


def _unit(module: str) -> str:
    return module.split(".")[1]


def imports_by_unit() -> dict:
    """{unit: {unit it imports from}} over every import statement of the package."""
    found = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        if rel.parts == ("aotv_cosim", "__init__"):
            continue
        unit = rel.parts[1]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
            else:
                continue
            for name in names:
                if name.startswith("aotv_cosim.") and _unit(name) in LAYERS and _unit(name) != unit:
                    found.setdefault(unit, set()).add(_unit(name))
    return found


def test_every_unit_has_a_layer():
    units = {p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
             if (p.suffix == ".py" and p.stem != "__init__") or (p / "__init__.py").is_file()}
    assert units <= set(LAYERS), units - set(LAYERS)


def test_imports_go_only_downward():
    upward = {(unit, target) for unit, targets in imports_by_unit().items() for target in targets
              if LAYERS.index(target) > LAYERS.index(unit)}
    assert not upward, sorted(upward)


def test_loading_never_builds():
    """The model layer names no FMU build: it takes a resolver (`simulation.loading` gives the
    building one)."""
    building = {"built_fmu", "ensure_fmu", "build_all", "_pythonfmu_build"}
    named = {(path.name, node.id if isinstance(node, ast.Name) else node.attr)
             for path in (PACKAGE / "model").rglob("*.py") for node in ast.walk(ast.parse(path.read_text()))
             if isinstance(node, (ast.Name, ast.Attribute))
             and (node.id if isinstance(node, ast.Name) else node.attr) in building}
    named |= {(path.name, alias.name) for path in (PACKAGE / "model").rglob("*.py")
              for node in ast.walk(ast.parse(path.read_text())) if isinstance(node, ast.ImportFrom)
              for alias in node.names if alias.name in building}
    assert named == set()
