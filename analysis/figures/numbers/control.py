"""The numbers of Secs. 5-7: Fig. 9, eq. (6) and errata E1-E8, the shooting method and
Figs. 10-13, the cooperative motions."""

from __future__ import annotations

import math

import numpy as np

from analysis.figures import cases
from analysis.figures.numbers import number, yes_no

# ------------------------------------------------------------------ Sec. 5, Fig. 9
number("fig9a.T", "time to turn the rod by pi/2 against a charge (L = 2, rho = 0.5)", "{:.4f}")(
    lambda: cases.charge_rotation().T
)
number("fig9a.recoil", "how far the charge pushes the pursuer back meanwhile", "{:.4f}")(
    lambda: cases.charge_rotation().recoil
)


@number("fig9b.l_star", "corner: least evader-corner distance, rho L/(1 + rho), L = 2", "{:.4f}")
def _l_star_2() -> float:
    from envs.maps import builtin_info
    from strategies.control import corner_min_distance

    i = builtin_info("corner")
    return corner_min_distance(L=i.l_min, rho=i.rho)


@number("e8.relative", "L theta_dot with the evader crossing the rod, pursuer still", "{:.2f}")
def _e8() -> float:
    from strategies.control import theta_dot_from_velocities

    return float(theta_dot_from_velocities((0.0, 0.5), (0.0, 0.0), 0.0, L=1.0))


# ------------------------------------------------------------------ Sec. 6.1
def _td(phi: float):
    from strategies.control import theta_dot

    return theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=0.5)


number("eq6.plus_pi6", "theta_dot+ at alpha - theta = pi/6 (rho = 0.5)", "{:.10f}")(
    lambda: _td(math.pi / 6)[0]
)
number("eq6.minus_pi6", "theta_dot- at alpha - theta = pi/6", "{:.10f}")(
    lambda: _td(math.pi / 6)[1]
)
number("eq6.plus_3pi2", "theta_dot+ at 3 pi/2", "{:.10f}")(lambda: _td(1.5 * math.pi)[0])


@number("e1.rho1", "theta_dot+ at rho = 1, alpha - theta = pi/2 (the paper: > 0)", "{:.1f}")
def _e1() -> float:
    from strategies.control import theta_dot

    return float(theta_dot(0.5 * math.pi, 0.0, L=1.0, v_p=1.0, rho=1.0)[0])


number("e2.minrate", "min over alpha of max |theta_dot| (rho = 0.5, L = V_p = 1)", "{:.4f}")(
    lambda: (
        __import__("strategies.control", fromlist=["x"])
        .min_max_theta_dot(0.0, L=1.0, v_p=1.0, rho=0.5)
        .rate
    )
)


def _g(phi, rho: float):
    from strategies.control import max_abs_theta_dot

    return np.asarray(max_abs_theta_dot(phi, 0.0, L=1.0, v_p=1.0, rho=rho))


@number(
    "e2.g2",
    "g''(0+) for rho = 0.5 by finite differences (closed form rho^2/sqrt(1-rho^2))",
    "{:.4f}",
)
def _e2_g2() -> float:
    h = 1e-5
    x = np.array([h, 2 * h, 3 * h])
    y = _g(x, 0.5)
    return float((y[0] - 2 * y[1] + y[2]) / h**2)


number("e2.g2_closed", "rho^2 / sqrt(1 - rho^2) at rho = 0.5", "{:.4f}")(
    lambda: 0.25 / math.sqrt(0.75)
)


def _inflection(rho: float) -> float:
    from scipy.optimize import brentq

    h = 1e-4

    def g2(x: float) -> float:
        y = _g(np.array([x - h, x, x + h]), rho)
        return float((y[0] - 2 * y[1] + y[2]) / h**2)

    return float(brentq(g2, 0.05, 1.2, xtol=1e-10))


for _rho in (0.3, 0.5, 0.9):
    number(f"e2.inflection_{_rho}", f"inflection of g on (0, pi/2), rho = {_rho}", "{:.5f}")(
        lambda r=_rho: _inflection(r)
    )


# ------------------------------------------------------------------ Sec. 6.2, Figs. 10-13
for _w in "ab":
    number(
        f"fig11{_w}.rho", f"the rho at which Fig. 11({_w})'s shot returns at x_e (L = 1)", "{:.4f}"
    )(lambda w=_w: cases.paper_shot_rho(w))
    number(f"fig11{_w}.k_printed", f"lambda1 / (1 + lambda2) printed in Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.PAPER_SHOTS[w]["lambda1"] / (1 + cases.PAPER_SHOTS[w]["lambda2_0"])
    )
    number(f"fig11{_w}.k_solved", f"k found by solve_escape for Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.paper_shot(w)[1].k
    )
    number(f"fig11{_w}.J", f"rotation J = theta(x_e) - theta0, Fig. 11({_w})", "{:.4f}")(
        lambda w=_w: cases.paper_shot(w)[0].J
    )
    number(
        f"fig11{_w}.lambdas",
        f"normalised (lambda1, lambda2(0)), lambda2(x_e) = 0, ({_w})",
        lambda v: f"({v[0]:.4f}, {v[1]:.4f})",
    )(lambda w=_w: (cases.paper_shot(w)[1].lambda1, cases.paper_shot(w)[1].lambda2_0))
    number(f"fig11{_w}.H_spread", f"max - min of H along the arc ({_w})", "{:.0e}")(
        lambda w=_w: float(np.ptp(cases.paper_shot(w)[0].H))
    )


@number("fig11a.xc_rho05", "Fig. 11(a)'s shot at L = 1, rho = 0.5: return abscissa", "{:.4f}")
def _xc05() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    return shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.5, x_max=4.0).x_c


@number("fig11a.H_rho05", "H along that arc (THEORY.md: 2.416242)", "{:.6f}")
def _h05() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    return float(shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.5, x_max=1.0).H[0])


@number("fig11b.unbounded_rho09", "Fig. 11(b)'s multipliers at rho = 0.9: H unbounded", yes_no)
def _unb() -> bool:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["b"]
    return shoot(p["theta0"], p["lambda1"], p["lambda2_0"], L=1.0, rho=0.9, x_max=2.0).unbounded


@number(
    "fig10.step", "change of the return abscissa from step 1e-2 to 1e-3 (Fig. 10, RK4)", "{:.0e}"
)
def _step() -> float:
    from strategies.control import shoot

    p = cases.PAPER_SHOTS["a"]
    xs = [
        shoot(
            p["theta0"],
            p["lambda1"],
            p["lambda2_0"],
            L=1.0,
            rho=0.5,
            x_max=2.0,
            method="pmp",
            step=h,
        ).x_c
        for h in (1e-2, 1e-3)
    ]
    return abs(xs[0] - xs[1])


@number(
    "fig10.scale",
    "max |y| difference of the shots (-1, 0.41), (-2, 1.82), (-0.5, -0.295)",
    "{:.0e}",
)
def _scale() -> float:
    from strategies.control import shoot

    arcs = [
        shoot(math.pi, a, b, L=1.0, rho=0.5, x_max=1.0)
        for a, b in ((-1.0, 0.41), (-2.0, 1.82), (-0.5, -0.295))
    ]
    n = min(len(a.y) for a in arcs)
    return float(max(np.max(np.abs(a.y[:n] - arcs[0].y[:n])) for a in arcs))


@number("fig12.alpha", "greedy heading at theta = pi (rho = 0.5): -arctan rho", "{:.4f}")
def _ga() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(math.pi, L=1.0, rho=0.5).alpha)


@number("fig12.f2", "its rate d theta/dx = (1 - rho^2)/(L rho)", "{:.4f}")
def _gf() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(math.pi, L=1.0, rho=0.5).f2)


@number(
    "minus.alpha", "theta_dot- branch, greedy heading at theta = 0 (minimises |rotation|)", "{:.4f}"
)
def _ma() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(0.0, L=1.0, rho=0.5, branch="-").alpha)


@number("minus.f2", "its rate (signed)", "{:.4f}")
def _mf() -> float:
    from strategies.control import greedy_heading

    return float(greedy_heading(0.0, L=1.0, rho=0.5, branch="-").f2)


@number(
    "minus.paper",
    "the paper's H for theta_dot-, (1 + lambda2) f2 at lambda2 = 0, "
    "at alpha = pi/2 - 1e-3: unbounded below",
    "{:.0f}",
)
def _mp() -> float:
    from strategies.control.hamiltonian import f2

    return float(f2(0.5 * math.pi - 1e-3, 0.0, L=1.0, rho=0.5, branch="-"))


for _c in ("vertex", "curve"):

    def _case(c=_c):
        return cases.vertex_escape() if c == "vertex" else cases.curve_escape()

    number(f"fig13.{_c}.needed", f"rotation needed ({_c} endpoint)", "{:.4f}")(
        lambda f=_case: f().needed
    )
    number(f"fig13.{_c}.achieved", f"rotation |J| the pursuer can effect ({_c})", "{:.4f}")(
        lambda f=_case: f().achieved
    )
    number(f"fig13.{_c}.escapes", f"the evader escapes ({_c})", yes_no)(
        lambda f=_case: f().evader_escapes
    )


# ------------------------------------------------------------------ Sec. 7
@number(
    "tractrix.t1",
    "follower and theta at t = 1 (L = V_e = 1, theta0 = pi/2)",
    lambda v: f"({v[0]:.10f}, {v[1]:.10f}), {v[2]:.10f}",
)
def _tr() -> tuple[float, float, float]:
    from strategies.control import tractrix

    tr = tractrix([1.0])
    return float(tr.follower[0, 0]), float(tr.follower[0, 1]), float(tr.theta[0])


@number(
    "tractrix.rk4", "max distance closed form vs RK4 of the dragged follower, t in [0, 4]", "{:.0e}"
)
def _tr_rk4() -> float:
    from strategies.control import tractrix, tractrix_numeric

    t = np.linspace(0.0, 4.0, 17)
    return float(np.max(np.hypot(*(tractrix(t).follower - tractrix_numeric(t).follower).T)))


def _T(theta1: float) -> float:
    from strategies.control import straight_leader_time

    return straight_leader_time(0.5 * math.pi, theta1, alpha=0.0, L=1.0, v_p=1.0, rho=0.5)


number("e5.T_plus", "T from pi/2 to pi, rho = 0.5 (counter-clockwise)", "{:.10f}")(
    lambda: _T(math.pi)
)
number("e5.T_minus", "T from pi/2 to 0 (clockwise)", "{:.10f}")(lambda: _T(0.0))


@number("e5.quad", "largest |closed form - quadrature of L / theta_dot| over both", "{:.0e}")
def _quad() -> float:
    from scipy.integrate import quad

    from strategies.control import theta_dot

    out = 0.0
    for th1, k in ((math.pi, 0), (0.0, 1)):

        def f(th, k=k):
            return 1.0 / abs(theta_dot(0.0, th, L=1.0, v_p=1.0, rho=0.5)[k])

        lo, hi = sorted((0.5 * math.pi, th1))
        out = max(out, abs(quad(f, lo, hi, epsabs=1e-14, epsrel=1e-13)[0] - _T(th1)))
    return out


@number(
    "e6.speed60", "wall following: worst-case follower speed at theta = 60 deg (V_e = 1)", "{:.4f}"
)
def _w60() -> float:
    from strategies.control import wall_follow_max_speed

    return float(wall_follow_max_speed(math.radians(60.0), v_e=1.0))


@number("e6.feasible120", "feasible at theta = 120 deg, rho = 0.45 (|cos| = 0.5 >= rho)", yes_no)
def _w120() -> bool:
    from strategies.control import wall_follow_feasible

    return bool(wall_follow_feasible(math.radians(120.0), rho=0.45))


@number("e7.l_star", "corner: rho L/(1 + rho) for L = 1, rho = 0.5", "{:.4f}")
def _l_star_1() -> float:
    from strategies.control import corner_min_distance

    return corner_min_distance(L=1.0, rho=0.5)


@number("e7.fd", "|finite-difference velocity of p = e + (L/l)(v - e) - the formula|", "{:.0e}")
def _fd() -> float:
    from strategies.control import corner_pursuer_position, corner_pursuer_velocity

    e, v, ev, h = np.array([-0.3, 0.4]), np.array([0.0, 0.0]), np.array([0.2, -0.45]), 1e-6
    num = (
        corner_pursuer_position(e + h * ev, v, L=1.0)
        - corner_pursuer_position(e - h * ev, v, L=1.0)
    ) / (2 * h)
    return float(np.max(np.abs(num - corner_pursuer_velocity(e, v, ev, L=1.0))))
