"""Monolithic reference: the same physics modules integrated by SciPy in one ODE system.

For systems whose guidance is a function of time, the entry state and the current state (open
loop or static feedback), the co-simulation's only approximation is the coupling: inputs held over
each communication step.
This reference integrates the vehicle equations (`physics.point_mass.derivatives`) with the
density evaluated continuously and the command evaluated at every instant (solve_ivp, DOP853,
tight tolerances), so `co-simulation - reference` measures the coupling error. The parameters are
those of the scenario's wiring (FMU defaults overridden by the wiring and the scenario).
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from aotv_cosim.errors import InputError
from aotv_cosim.guidance.optimal_bvp import solve_min_effort
from aotv_cosim.guidance.predictive import solve_predictive, solve_predictive_adaptive
from aotv_cosim.guidance.time_linear import approximate_law_coefficients
from aotv_cosim.guidance.tracking import InfiniteLqrLaw, RobustLaw, TerminalLqrLaw
from aotv_cosim.physics import aero, point_mass
from aotv_cosim.physics.actuator import saturate
from aotv_cosim.physics.atmosphere import density_dispersion, exponential_density
from aotv_cosim.physics.constants import R_EARTH_000


def effective_parameters(component) -> dict:
    """The values a component runs with: the FMU's start values, then the wiring's values."""
    values = {}
    for var in component.fmu.variables.values():
        if var.causality in ("parameter", "input") and var.start is not None:
            values[var.name] = {"Real": float, "Integer": int}.get(var.type, str)(var.start)
    values.update(component.parameters)
    return values


def _time_linear_command(params, entry, start):
    """u(t) of TimeLinearGuidance: eqs. (4.23), (4.28) on the entry state, 0 after tf."""
    a, b = approximate_law_coefficients(entry["v"], entry["gamma"], entry["h"], params["tf"],
                                        params["weight"])
    tf = params["tf"]
    return lambda t, x: a + b * (t - start) if t - start <= tf * (1.0 + 1e-12) else 0.0


def _until(final_time, start, law):
    """u(t, x) = law(t - start, x) while t - start <= final_time, else 0 (the FMUs' convention)."""
    return lambda t, x: law(t - start, x) if t - start <= final_time * (1.0 + 1e-12) else 0.0


def _exit_target(params):
    return params["hf"], params["vf"], params["gammaf"]


def _optimal_command(params, entry, start):
    """u(t) of OptimalGuidance: the 2PBVP (3.21)-(3.22) solution from the entry state, eq. (3.20)."""
    sol = solve_min_effort((entry["h"], entry["v"], entry["gamma"]), _exit_target(params), params["tf"],
                           params["K_ball"], free_exit_velocity=bool(params["free_exit_velocity"]))
    return _until(params["tf"], start, lambda s, x: float(sol.u(s)))


def _linear(sol, start):
    return _until(sol.tf, start, lambda s, x: sol.a + sol.b * s)


def _predictive_command(params, entry, start):
    """u(t) of PredictiveGuidance: (a, b, tf') of Ch. 6 from the entry state."""
    return _linear(solve_predictive((entry["h"], entry["v"], entry["gamma"]), _exit_target(params),
                                    params["K_ball"]), start)


def _predictive_adaptive_command(params, entry, start):
    """u(t) of PredictiveAdaptiveGuidance: K from the drag measured at entry (8.1), then (a, b, tf')."""
    _k, sol = solve_predictive_adaptive((entry["h"], entry["v"], entry["gamma"]), entry["drag"],
                                        _exit_target(params))
    return _linear(sol, start)


def _tracking(build):
    """Builder of u(t, x) = u_d + du for a NominalTrackingGuidance whose law is build(params, nominal)."""
    def builder(params, entry, start):
        nominal = solve_min_effort((params["h0_nom"], params["v0_nom"], params["gamma0_nom"]),
                                   _exit_target(params), params["tf"], params["K_ball"])
        law = build(params, nominal)
        return _until(params["tf"], start, lambda s, x: float(nominal.u(s)) + law.delta_u(
            s, (x[0] - R_EARTH_000, x[3], x[4])))
    return builder


def _weights(params, prefix):
    return tuple(params[f"{prefix}_{k}"] for k in ("r", "v", "gamma"))


GUIDANCE = {
    "TimeLinearGuidance": _time_linear_command,
    "OptimalGuidance": _optimal_command,
    "PredictiveGuidance": _predictive_command,
    "PredictiveAdaptiveGuidance": _predictive_adaptive_command,
    "InfiniteLqrGuidance": _tracking(lambda p, nom: InfiniteLqrLaw(
        nom, R_EARTH_000, p["K_ball"], _weights(p, "Q"), p["R_u"])),
    "TerminalLqrGuidance": _tracking(lambda p, nom: TerminalLqrLaw(
        nom, R_EARTH_000, p["K_ball"], p["tf"], _weights(p, "Q"), p["R_u"], _weights(p, "V"))),
    "RobustGuidance": _tracking(lambda p, nom: RobustLaw(nom, R_EARTH_000)),
}
"""Guidance FMUs the reference can reproduce: name -> builder of u(t, x) in m/s^2, x the vehicle
state of `physics.point_mass` (r, theta, phi, v, gamma, psi). AdaptiveGuidance is absent: its gain
is a state advanced once per communication step, not a function of (t, x)."""


@dataclass
class ReferenceResult:
    t: np.ndarray
    y: np.ndarray
    final: dict
    event_time: float | None = None
    event: dict | None = None


def _component(system, fmu_name):
    for comp in system.components.values():
        if comp.fmu.model_identifier == fmu_name:
            return comp
    raise InputError(f"the system has no {fmu_name} component", file=system.path, entry="components",
                     fix="the monolithic reference covers PointMassVehicle + Atmosphere + guidance")


def _actuator_map(system):
    comps = [c for c in system.components.values() if c.fmu.model_identifier.endswith("Actuator")]
    if not comps:
        return lambda u: u
    p = effective_parameters(comps[0])
    if p.get("time_constant", 0.0) > 0 or math.isfinite(p.get("rate_limit", math.inf)):
        raise InputError("the reference covers a saturating actuator only", file=system.path,
                         entry=f"components.{comps[0].name}", fix="disable lag and rate limit")
    return lambda u: saturate(u, p["lower"], p["upper"])


def reference_run(scenario, rtol=1e-12, atol=None) -> ReferenceResult:
    """Integrate the scenario's vehicle, atmosphere and open-loop guidance monolithically.

    Returns the state history, the final vehicle outputs {'vehicle.h': ...} (m, m/s, rad) and,
    if the scenario has a stop condition on a vehicle state output, its located crossing.
    """
    system = scenario.system
    vehicle = _component(system, "PointMassVehicle")
    vp = effective_parameters(vehicle)
    ap = effective_parameters(_component(system, "Atmosphere"))
    guidance = next((c for c in system.components.values() if c.fmu.model_identifier in GUIDANCE), None)
    if guidance is None:
        raise InputError("no guidance the reference can reproduce", file=system.path, entry="components",
                         fix=f"use one of {', '.join(GUIDANCE)}")
    def density(t, h):
        factor = density_dispersion(t - scenario.start, ap["density_factor"], ap["noise_amplitude"],
                                    ap["noise_interval"], ap["noise_seed"])
        return factor * exponential_density(h, ap["rho_ref"], ap["h_ref"], ap["scale_height"])

    rho0 = density(scenario.start, vp["h0"])
    entry = {"h": vp["h0"], "v": vp["v0"], "gamma": vp["gamma0"],
             "drag": aero.parasite_drag_acceleration(rho0, vp["v0"], vp["CD0"], vp["mass_per_area"])}
    command = GUIDANCE[guidance.fmu.model_identifier](effective_parameters(guidance), entry, scenario.start)
    actuate = _actuator_map(system)
    cd_s_m = vp["CD0"] / vp["mass_per_area"]
    R_e = vp["R_e"]
    consts = (vp["sigma"], int(vp["gravity_model"]), vp["g0"], vp["mu"])

    def rhs(t, y):
        x = y[:6]
        rho = density(t, x[0] - R_e)
        u = actuate(command(t, x))
        dx = point_mass.derivatives(x, rho, u, 0.0, cd_s_m, *consts)
        return [*dx, u, abs(u), u * u]

    y0 = [R_e + vp["h0"], vp["theta0"], vp["phi0"], vp["v0"], vp["gamma0"], vp["psi0"], 0.0, 0.0, 0.0]
    names = ["r", "theta", "phi", "v", "gamma", "psi", "int_u", "int_abs_u", "int_u2"]
    events = _events(scenario, vehicle.name, names, R_e)
    sol = solve_ivp(rhs, (scenario.start, scenario.stop), y0, method="DOP853", rtol=rtol,
                    atol=atol if atol is not None else [1e-6, 1e-13, 1e-13, 1e-8, 1e-13, 1e-13, 1e-9, 1e-9, 1e-9],
                    events=events or None, dense_output=True)
    final = _outputs(vehicle.name, names, sol.y[:, -1], R_e)
    result = ReferenceResult(sol.t, sol.y, final)
    if events and len(sol.t_events[0]):
        result.event_time = float(sol.t_events[0][0])
        result.event = _outputs(vehicle.name, names, sol.y_events[0][0], R_e)
    return result


def _outputs(vehicle, names, y, R_e):
    out = {f"{vehicle}.{n}": float(v) for n, v in zip(names, y)}
    out[f"{vehicle}.h"] = float(y[0] - R_e)
    return out


def _events(scenario, vehicle, names, R_e):
    """solve_ivp event functions for the first stop condition on a vehicle state (h or a state)."""
    events = []
    for cond in scenario.stop_conditions[:1]:
        comp, var = cond.signal.split(".", 1)
        if comp != vehicle or var not in [*names, "h"]:
            continue
        k = 0 if var == "h" else names.index(var)
        offset = R_e if var == "h" else 0.0

        def crossing(t, y, k=k, thr=cond.threshold + offset):
            return y[k] - thr

        crossing.terminal = True  # type: ignore[attr-defined]  # read by solve_ivp
        crossing.direction = {"up": 1, "down": -1}.get(cond.direction, 0)  # type: ignore[attr-defined]  # read by solve_ivp
        events.append(crossing)
    return events
