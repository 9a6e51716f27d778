"""RK4 integrators of the Sec. 6 extremals (scalar math; the hot path of the shooting).

See :mod:`strategies.control.evasion` for the equations. Two integrators:

* :func:`integrate_reduced` runs in the evader's arclength σ on the state
  ``(x, y, θ, α, ln μ)``. All right-hand sides are bounded, so headings near ±π/2 cost
  nothing; the x-formulation of the paper is only needed to *interpret* the arc, which
  stops being admissible (H unbounded, THEORY §4.3) when α reaches ±π/2.
* :func:`integrate_pmp` is the paper's Fig. 10 in x with RK4: state ``(y, θ, λ2)`` and α
  the minimiser of H at every stage.

:func:`integrate_reduced_end` is :func:`integrate_reduced` without ln μ, keeping the last
row only (the shooting's coarse bracketing integrations).
"""

from __future__ import annotations

import math

from scipy.optimize import brentq

from strategies.control.hamiltonian import _kappa_scalar, minimise_hamiltonian, solve_stationary

__all__ = ["first_return", "integrate_pmp", "integrate_reduced", "integrate_reduced_end"]

_HALF_PI = 0.5 * math.pi
_NAN = math.nan
REACHED, TOO_LONG = 0, 2
"""Status codes of :func:`integrate_reduced`; ±1 means α reached ±π/2 (turned back)."""


def _rhs(th: float, a: float, s: int, L: float, rho: float, q: float):
    """d/dσ of (x, y, θ, α, ln μ); ``q = 1 / (1 - rho²)``."""
    phi = a - th
    c, sp = math.cos(phi), math.sin(phi)
    h = math.sqrt(1.0 - rho * rho * c * c)
    n = h - s * rho * sp  # L θ̇ˢ / (s V_p) >= 0
    return (
        math.cos(a),
        math.sin(a),
        s * n / (L * rho),
        n * n * sp * q / L,  # reduced extremal: dα/dσ (see evasion module docstring)
        -c * n / (h * L),
    )  # d ln μ/dσ = cos α · (-∂f2/∂θ), μ = 1 + s λ2 (E3b)


def integrate_reduced(
    theta0: float,
    alpha0: float,
    s: int,
    L: float,
    rho: float,
    step: float,
    x_target: float,
    store: bool,
    max_steps: int,
):
    """Integrate until ``x = x_target`` exactly (last step shortened by Newton on its length).

    Returns ``(rows, status)``: rows are ``(σ, x, y, θ, α, ln(μ/μ0))``; only the last row is
    kept when ``store`` is False. ``status`` is 0 (reached), +1/-1 (α reached ±π/2 going
    up/down: the arc turned back in x) or 2 (``max_steps`` exhausted).

    Each RK4 step of length ``d`` is :func:`_rhs` at the four classical stages written out
    (the same floats, without the calls: this is the shooting's inner loop), the state in
    locals; once a step passes ``x_target``, the same code runs the shortened steps from
    the last state: three Newton passes on their length ``d`` (dx/dσ = cos α), then the
    step of the final length.
    """
    cos, sin, sqrt = math.cos, math.sin, math.sqrt
    q = 1.0 / (1.0 - rho * rho)
    # the same floats as _rhs with fewer operations: rho * rho * c * c is (rho * rho) * c * c;
    # s * n / (L rho) = n / (s L rho) and -c * n / (h L) = c * n / (h (-L)) exactly (s = ±1,
    # and IEEE rounding is symmetric: a sign moves freely through products and quotients)
    rr, srho, sLrho, nL = rho * rho, s * rho, s * (L * rho), -L
    x, y, th, a, lm = 0.0, 0.0, theta0, alpha0, 0.0
    sig = 0.0
    rows = [(sig, x, y, th, a, lm)]
    d = step
    newton = 0  # 0: whole steps; 1-3: Newton passes on the last step's length; 4: final
    taken = 0
    while newton or taken < max_steps:
        h2 = 0.5 * d
        # stage 1 at (th, a)
        phi = a - th
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x1, y1 = cos(a), sin(a)
        t1 = n / sLrho
        a1 = n * n * sp * q / L
        m1 = c * n / (h * nL)
        # stage 2
        th2, aa2 = th + h2 * t1, a + h2 * a1
        phi = aa2 - th2
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x2, y2 = cos(aa2), sin(aa2)
        t2 = n / sLrho
        a2 = n * n * sp * q / L
        m2 = c * n / (h * nL)
        # stage 3
        th3, aa3 = th + h2 * t2, a + h2 * a2
        phi = aa3 - th3
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x3, y3 = cos(aa3), sin(aa3)
        t3 = n / sLrho
        a3 = n * n * sp * q / L
        m3 = c * n / (h * nL)
        # stage 4
        th4, aa4 = th + d * t3, a + d * a3
        phi = aa4 - th4
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x4, y4 = cos(aa4), sin(aa4)
        t4 = n / sLrho
        a4 = n * n * sp * q / L
        m4 = c * n / (h * nL)
        w = d / 6.0
        nx = x + w * (x1 + 2.0 * (x2 + x3) + x4)
        na = a + w * (a1 + 2.0 * (a2 + a3) + a4)
        if newton:
            if newton < 4:  # solve x(d) = x_target
                d += (x_target - nx) / cos(na)
                newton += 1
                continue
            row = (
                sig + d,
                x_target,
                y + w * (y1 + 2.0 * (y2 + y3) + y4),
                th + w * (t1 + 2.0 * (t2 + t3) + t4),
                na,
                lm + w * (m1 + 2.0 * (m2 + m3) + m4),
            )
            if store:
                rows.append(row)
            else:
                rows[0] = row
            return rows, REACHED
        if not abs(na) < _HALF_PI:  # also catches NaN
            if not store:
                rows[0] = (sig, x, y, th, a, lm)
            return rows, (1 if na > 0 else -1)
        if nx >= x_target:  # shorten this step, from the same state
            d = step * (x_target - x) / (nx - x)
            newton = 1
            continue
        y = y + w * (y1 + 2.0 * (y2 + y3) + y4)
        th = th + w * (t1 + 2.0 * (t2 + t3) + t4)
        lm = lm + w * (m1 + 2.0 * (m2 + m3) + m4)
        x, a = nx, na
        sig += step
        taken += 1
        if store:
            rows.append((sig, x, y, th, a, lm))
    if not store:
        rows[0] = (sig, x, y, th, a, lm)
    return rows, TOO_LONG


def integrate_reduced_end(
    theta0: float,
    alpha0: float,
    s: int,
    L: float,
    rho: float,
    step: float,
    x_target: float,
    max_steps: int,
):
    """:func:`integrate_reduced` with ``store`` False, without ln μ: ``(row, status)``, the
    last row ``(σ, x, y, θ, α, nan)`` and the same status.

    σ, x, y, θ and α are the same floats as :func:`integrate_reduced`'s (the same
    operations in the same order; ln μ never feeds back into them). The shooting's coarse
    grid and Brent read only y and the status: dropping ln μ's four stage terms and its
    update makes each of those integrations ~13% cheaper (issue 13: near rho = 1 they are
    nearly all of a failed solve). The loop is :func:`integrate_reduced`'s, written out
    again on purpose (a flag tested at every stage would cost what it saves); a test
    holds the two to the same floats.
    """
    cos, sin, sqrt = math.cos, math.sin, math.sqrt
    q = 1.0 / (1.0 - rho * rho)
    rr, srho, sLrho = rho * rho, s * rho, s * (L * rho)  # (as integrate_reduced)
    x, y, th, a = 0.0, 0.0, theta0, alpha0
    sig = 0.0
    d = step
    newton = 0  # 0: whole steps; 1-3: Newton passes on the last step's length; 4: final
    taken = 0
    while newton or taken < max_steps:
        h2 = 0.5 * d
        # stage 1 at (th, a)
        phi = a - th
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x1, y1 = cos(a), sin(a)
        t1 = n / sLrho
        a1 = n * n * sp * q / L
        # stage 2
        th2, aa2 = th + h2 * t1, a + h2 * a1
        phi = aa2 - th2
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x2, y2 = cos(aa2), sin(aa2)
        t2 = n / sLrho
        a2 = n * n * sp * q / L
        # stage 3
        th3, aa3 = th + h2 * t2, a + h2 * a2
        phi = aa3 - th3
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x3, y3 = cos(aa3), sin(aa3)
        t3 = n / sLrho
        a3 = n * n * sp * q / L
        # stage 4
        th4, aa4 = th + d * t3, a + d * a3
        phi = aa4 - th4
        c = cos(phi)
        sp = sin(phi)
        h = sqrt(1.0 - rr * c * c)
        n = h - srho * sp
        x4, y4 = cos(aa4), sin(aa4)
        t4 = n / sLrho
        a4 = n * n * sp * q / L
        w = d / 6.0
        nx = x + w * (x1 + 2.0 * (x2 + x3) + x4)
        na = a + w * (a1 + 2.0 * (a2 + a3) + a4)
        if newton:
            if newton < 4:  # solve x(d) = x_target
                d += (x_target - nx) / cos(na)
                newton += 1
                continue
            row = (
                sig + d,
                x_target,
                y + w * (y1 + 2.0 * (y2 + y3) + y4),
                th + w * (t1 + 2.0 * (t2 + t3) + t4),
                na,
                _NAN,
            )
            return row, REACHED
        if not abs(na) < _HALF_PI:  # also catches NaN
            return (sig, x, y, th, a, _NAN), (1 if na > 0 else -1)
        if nx >= x_target:  # shorten this step, from the same state
            d = step * (x_target - x) / (nx - x)
            newton = 1
            continue
        y = y + w * (y1 + 2.0 * (y2 + y3) + y4)
        th = th + w * (t1 + 2.0 * (t2 + t3) + t4)
        x, a = nx, na
        sig += step
        taken += 1
    return (sig, x, y, th, a, _NAN), TOO_LONG


def integrate_pmp(
    theta0: float,
    lambda1: float,
    lambda2_0: float,
    s: int,
    L: float,
    rho: float,
    dx: float,
    n_steps: int,
):
    """Fig. 10 with RK4 in x: state (y, θ, λ2), α = argmin H at every stage.

    Returns ``(rows, unbounded)`` with rows ``(x, y, θ, α, λ2)``.
    """

    def rhs(th: float, l2: float, guess: float):
        mu = 1.0 + s * l2
        lo_k = _kappa_scalar(_HALF_PI, th, L, rho, s)[0]
        hi_k = _kappa_scalar(-_HALF_PI, th, L, rho, s)[0]
        if mu <= 0.0 or not lo_k < lambda1 / mu < hi_k:  # THEORY §4.3
            return None
        a, it = solve_stationary(lambda1 / mu, th, L, rho, s, guess)
        if it >= 60:  # pragma: no cover - the bracketed iteration always converges
            a = minimise_hamiltonian(th, lambda1, l2, L=L, rho=rho, branch=s).alpha
        phi = a - th
        c, sp = math.cos(phi), math.sin(phi)
        ca = math.cos(a)
        hh = math.sqrt(1.0 - rho * rho * c * c)
        n = hh - s * rho * sp
        return math.tan(a), s * n / (L * rho * ca), -(s + l2) * c * n / (hh * L * ca), a

    y, th, l2 = 0.0, theta0, lambda2_0
    k1 = rhs(th, l2, 0.0)
    if k1 is None:
        return [], True
    rows = [(0.0, y, th, k1[3], l2)]
    h2 = 0.5 * dx
    for i in range(1, n_steps + 1):
        k2 = rhs(th + h2 * k1[1], l2 + h2 * k1[2], k1[3])
        k3 = k2 and rhs(th + h2 * k2[1], l2 + h2 * k2[2], k2[3])
        k4 = k3 and rhs(th + dx * k3[1], l2 + dx * k3[2], k3[3])
        if k4 is None:
            return rows, True
        w = dx / 6.0
        y += w * (k1[0] + 2.0 * (k2[0] + k3[0]) + k4[0])
        th += w * (k1[1] + 2.0 * (k2[1] + k3[1]) + k4[1])
        l2 += w * (k1[2] + 2.0 * (k2[2] + k3[2]) + k4[2])
        k1 = rhs(th, l2, k4[3])
        if k1 is None:
            return rows, True
        rows.append((i * dx, y, th, k1[3], l2))
    return rows, False


def _hermite(t, t0, t1, v0, v1, m0, m1) -> float:
    d = t1 - t0
    u = (t - t0) / d
    u2, u3 = u * u, u * u * u
    return (
        (2 * u3 - 3 * u2 + 1) * v0
        + (u3 - 2 * u2 + u) * d * m0
        + (-2 * u3 + 3 * u2) * v1
        + (u3 - u2) * d * m1
    )


def first_return(t, x, y, th, dx, dy, dth, tol: float):
    """First sign change of y after it leaves 0, by cubic Hermite interpolation in the
    integration variable ``t`` (O(step⁴), like RK4). ``dx, dy, dth`` are derivatives in t.

    Returns ``(x_c, θ(x_c))`` or ``(None, None)``. ``|y| <= tol`` counts as zero.
    """
    n = len(t)
    i0 = next((i for i in range(1, n) if abs(y[i]) > tol), None)
    if i0 is None:
        return None, None
    sgn = 1.0 if y[i0] > 0 else -1.0
    j = next((j for j in range(i0 + 1, n) if sgn * y[j] <= tol), None)
    if j is None:
        return None, None
    if abs(y[j]) <= tol:
        tc = t[j]
    else:
        tc = brentq(
            lambda u: _hermite(u, t[j - 1], t[j], y[j - 1], y[j], dy[j - 1], dy[j]),
            t[j - 1],
            t[j],
            xtol=1e-15,
        )
    xc = _hermite(tc, t[j - 1], t[j], x[j - 1], x[j], dx[j - 1], dx[j])
    thc = _hermite(tc, t[j - 1], t[j], th[j - 1], th[j], dth[j - 1], dth[j])
    return float(xc), float(thc)
