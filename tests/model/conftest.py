"""Fixtures of the bad-input tests: the corpus's crafted FMU archives and an exported SSP."""

import importlib.util

import pytest

from tests.model.archives import CORPUS, export_nominal


@pytest.fixture(scope="session")
def crafted_archives():
    """Write the corpus's crafted FMU archives (deterministic bytes) into tests/data/corpus/fmus."""
    spec = importlib.util.spec_from_file_location("make_archives", CORPUS / "make_archives.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main()


@pytest.fixture(scope="module")
def nominal_ssp(tmp_path_factory):
    """The nominal scenario exported as an .ssp archive, once per module."""
    return export_nominal(tmp_path_factory)
