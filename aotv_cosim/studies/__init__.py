"""Seed studies: the seed documents' figures and reports, generators of reference tables and
scenarios, the seed-000 law comparison, the monolithic SciPy reference the co-simulation is
checked against, and the entry corridor (which the corridor command flies on its workers). They
drive the engine; nothing in the engine or the FMUs imports them.
"""
