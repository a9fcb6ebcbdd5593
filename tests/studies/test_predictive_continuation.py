"""The predictive laws on the aerocapture entry: the guarded solve and its continuation from the
mission's nominal (`guidance.predictive.solve_from_known`).

The entries are the AFE-class set's (scenarios/benchmark_aerocapture/systems/afe_predictive.json):
122 km, 10308.38 m/s, -0.07773 rad nominal, dispersed by +-0.15 deg and +-20 m/s; K_ball and the
exit target are that system's. The nominal's (a, b, tf') is the one the system gives."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance import predictive
from aotv_cosim.physics.planar import AotvConstants
from tests.helpers import SCENARIOS

NOMINAL_ENTRY = (122000.0, 10308.38, -0.07773)
EXIT = (122000.0, 7885.3, 0.02404)
K_AFE = 0.009711
NOMINAL = predictive.KnownSolution(NOMINAL_ENTRY, K_AFE, (0.29166908, -7.408214e-05, 432.73708))
STEEP = (122000.0, 10308.38, -0.07773 - math.radians(0.15))


def _exit_error(entry, sol, k_ball):
    """Exit (h m, v m/s, gamma rad) error of the law flown by `fly_time_linear` (an integration
    independent of the solver's sensitivities)."""
    _t, h, v, gamma = predictive.fly_time_linear(entry, sol.a, sol.b, sol.tf, k_ball)
    return np.array([h[-1] - EXIT[0], v[-1] - EXIT[1], gamma[-1] - EXIT[2]])


def test_the_nominal_given_to_the_set_solves_the_nominal_entry():
    sol = predictive.solve_predictive(NOMINAL_ENTRY, EXIT, K_AFE, NOMINAL.guess)
    assert sol.converged and sol.iterations <= 2


def test_a_direct_start_from_the_nominal_fails_on_the_steepest_entry_and_returns():
    """Its first flight falls vertically (h 18 km, v 119 m/s); the next Newton step asks for
    tf' = -1.7e8 s, which the guard refuses instead of integrating it backwards for minutes."""
    sol = predictive.solve_predictive(STEEP, EXIT, K_AFE, NOMINAL.guess)
    assert not sol.converged
    assert sol.iterations == 1


@pytest.mark.parametrize("dgamma_deg, dv", [(-0.15, -20.0), (-0.15, 20.0), (0.15, -20.0), (0.15, 20.0),
                                            (-0.1, 0.0), (0.05, 10.0)])
def test_continuation_from_the_nominal_meets_the_exit_over_the_dispersed_entries(dgamma_deg, dv):
    entry = (122000.0, 10308.38 + dv, -0.07773 + math.radians(dgamma_deg))
    sol = predictive.solve_from_known(entry, EXIT, K_AFE, NOMINAL)
    assert sol.converged and sol.tf > 0.0
    assert np.all(np.abs(sol.residual) < predictive.TERMINAL_TOL)
    # the solver's TERMINAL_TOL (1 cm, 1e-5 m/s, 1e-8 rad) against an independent DOP853 flight at
    # the same rtol: agreement to 1 m, 1 mm/s and 1e-6 rad
    assert np.all(np.abs(_exit_error(entry, sol, K_AFE)) < [1.0, 1e-3, 1e-6])


def test_continuation_moves_k_too():
    """The adaptive law continues from the nominal's K to the one it estimates at entry: US76 at
    122 km gives 3.67e-3 1/m for the AFE class, 0.38 of the K fitted between 60 and 80 km."""
    k_est = 0.0036737
    sol = predictive.solve_from_known(STEEP, EXIT, k_est, NOMINAL)
    assert sol.converged
    assert np.all(np.abs(_exit_error(STEEP, sol, k_est)) < [1.0, 1e-3, 1e-6])


def test_a_guess_with_no_time_in_the_atmosphere_is_not_flown():
    sol = predictive.solve_predictive(NOMINAL_ENTRY, EXIT, K_AFE, (0.3, 0.0, -10.0))
    assert not sol.converged and sol.iterations == 0 and np.all(np.isinf(sol.residual))


@pytest.mark.parametrize("guess", [(1e3, 0.0, 300.0), (-1e3, 0.0, 300.0), (0.001, 0.002, 0.001), (0.77, -2.5e-3, 1e6)])
def test_an_absurd_known_solution_ends_the_solve_unconverged_at_once(guess):
    """A lift of 1000 m/s^2 loops above the atmosphere (`_loop`), -1000 m/s^2 dives
    (`_EnergyFloor`); a 1 ms or a 1e6 s pass is no start either: the solve says so within a few
    integrations instead of flying them for minutes (the FMU then stops the run with an error)."""
    sol = predictive.solve_from_known(NOMINAL_ENTRY, EXIT, K_AFE, predictive.KnownSolution(NOMINAL_ENTRY, K_AFE, guess))
    assert not sol.converged and sol.iterations <= 20


def test_a_flight_that_can_no_longer_reach_the_exit_speed_stops_at_the_energy_floor():
    """A hard dive (u = -5 m/s^2) falls below the energy of the exit point at half its speed."""
    c = AotvConstants.si(K_AFE)
    x0 = np.array([c.r_earth + NOMINAL_ENTRY[0], NOMINAL_ENTRY[1], NOMINAL_ENTRY[2]])
    floor = predictive._EnergyFloor(EXIT, c)
    assert predictive._terminal_with_sensitivities(x0, -5.0, 0.0, 2000.0, c, (floor,)) is None
    assert predictive._terminal_with_sensitivities(x0, *NOMINAL.guess, c, (floor,)) is not None


def test_the_seed_laws_start_from_the_table_8_1_fits_by_default():
    """start_from_nominal = 0, the FMUs' default, keeps the seed-000 solve (no known solution)."""
    slave = SimpleNamespace(start_from_nominal=0, tf_nom=300.0)
    assert guidance_slave.known_solution(slave, K_AFE) is None
    slave = SimpleNamespace(start_from_nominal=1, h0_nom=1.0, v0_nom=2.0, gamma0_nom=3.0, a_nom=4.0, b_nom=5.0,
                            tf_nom=6.0)
    assert guidance_slave.known_solution(slave, K_AFE) == predictive.KnownSolution((1.0, 2.0, 3.0), K_AFE,
                                                                                  (4.0, 5.0, 6.0))
    slave.K_nom = 7.0
    assert guidance_slave.known_solution(slave, K_AFE).k_ball == 7.0


@pytest.mark.integration
def test_the_predictive_law_flies_the_steepest_aerocapture_entry(tmp_path):
    """The FMU stops a run whose solve did not converge (accept_unconverged 0): this one, the
    steepest entry of the set, completes and is classified."""
    from aotv_cosim import api

    result = api.run(SCENARIOS / "benchmark_aerocapture" / "afe" / "predictive.json",
                     set={"vehicle.gamma0": STEEP[2]}, out=tmp_path)
    assert result.status == "completed"
    assert result.outcome is not None
