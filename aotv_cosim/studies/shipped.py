"""Files shipped with the package: the regression scenarios and their wiring files.

A wheel carries the repository's `scenarios/` as `aotv_cosim/scenarios` (pyproject.toml
force-include), so the figure commands find the runs they draw from any folder after
`pip install .`; a source checkout uses its own `scenarios/` beside the package.
"""

from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parents[1]


def scenarios_dir() -> Path:
    """The shipped scenarios folder: inside the installed package, else the checkout's.

    When neither exists the package's path is returned, and the loader reports the file
    missing there."""
    for candidate in (PACKAGE_DIR / "scenarios", PACKAGE_DIR.parent / "scenarios"):
        if candidate.is_dir():
            return candidate
    return PACKAGE_DIR / "scenarios"


def scenario(name: str) -> Path:
    """The path of the shipped scenario file `name` (e.g. 'aotv_compare.json')."""
    return scenarios_dir() / name
