"""``python -m aotv_cosim``: the same command line as ``aotv-cosim``."""

from aotv_cosim.cli import main

main(prog_name="aotv-cosim")
