"""Damped Newton iteration with a forward-difference Jacobian, shared by the guidance solvers."""

import numpy as np


def damped_newton(fun, x0, steps, tol, max_iter, min_alpha=1e-3):
    """Solve fun(x) = 0 by Newton steps halved until max|fun| decreases.

    steps: forward-difference step per unknown; tol: accepted max|fun|; the step length is halved
    down to min_alpha. Returns (x, converged, iterations, max|fun|). Non-finite residuals or a
    singular Jacobian end the iteration as not converged.
    """
    x = np.array(x0, dtype=float)
    r = fun(x)
    for it in range(max_iter + 1):
        norm = float(np.max(np.abs(r)))
        if not np.isfinite(norm):
            return x, False, it, norm
        if norm <= tol:
            return x, True, it, norm
        jac = np.empty((r.size, x.size))
        for j, hj in enumerate(steps):
            xp = x.copy()
            xp[j] += hj
            jac[:, j] = (fun(xp) - r) / hj
        if not np.all(np.isfinite(jac)):
            return x, False, it, norm
        try:
            dx = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            return x, False, it, norm
        alpha = 1.0
        while alpha > min_alpha:
            r_new = fun(x + alpha * dx)
            if np.all(np.isfinite(r_new)) and np.linalg.norm(r_new) < np.linalg.norm(r):
                break
            alpha *= 0.5
        else:
            return x, False, it, norm
        x, r = x + alpha * dx, r_new
    return x, False, max_iter, float(np.max(np.abs(r)))
