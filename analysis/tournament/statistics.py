"""Statistics of a tournament: intervals, payoff matrices, Nash, ratings, paired tests.

Inputs are the flat rows of :meth:`Store.rows` (one per finished match). A match counts
for the pursuer when surveillance held to the horizon (``winner == "pursuer"``),
including forfeits; ``error`` rows (nobody played) are left out and counted apart.

* :func:`cells` -- per scope (map, variant, start) and pairing: the held rate with its
  Wilson interval, the mean time to escape with a Student t interval, escape causes.
* :func:`payoff_matrices` -- pursuers x evaders held-rate matrices per scope and pooled
  ("overall"), and :func:`games`, the zero-sum game of each (Nash mixtures, value, each
  policy's exploitability within the roster; :mod:`strategies.mixed`).
* :func:`ratings` -- one strength per policy on one scale for both roles, a
  Bradley-Terry (Rasch) model P(hold) = sigmoid(a_pursuer - b_evader) fitted by maximum a
  posteriori (a weak N(0, 3^2) prior keeps all-or-nothing pairings finite), with
  posterior (Laplace) intervals, or percentile bootstrap ones on request.
* :func:`paired_comparisons` -- two policies of one role on the *same* starts (common
  random numbers): McNemar's exact test on the discordant pairs, Holm-adjusted.
* :func:`sprt` -- Wald's sequential probability ratio test on discordant pairs.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import stats

from envs.errors import InvalidConfigError

__all__ = [
    "Cell",
    "Game",
    "Matrix",
    "PairedComparison",
    "Rating",
    "bootstrap_mean_interval",
    "cells",
    "games",
    "paired_comparisons",
    "payoff_matrices",
    "ratings",
    "scope_of",
    "sprt",
    "t_mean_interval",
    "wilson_interval",
]

OVERALL = "overall"


# --------------------------------------------------------------------------- intervals
def _check_confidence(confidence: float) -> float:
    from envs.validation import unit_interval

    return unit_interval("confidence", confidence)


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (``n = 0`` gives ``(0, 1)``).

    Examples:
        >>> lo, hi = wilson_interval(8, 10)
        >>> round(lo, 4), round(hi, 4)
        (0.4902, 0.9433)
    """
    c = _check_confidence(confidence)
    if n < 0 or not 0 <= successes <= n:
        raise InvalidConfigError(f"need 0 <= successes <= n, got successes={successes}, n={n}")
    if n == 0:
        return (0.0, 1.0)
    z = float(stats.norm.ppf(0.5 + c / 2))
    if successes in (0, n):  # exact ends: 0 (resp. 1) without rounding residue
        edge = z * z / (n + z * z)
        return (0.0, edge) if successes == 0 else (1.0 - edge, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def t_mean_interval(
    values: Sequence[float], confidence: float = 0.95
) -> tuple[float, float, float]:
    """``(mean, lo, hi)`` with a Student t interval; NaNs when empty, infinite for one value."""
    c = _check_confidence(confidence)
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return (math.nan, math.nan, math.nan)
    m = float(x.mean())
    if x.size == 1:
        return (m, -math.inf, math.inf)
    h = float(stats.t.ppf(0.5 + c / 2, x.size - 1)) * float(x.std(ddof=1)) / math.sqrt(x.size)
    return (m, m - h, m + h)


def bootstrap_mean_interval(
    values: Sequence[float], confidence: float = 0.95, *, n_resamples: int = 2000, seed: int = 0
) -> tuple[float, float, float]:
    """``(mean, lo, hi)`` with a percentile bootstrap interval; NaNs when empty."""
    c = _check_confidence(confidence)
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return (math.nan, math.nan, math.nan)
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(n_resamples, x.size))].mean(axis=1)
    lo, hi = np.quantile(means, [0.5 - c / 2, 0.5 + c / 2])
    return (float(x.mean()), float(lo), float(hi))


# --------------------------------------------------------------------------- cells
def scope_of(row: Mapping[str, Any], *, variants: bool, starts: bool) -> str:
    """The scope label of a row: its map, plus the variant/start when they vary."""
    parts = [row["map"]]
    if variants and row.get("variant"):
        parts.append(row["variant"])
    if starts:
        parts.append(f"{row['start']} start")
    return " | ".join(parts)


def _scoped(rows: Sequence[Mapping[str, Any]]) -> list[tuple[str, Mapping[str, Any]]]:
    variants = len({r["variant"] for r in rows}) > 1
    starts = len({r["start"] for r in rows}) > 1
    return [(scope_of(r, variants=variants, starts=starts), r) for r in rows]


@dataclass(frozen=True)
class Cell:
    """One pairing in one scope.

    Attributes:
        scope: map (| variant | start) label, or ``"overall"``.
        pursuer, evader: roster labels.
        n: matches with a winner (played out or forfeited).
        held: of those, won by the pursuer.
        rate, lo, hi: held rate and its Wilson interval.
        escape_mean, escape_lo, escape_hi: mean time to escape (s) over the escapes,
            Student t interval (NaN without escapes).
        causes: escape causes (and ``"forfeit"``) with their counts.
        forfeits: ``{"pursuer": k, "evader": k}`` matches lost by forfeit.
        errors: matches that could not be played.
    """

    scope: str
    pursuer: str
    evader: str
    n: int
    held: int
    rate: float
    lo: float
    hi: float
    escape_mean: float
    escape_lo: float
    escape_hi: float
    causes: dict[str, int] = field(default_factory=dict)
    forfeits: dict[str, int] = field(default_factory=dict)
    errors: int = 0


def _cell(scope: str, p: str, e: str, rows: Sequence[Mapping[str, Any]], conf: float) -> Cell:
    decided = [r for r in rows if r["status"] != "error" and r["winner"] is not None]
    held = sum(r["winner"] == "pursuer" for r in decided)
    lo, hi = wilson_interval(held, len(decided), conf)
    times = [
        r["escape_time"]
        for r in decided
        if r["winner"] == "evader" and r["status"] == "ok" and r["escape_time"] is not None
    ]
    mean, tlo, thi = t_mean_interval(times, conf)
    causes: dict[str, int] = {}
    forfeits = {"pursuer": 0, "evader": 0}
    for r in decided:
        if r["status"] == "forfeit":
            forfeits[r["blame"]] = forfeits.get(r["blame"], 0) + 1
            causes["forfeit"] = causes.get("forfeit", 0) + 1
        elif r["cause"]:
            causes[r["cause"]] = causes.get(r["cause"], 0) + 1
    return Cell(
        scope,
        p,
        e,
        len(decided),
        held,
        held / len(decided) if decided else math.nan,
        lo,
        hi,
        mean,
        tlo,
        thi,
        causes,
        forfeits,
        len(rows) - len(decided),
    )


def cells(
    rows: Sequence[Mapping[str, Any]], *, confidence: float = 0.95, overall: bool = True
) -> list[Cell]:
    """Per scope and pairing, then pooled over scopes (``"overall"``) if there are several."""
    groups: dict[tuple[str, str, str], list[Mapping[str, Any]]] = {}
    scoped = _scoped(rows)
    for scope, r in scoped:
        groups.setdefault((scope, r["pursuer"], r["evader"]), []).append(r)
    out = [_cell(s, p, e, g, confidence) for (s, p, e), g in groups.items()]
    if overall and len({s for s, _ in scoped}) > 1:
        pooled: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
        for r in rows:
            pooled.setdefault((r["pursuer"], r["evader"]), []).append(r)
        out += [_cell(OVERALL, p, e, g, confidence) for (p, e), g in pooled.items()]
    return out


# --------------------------------------------------------------------------- games
@dataclass(frozen=True)
class Matrix:
    """A payoff matrix: held rates of pursuers (rows) against evaders (columns)."""

    scope: str
    pursuers: list[str]
    evaders: list[str]
    rate: np.ndarray
    n: np.ndarray

    @property
    def complete(self) -> bool:
        """Every pairing has at least one decided match."""
        return bool((self.n > 0).all())


def payoff_matrices(cell_list: Iterable[Cell]) -> list[Matrix]:
    """One :class:`Matrix` per scope (roster order as first seen)."""
    by_scope: dict[str, list[Cell]] = {}
    for c in cell_list:
        by_scope.setdefault(c.scope, []).append(c)
    out = []
    for scope, cs in by_scope.items():
        ps = list(dict.fromkeys(c.pursuer for c in cs))
        es = list(dict.fromkeys(c.evader for c in cs))
        rate = np.full((len(ps), len(es)), np.nan)
        n = np.zeros((len(ps), len(es)), dtype=int)
        for c in cs:
            i, j = ps.index(c.pursuer), es.index(c.evader)
            rate[i, j], n[i, j] = c.rate, c.n
        out.append(Matrix(scope, ps, es, rate, n))
    return out


@dataclass(frozen=True)
class Game:
    """The zero-sum game of a payoff matrix (the pursuer maximises the held rate).

    Attributes:
        scope: the matrix's scope.
        value: the held rate the equilibrium pursuer mixture guarantees.
        pursuers, evaders: ``{label: weight}`` of the Nash mixtures (all labels).
        pursuer_exploitability, evader_exploitability: per label, what a best-responding
            opponent gains against it compared with the value (0 for the best).
    """

    scope: str
    value: float
    pursuers: dict[str, float]
    evaders: dict[str, float]
    pursuer_exploitability: dict[str, float]
    evader_exploitability: dict[str, float]


def games(matrices: Iterable[Matrix]) -> list[Game]:
    """The game of every complete matrix (incomplete ones are skipped)."""
    from strategies.mixed import solve_zero_sum

    out = []
    for m in matrices:
        if not m.complete:
            continue
        sol = solve_zero_sum(m.rate)
        out.append(
            Game(
                m.scope,
                sol.value,
                dict(zip(m.pursuers, map(float, sol.row), strict=True)),
                dict(zip(m.evaders, map(float, sol.col), strict=True)),
                dict(zip(m.pursuers, map(float, sol.row_exploitability), strict=True)),
                dict(zip(m.evaders, map(float, sol.col_exploitability), strict=True)),
            )
        )
    return out


# --------------------------------------------------------------------------- ratings
@dataclass(frozen=True)
class Rating:
    """A policy's Bradley-Terry strength (logit scale) with a bootstrap interval."""

    role: str
    label: str
    strength: float
    lo: float
    hi: float
    matches: int


PRIOR_SD = 3.0
"""Standard deviation of the Gaussian prior on strengths (logit units)."""


def _fit_bt(h: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """MAP strengths (a per pursuer, b per evader) of P(hold) = sigmoid(a_i - b_j)."""
    from scipy.optimize import minimize
    from scipy.special import expit, log_expit

    m, k = n.shape

    def f(z: np.ndarray) -> tuple[float, np.ndarray]:
        a, b = z[:m], z[m:]
        d = a[:, None] - b[None, :]
        ll = h * log_expit(d) + (n - h) * log_expit(-d)
        g = h - n * expit(d)  # d ll / d d
        obj = -ll.sum() + 0.5 * (z @ z) / PRIOR_SD**2
        grad = np.concatenate([-g.sum(axis=1), g.sum(axis=0)]) + z / PRIOR_SD**2
        return float(obj), grad

    res = minimize(f, np.zeros(m + k), jac=True, method="L-BFGS-B")
    return res.x[:m], res.x[m:]


def _laplace_sd(a: np.ndarray, b: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Posterior standard deviations of the strengths (Laplace: inverse Hessian at the MAP)."""
    from scipy.special import expit

    p = expit(a[:, None] - b[None, :])
    w = n * p * (1.0 - p)
    m, k = n.shape
    h = np.zeros((m + k, m + k))
    h[np.arange(m), np.arange(m)] = w.sum(axis=1)
    h[m + np.arange(k), m + np.arange(k)] = w.sum(axis=0)
    h[:m, m:] = -w
    h[m:, :m] = -w.T
    h += np.eye(m + k) / PRIOR_SD**2
    # only differences a_i - b_j are identified: report the strengths centred on their
    # mean, whose covariance is J H^-1 J^T (J removes the common shift)
    j = np.eye(m + k) - 1.0 / (m + k)
    return np.sqrt(np.diag(j @ np.linalg.inv(h) @ j.T))


def ratings(
    rows: Sequence[Mapping[str, Any]],
    *,
    confidence: float = 0.95,
    method: str = "laplace",
    n_resamples: int = 200,
    seed: int = 0,
) -> list[Rating]:
    """Bradley-Terry strengths of every pursuer and evader, pooled over all scopes.

    A pursuer's strength minus an evader's is the log-odds that the pursuer holds; the
    strengths are centred (their mean over both roles is 0), since only those differences
    are identified.

    Args:
        rows: the run's rows.
        confidence: level of the intervals.
        method: ``"laplace"`` (default): the posterior's normal approximation at the MAP
            (honest for all-or-nothing pairings, where a percentile bootstrap collapses
            to a point: 24 holds out of 24 resample to 24 out of 24 every time);
            ``"bootstrap"``: percentile bootstrap over matches resampled within each
            pairing.
        n_resamples, seed: of the bootstrap.
    """
    from envs.validation import choice

    c = _check_confidence(confidence)
    choice("method", method, ("laplace", "bootstrap"))
    decided = [r for r in rows if r["status"] != "error" and r["winner"] is not None]
    if not decided:
        return []
    ps = list(dict.fromkeys(r["pursuer"] for r in decided))
    es = list(dict.fromkeys(r["evader"] for r in decided))
    outcomes: dict[tuple[int, int], list[int]] = {}
    for r in decided:
        key = (ps.index(r["pursuer"]), es.index(r["evader"]))
        outcomes.setdefault(key, []).append(int(r["winner"] == "pursuer"))
    h = np.zeros((len(ps), len(es)))
    n = np.zeros((len(ps), len(es)))
    for (i, j), o in outcomes.items():
        h[i, j], n[i, j] = sum(o), len(o)
    a, b = _fit_bt(h, n)
    shift = float(np.concatenate([a, b]).mean())
    a, b = a - shift, b - shift
    if method == "laplace":
        z = float(stats.norm.ppf(0.5 + c / 2))
        sd = _laplace_sd(a, b, n)
        qa = np.stack([a - z * sd[: len(ps)], a + z * sd[: len(ps)]])
        qb = np.stack([b - z * sd[len(ps) :], b + z * sd[len(ps) :]])
    else:
        rng = np.random.default_rng(seed)
        boot_a, boot_b = [], []
        for _ in range(n_resamples):
            hb = rng.binomial(n.astype(int), np.divide(h, n, out=np.zeros_like(h), where=n > 0))
            ra, rb = _fit_bt(hb, n)
            centre = float(np.concatenate([ra, rb]).mean())
            boot_a.append(ra - centre)
            boot_b.append(rb - centre)
        qa = np.quantile(np.array(boot_a), [0.5 - c / 2, 0.5 + c / 2], axis=0)
        qb = np.quantile(np.array(boot_b), [0.5 - c / 2, 0.5 + c / 2], axis=0)
    out = [
        Rating("pursuer", p, float(a[i]), float(qa[0, i]), float(qa[1, i]), int(n[i].sum()))
        for i, p in enumerate(ps)
    ]
    out += [
        Rating("evader", e, float(b[j]), float(qb[0, j]), float(qb[1, j]), int(n[:, j].sum()))
        for j, e in enumerate(es)
    ]
    return sorted(out, key=lambda r: (r.role != "pursuer", -r.strength))


# --------------------------------------------------------------------------- paired tests
@dataclass(frozen=True)
class PairedComparison:
    """Two policies of one role on the same starts against the same opponents.

    Attributes:
        role: ``"pursuer"`` or ``"evader"``.
        a, b: the labels compared.
        pairs: shared (scope, opponent, seed) starts.
        a_only, b_only: discordant pairs won by ``a`` only and by ``b`` only.
        p_value: McNemar's exact (binomial) two-sided p-value.
        p_holm: Holm-adjusted over all comparisons of the family.
    """

    role: str
    a: str
    b: str
    pairs: int
    a_only: int
    b_only: int
    p_value: float
    p_holm: float = math.nan


def paired_comparisons(rows: Sequence[Mapping[str, Any]]) -> list[PairedComparison]:
    """Every pair of same-role policies, compared on their shared starts."""
    out: list[PairedComparison] = []
    scoped = [(s, r) for s, r in _scoped(rows) if r["status"] != "error" and r["winner"]]
    for role, other in (("pursuer", "evader"), ("evader", "pursuer")):
        wins: dict[str, dict[tuple, int]] = {}
        for s, r in scoped:
            key = (s, r[other], r["seed"], r["start"])
            wins.setdefault(r[role], {})[key] = int(r["winner"] == role)
        for a, b in itertools.combinations(wins, 2):
            shared = wins[a].keys() & wins[b].keys()
            a_only = sum(wins[a][k] > wins[b][k] for k in shared)
            b_only = sum(wins[b][k] > wins[a][k] for k in shared)
            d = a_only + b_only
            p = 1.0 if d == 0 else float(stats.binomtest(a_only, d, 0.5).pvalue)
            out.append(PairedComparison(role, a, b, len(shared), a_only, b_only, p))
    return _holm(out)


def _holm(tests: list[PairedComparison]) -> list[PairedComparison]:
    from dataclasses import replace

    order = sorted(range(len(tests)), key=lambda i: tests[i].p_value)
    adjusted = [math.nan] * len(tests)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(tests) - rank) * tests[i].p_value))
        adjusted[i] = running
    return [replace(t, p_holm=adjusted[i]) for i, t in enumerate(tests)]


def sprt(
    a_only: int, b_only: int, *, p1: float = 0.65, alpha: float = 0.05, beta: float = 0.05
) -> str:
    """Wald's SPRT on discordant pairs: is ``a`` better than ``b`` (H1: P(a | discordant) =
    p1) or not (H0: 0.5)?

    Returns:
        ``"a better"`` (accept H1), ``"not better"`` (accept H0) or ``"undecided"``.

    Examples:
        >>> sprt(12, 0), sprt(0, 12), sprt(3, 2)
        ('a better', 'not better', 'undecided')
    """
    from envs.validation import unit_interval

    p1 = unit_interval("p1", p1)
    if p1 <= 0.5:
        raise InvalidConfigError(f"p1 = {p1}: expected a probability > 0.5")
    unit_interval("alpha", alpha)
    unit_interval("beta", beta)
    llr = a_only * math.log(p1 / 0.5) + b_only * math.log((1 - p1) / 0.5)
    if llr >= math.log((1 - beta) / alpha):
        return "a better"
    if llr <= math.log(beta / (1 - alpha)):
        return "not better"
    return "undecided"
