"""Seed-001 figures (aotv_cosim.studies.plane_change_plots, after Calise & Melamed Figs. 3.4-3.19)."""

import math

import numpy as np

from aotv_cosim.studies import plane_change_plots as pcp
from aotv_cosim.guidance import mae


def test_open_loop_curves_compose_as_eq_3_99():
    """Composite = outer + inner - common part (3.99) on each side of the lowest point, for
    gamma and P_gamma; the curves are the ones drawn in Figs. 3.4 and 3.6."""
    k = mae.solve(pcp.ENTRY, pcp.TARGETS).constants
    psi = np.array([math.radians(5.0), math.radians(17.0)])
    _, curves = pcp.open_loop_curves(k, psi)
    inner, outer, comp = curves["p_gamma"]
    common = np.array([k.left.p_gamma0, k.right.p_gamma0])
    np.testing.assert_allclose(comp, inner + outer - common, atol=1e-12)
    inner, outer, comp = curves["gamma"]
    common = np.degrees([k.left.gamma0, k.right.gamma0])
    np.testing.assert_allclose(comp, inner + outer - common, atol=1e-10)


def test_open_loop_figures_are_written(tmp_path, drawn):
    """Figs. 3.4-3.10: one panel against the heading; inner, outer and composite curves for the
    four states and costates, the composite alone for lift, bank and altitude."""
    files = pcp.open_loop_figures(tmp_path)
    assert len(files) == 7
    assert all((tmp_path / f).stat().st_size > 0 for f in files)
    ylabels = ["gamma [deg]", "V [m/s]", "P_gamma [-]", "P_u [-]", "lambda [-]", "mu [deg]", "z [km]"]
    for number, (name, ylabel) in enumerate(zip(files, ylabels), start=4):
        panel, = drawn[(tmp_path / name).resolve()].panels
        assert panel.title.startswith(f"Fig. 3.{number}: ") and panel.title.endswith(", zeroth-order open loop")
        assert (panel.xlabel, panel.ylabel) == ("heading psi [deg]", ylabel)
        assert panel.lines == (("inner", "outer", "composite") if number <= 7 else ("composite",))
