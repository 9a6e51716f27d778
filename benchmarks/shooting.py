"""Benchmark of the Sec. 6 shooting: one ``solve_escape`` and one ``shoot``.

Plain script: ``python benchmarks/shooting.py [n_cases]``. A fixed seeded set of random
cases (theta0, x_e, L, rho, branch) is timed; the reference measured in the same run is
``scipy.integrate.solve_ivp`` (RK45, rtol 1e-10) on the same reduced extremal ODE over
the same arc, so the ratios are machine independent.
"""

from __future__ import annotations

import argparse
import math
import time
from functools import partial

import numpy as np
from bench_cli import integer, run
from scipy.integrate import solve_ivp

from strategies.control.evasion import shoot, solve_escape


def _cases(n: int, seed: int = 20070101):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        L = float(rng.uniform(0.5, 2.0))
        yield (
            float(rng.uniform(-math.pi, math.pi)),
            L * float(rng.uniform(0.2, 2.0)),
            L,
            float(rng.uniform(0.2, 0.9)),
            str(rng.choice(["+", "-"])),
        )


def _rhs(s, L, rho):
    q = 1.0 / (1.0 - rho * rho)

    def f(_sig, z):
        _, _, th, a, _ = z
        phi = a - th
        c, sp = math.cos(phi), math.sin(phi)
        h = math.sqrt(1.0 - rho * rho * c * c)
        n = h - s * rho * sp
        return [math.cos(a), math.sin(a), s * n / (L * rho), n * n * sp * q / L, -c * n / (h * L)]

    return f


def _timed(fn, repeat: int = 3) -> float:
    """Best of ``repeat`` wall-clock runs."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(n_cases: int = 40) -> None:
    t_solve, t_shoot, t_ref, failures = [], [], [], 0
    for theta0, x_e, L, rho, branch in _cases(n_cases):
        sol = solve_escape(theta0, x_e, L=L, rho=rho, branch=branch)
        t_solve.append(_timed(partial(solve_escape, theta0, x_e, L=L, rho=rho, branch=branch)))
        if not sol.success:
            failures += 1
            continue
        l1, l20 = sol.lambda1, sol.lambda2_0
        t_shoot.append(
            _timed(partial(shoot, theta0, l1, l20, L=L, rho=rho, branch=branch, x_max=x_e))
        )
        s = 1 if branch == "+" else -1
        sig_end = float(sol.arc.arclength[-1])
        z0 = [0.0, 0.0, theta0, sol.alpha0, 0.0]
        t_ref.append(
            _timed(partial(solve_ivp, _rhs(s, L, rho), (0.0, sig_end), z0, rtol=1e-10, atol=1e-12))
        )

    def stats(name, ts):
        ms = 1e3 * np.asarray(ts)
        print(
            f"{name:<34} median {np.median(ms):8.3f} ms   p90 {np.percentile(ms, 90):8.3f} ms"
            f"   max {ms.max():8.3f} ms"
        )

    print(
        f"cases: {n_cases} (seeded; rho in [0.2, 0.9], x_e/L in [0.2, 2]), "
        f"solve_escape failures: {failures}"
    )
    stats("solve_escape", t_solve)
    stats("shoot (one arc, reduced RK4)", t_shoot)
    stats("reference: solve_ivp RK45 same arc", t_ref)
    print(
        f"ratio shoot / solve_ivp (median of per-case ratios): "
        f"{np.median(np.asarray(t_shoot) / np.asarray(t_ref)):.3f}"
    )
    print(f"ratio solve_escape / solve_ivp arc: {np.median(t_solve) / np.median(t_ref):.2f}")


def _cli() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n_cases", nargs="?", type=integer(1), default=40, help="cases (40)")
    main(ap.parse_args().n_cases)
    return 0


if __name__ == "__main__":
    raise SystemExit(run(_cli))
