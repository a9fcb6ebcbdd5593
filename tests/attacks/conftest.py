"""The corpus's crafted FMU archives (tests/data/corpus/fmus), for the cases that name them."""

from tests.model.conftest import crafted_archives  # noqa: F401
