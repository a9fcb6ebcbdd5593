"""Seed 002: SX-2 model numbers, the reference table, and the tracking law's implementation.

Check values are the extraction's (Sec. 3.5, 6.2); the ideal-plant test is its strongest
implementation test: with drag at alpha_ref the errors follow the designed linear ODE (50).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from aotv_cosim.guidance import entry_tracking as law
from aotv_cosim.studies import entry_tracking_study as study
from aotv_cosim.guidance.entry_tracking_reference import Reference, read_table
from aotv_cosim.physics import entry, entry_reference, sx2

FT2 = entry_reference.FT2


@pytest.fixture(scope="module")
def reference():
    return Reference()


def test_polar_max_lift_to_drag():
    """T9: the fit's L/D max is 1.4909 at 14.068 deg (not the quoted SX-2 1.6, A5)."""
    ld, alpha = sx2.max_lift_to_drag()
    assert ld == pytest.approx(1.4909, abs=5e-5)
    assert math.degrees(alpha) == pytest.approx(14.068, abs=5e-4)


def test_entry_check_values():
    """Extraction 3.5: E0 = 1.508685e8 ft^2/s^2, rho(h0) = 4.68706e-7 slug/ft^3, US76 a(h0)."""
    assert pytest.approx(1.508685e8, rel=1e-6) == entry_reference.E_ENTRY / FT2
    assert entry.density(entry_reference.R_ENTRY) / sx2.SLUG_PER_FT3 == pytest.approx(4.68706e-7, rel=1e-5)
    assert entry.speed_of_sound(sx2.H0) / sx2.FT == pytest.approx(1028.2, abs=0.05)
    assert entry.speed_of_sound(84000 * sx2.FT) / sx2.FT == pytest.approx(980.3, abs=0.05)


def test_reference_design_targets():
    """T5, T8: bank reversal centred at V_ref = 10,000 ft/s; end near 84,000 ft at Mach 2.7."""
    table = read_table()
    assert table["mach"][-1] == pytest.approx(2.7, abs=1e-6)
    assert table["h"][-1] / sx2.FT == pytest.approx(84000.0, abs=500.0)
    centre = 0.5 * (entry_reference.SIGMA_BREAKS[0][0] + entry_reference.SIGMA_BREAKS[1][0])
    v_rev = np.interp(centre, table["energy"][::-1], table["v"][::-1])
    assert v_rev / sx2.FT == pytest.approx(10000.0, abs=50.0)
    assert table["energy"][0] > entry_reference.E_ENTRY + 100.0 * sx2.FT * sx2.V0  # covers +100 ft/s


TABLE_ERROR = {"energy": 4.1e-5, "r": 3.6e-5, "theta": 1.24e-10, "phi": 3.1e-11, "gamma": 4.9e-10,
               "chi": 6.0e-10, "alpha": 0.0, "sigma": 0.0, "h": 3.6e-5, "v": 1.23e-7, "mach": 1.94e-9,
               "drag": 2.9e-8}
"""Largest |table - the same table integrated at rtol 1e-12| per column (SI: m^2/s^2, m, rad, m/s,
1, m/s^2), measured with numpy 2.4.6 / scipy 1.17.1: the checked-in table's own integration error
(RK45 at rtol 1e-11; `energy` differs in its last row, the Mach 2.7 event). Floating-point
differences between machines (another libm or BLAS) change the adaptive steps and so move the
result by up to this much (the issue measured 2.4e-5 m in altitude, 3.4e-9 relative in drag,
which follows the density exponentially): agreement closer than this is not a property of the
table. `test_table_error_estimate` re-measures it."""


def _table_tolerance(column):
    """Accepted |difference| for a regenerated table: 4x its integration error (alpha and sigma,
    which are the control schedules of the energy grid, to 1e-12 rad)."""
    return max(4.0 * TABLE_ERROR[column], 1e-12)


def test_table_is_reproduced_by_the_command(tmp_path):
    """The checked-in table is what `python -m aotv_cosim.studies.entry_reference` writes today, to within
    the table's integration error (`TABLE_ERROR`), not to the last bit of one machine's run."""
    from aotv_cosim.studies.entry_reference import generate

    generate(tmp_path / "t.csv")
    new, old = read_table(tmp_path / "t.csv"), read_table()
    assert list(new) == list(old) and len(new["energy"]) == len(old["energy"])
    for column in old:
        np.testing.assert_allclose(new[column], old[column], rtol=0, atol=_table_tolerance(column),
                                   err_msg=column)


@pytest.mark.slow
def test_table_error_estimate(tmp_path):
    """`TABLE_ERROR` holds: the checked-in table against the same integration at rtol 1e-12 differs
    by at most 1.5x the stated figure per column (the estimate is not understated)."""
    from aotv_cosim.studies.entry_reference import SPACING
    from aotv_cosim.guidance.entry_tracking_reference import write_table

    energies, states, _ = entry_reference.integrate(SPACING, rtol=1e-12)
    write_table(tmp_path / "fine.csv", energies, states, entry_reference.alpha_ref(energies),
                entry_reference.sigma_ref(energies), sx2.R_EARTH)
    fine, old = read_table(tmp_path / "fine.csv"), read_table()
    for column in old:
        assert np.abs(fine[column] - old[column]).max() <= 1.5 * TABLE_ERROR[column] + 1e-15, column


@pytest.mark.parametrize("e_ft2", [1.2e8, 3e7, 9e6])
def test_law_derivatives_match_finite_differences(reference, e_ft2):
    """phi11, phi12, y1''' and y2'' equal d/dE of theta, phi11, phi12, phi21 along the reference
    where alpha_ref and sigma_ref are constant (the law's frozen-control premise holds)."""
    e, h = e_ft2 * FT2, 50.0
    alpha, sigma = reference.controls(e)

    def coords(en):
        return law.coordinates([reference.state(en)], en, alpha, sigma)[0]

    def fd(f):
        return (f(e + h) - f(e - h)) / (2 * h)

    c = coords(e)
    u = law.reference_lift(reference.state(e), e, alpha, sigma)
    assert c.y1p == pytest.approx(fd(lambda en: reference.state(en)[1]), rel=1e-6)
    assert c.y2p == pytest.approx(fd(lambda en: reference.state(en)[2]), rel=1e-6)
    assert c.y1pp == pytest.approx(fd(lambda en: coords(en).y1p), rel=1e-4)
    assert c.a[0] + c.b[0] @ u == pytest.approx(fd(lambda en: coords(en).y1pp), rel=1e-5)
    assert c.a[1] + c.b[1] @ u == pytest.approx(fd(lambda en: coords(en).y2p), rel=1e-6)


def test_gains_place_right_half_plane_poles():
    """Energy decreases, so the error poles in s = d/dE lie in Re(s) > 0 at the designed places."""
    omega, zeta = 33.6, 0.7
    down, cross = law.error_poles(law.gains(omega, zeta, omega, zeta))
    w = omega / law.E_SCALE
    assert np.all(down.real > 0) and np.all(cross.real > 0)
    np.testing.assert_allclose(sorted(down.real), [zeta * w] * 4, rtol=1e-4)
    assert sorted(cross.real)[-1] == pytest.approx(w, rel=1e-9)


def test_constrained_inversion_inside_and_on_the_bands():
    """(54) with eta = 0.5: the unconstrained answer when feasible, else the nearest feasible point."""
    lift, sigma, constrained = law.constrained_lift(3.0, 4.0, 1.0, 10.0, -1.0, 1.0, 0.5)
    assert (lift, sigma, constrained) == (pytest.approx(5.0), pytest.approx(math.atan2(4, 3)), False)
    lift, sigma, constrained = law.constrained_lift(30.0, 40.0, 1.0, 10.0, -1.0, 1.0, 0.5)
    assert constrained and lift == pytest.approx(10.0) and sigma == pytest.approx(math.atan2(4, 3), abs=1e-6)
    lift, sigma, constrained = law.constrained_lift(0.0, 5.0, 1.0, 10.0, -0.5, 0.5, 0.5)
    assert constrained and sigma == pytest.approx(0.5, abs=1e-6)
    assert lift == pytest.approx(5.0 * math.cos(math.pi / 2 - 0.5), rel=1e-6)


def test_ideal_plant_errors_follow_the_designed_linear_ode(reference):
    """Extraction 6.2: drag at alpha_ref, dtheta = 0.01 deg: e1 follows e1''' + k11 e1'' + k12 e1'
    + k13 e1 + k14 int e1 = 0 (eq. 50) and the crossrange stays zero (decoupling).

    Measured: largest |e1 - e1_linear| = 5.6 % of e1(E0) (the neglected u_ref' terms of eq. 44,
    A18), crossrange below 1e-5 n mi; bounds 10 % and 1e-4 n mi."""
    design = study.Design()
    run = study.simulate((0, 0.01 * study.DEG, 0, 0, 0, 0), "ideal", design, reference, step=1e5 * FT2)
    k11, k12, k13, k14 = design.gains().k1

    def rhs(e, z):
        return [z[1], z[2], z[3], -(k14 * z[0] + k13 * z[1] + k12 * z[2] + k11 * z[3])]

    e1_0 = 0.01 * study.DEG
    linear = solve_ivp(rhs, (run.energy[0], run.energy[-1]), [0, e1_0, 0, 0], rtol=1e-10, atol=1e-20,
                       dense_output=True).sol(run.energy)[1]
    assert np.abs(run.errors[:, 0] - linear).max() < 0.10 * e1_0
    assert np.abs(run.errors[:, 1]).max() * sx2.R_EARTH / sx2.NMI < 1e-4


def test_drag_aware_inversion_equals_the_paper_at_the_reference_drag(reference):
    """At D = D~ the exact lift vector D p - n is the paper's b^-1 (w - a) (eq. 52), and on the
    reference (w = w_ref) the exact inversion returns u_ref: alpha_ref, sigma_ref."""
    e = 3e7 * FT2
    x_ref, (alpha, sigma) = reference.state(e), reference.controls(e)
    x = x_ref + np.array([300.0, 1e-4, -2e-4, 1e-3, 2e-3])
    c, ref = law.coordinates((x, x_ref), e, alpha, sigma)
    g = law.gains(26.9, 0.7, 26.9, 0.7)
    w = law.pseudo_controls(c, ref, law.reference_lift(x_ref, e, alpha, sigma), (0.0, 0.0), g)
    d_tilde = law.drag_tilde(x[0], e, alpha)
    p, n = law.drag_aware_lift(c, w, d_tilde)
    np.testing.assert_allclose(d_tilde * p - n, law.required_lift(c, w), rtol=1e-10)
    bands = study.Design().bands
    cmd = law.command(x_ref, e, x_ref, alpha, sigma, (0.0, 0.0), g, bands, 0.5, "drag_aware")
    assert (cmd.alpha, cmd.sigma, cmd.constrained) == (pytest.approx(alpha, abs=1e-9),
                                                       pytest.approx(sigma, abs=1e-9), False)


def test_drag_aware_controls_solve_lift_and_drag_together():
    """A lift vector built from (alpha0, sigma0) with the drag at alpha0 is recovered exactly; the
    same demand read with D = D~ (the paper) would give a different alpha."""
    q_s_m, alpha0, sigma0 = 20.0, math.radians(17.0), math.radians(25.0)
    lift, drag = q_s_m * sx2.lift_coefficient(alpha0), q_s_m * sx2.drag_coefficient(alpha0)
    n = np.array([1.5, -0.4])
    p = (lift * np.array([math.cos(sigma0), math.sin(sigma0)]) + n) / drag
    band = (math.radians(12.0), math.radians(22.0))
    alpha, sigma, constrained = law.drag_aware_controls(p, n, q_s_m, band, (-1.4, 1.4), 0.5, alpha0)
    assert not constrained
    assert (alpha, sigma) == (pytest.approx(alpha0, abs=1e-10), pytest.approx(sigma0, abs=1e-10))
    alpha, sigma, constrained = law.drag_aware_controls(p, n, q_s_m, band, (0.5, 1.4), 0.5, alpha0)
    assert constrained and sigma == pytest.approx(0.5, abs=1e-6)
