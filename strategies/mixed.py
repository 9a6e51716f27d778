"""Zero-sum matrix games and mixed policies.

A tournament's payoff matrix (pursuers x evaders, entry = the pursuer's payoff, e.g. the
rate at which it holds surveillance) defines a two-player zero-sum game. Its value and a
Nash equilibrium come from one linear program per player (von Neumann's minimax
theorem): the pursuer (rows, maximiser) solves

    max v  subject to  sum_i x_i A[i, j] >= v  for every column j,  sum_i x_i = 1,  x >= 0,

and the evader (columns, minimiser) the dual. :func:`solve_zero_sum` solves both with
HiGHS (``scipy.optimize.linprog``). The *exploitability* of a strategy is how much a best
response gains against it compared with the value; it is 0 exactly at equilibrium.

:class:`MixedPolicy` plays a mixture: one component policy per episode, drawn with a
seeded generator, so that training can sample opponents from a Nash mixture and a
tournament can play the equilibrium itself.

Examples:
    >>> sol = solve_zero_sum([[1.0, -1.0], [-1.0, 1.0]])  # matching pennies
    >>> sol.value, sol.row.round(3).tolist(), sol.col.round(3).tolist()
    (0.0, [0.5, 0.5], [0.5, 0.5])
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from envs.errors import InfeasibleError, InvalidConfigError
from envs.validation import finite_array
from strategies.policies.base import ActPredictor

__all__ = [
    "GameSolution",
    "MixedPolicy",
    "column_exploitability",
    "row_exploitability",
    "solve_zero_sum",
]

_TOL = 1e-9
"""Weights below this are rounded to 0 (LP solutions carry residues of order 1e-12)."""


@dataclass(frozen=True)
class GameSolution:
    """A Nash equilibrium of a zero-sum matrix game.

    Attributes:
        row: the row player's (maximiser's) equilibrium mixture, shape (m,).
        col: the column player's (minimiser's) equilibrium mixture, shape (n,).
        value: the game's value ``row @ A @ col`` (what the row player is guaranteed).
        payoff: the matrix ``A`` (row player's payoff).
    """

    row: np.ndarray
    col: np.ndarray
    value: float
    payoff: np.ndarray

    @property
    def row_exploitability(self) -> np.ndarray:
        """Per pure row strategy i: ``value - min_j A[i, j]`` (>= 0)."""
        return self.value - self.payoff.min(axis=1)

    @property
    def col_exploitability(self) -> np.ndarray:
        """Per pure column strategy j: ``max_i A[i, j] - value`` (>= 0)."""
        return self.payoff.max(axis=0) - self.value

    @property
    def gap(self) -> float:
        """Exploitability of the equilibrium pair: ``max_i (A y)_i - min_j (x A)_j`` (~0)."""
        return float((self.payoff @ self.col).max() - (self.row @ self.payoff).min())


def _matrix(payoff: Any) -> np.ndarray:
    a = finite_array("payoff", payoff, shape=(None, None))
    if a.size == 0:
        raise InvalidConfigError(f"payoff: expected a non-empty matrix, got shape {a.shape}")
    return a


def _maximin(a: np.ndarray) -> tuple[np.ndarray, float]:
    """The row player's maximin mixture and value of ``a`` by LP."""
    from scipy.optimize import linprog

    m, n = a.shape
    # shift to strictly positive payoffs: same equilibria, better-conditioned LP
    shift = 1.0 - float(a.min())
    b = a + shift
    c = np.zeros(m + 1)
    c[-1] = -1.0  # maximise v
    a_ub = np.hstack([-b.T, np.ones((n, 1))])  # v - sum_i x_i b[i, j] <= 0
    a_eq = np.hstack([np.ones((1, m)), np.zeros((1, 1))])
    bounds = [(0.0, None)] * m + [(None, None)]
    res = linprog(
        c, A_ub=a_ub, b_ub=np.zeros(n), A_eq=a_eq, b_eq=[1.0], bounds=bounds, method="highs"
    )
    if res.status != 0:  # pragma: no cover - a finite matrix game always has a solution
        raise InfeasibleError(f"the matrix game LP failed: {res.message}")
    x = np.clip(res.x[:m], 0.0, None)
    x[x < _TOL] = 0.0
    x /= x.sum()
    return x, float(res.x[-1]) - shift


def solve_zero_sum(payoff: Any) -> GameSolution:
    """A Nash equilibrium and the value of the zero-sum game with row payoff ``payoff``.

    Args:
        payoff: an (m, n) matrix of finite numbers; entry (i, j) is what the row player
            (maximiser) gets and the column player (minimiser) loses when they play i, j.

    Returns:
        The :class:`GameSolution` (mixtures rounded below 1e-9 to 0 and renormalised).

    Raises:
        InvalidConfigError: the payoff is not a non-empty finite 2-D matrix.

    Examples:
        >>> sol = solve_zero_sum([[3.0, 0.0], [-1.0, 1.0]])  # no saddle point
        >>> round(sol.value, 6), sol.row.round(6).tolist(), sol.col.round(6).tolist()
        (0.6, [0.4, 0.6], [0.2, 0.8])
    """
    a = _matrix(payoff)
    x, v_row = _maximin(a)
    y, v_col = _maximin(-a.T)  # the column player maximises -A^T
    value = 0.5 * (v_row - v_col)
    return GameSolution(row=x, col=y, value=float(value), payoff=a)


def row_exploitability(payoff: Any, row: Any) -> float:
    """How much less than the game's value a row mixture guarantees (>= 0).

    ``value - min_j (row @ A)_j``: what a best-responding column player takes from it.
    """
    a = _matrix(payoff)
    x = _mixture("row", row, a.shape[0])
    return float(solve_zero_sum(a).value - (x @ a).min())


def column_exploitability(payoff: Any, col: Any) -> float:
    """How much more than the game's value a column mixture concedes (>= 0)."""
    a = _matrix(payoff)
    y = _mixture("col", col, a.shape[1])
    return float((a @ y).max() - solve_zero_sum(a).value)


def _mixture(name: str, weights: Any, n: int) -> np.ndarray:
    w = finite_array(name, weights, shape=(n,))
    if (w < 0).any() or w.sum() <= 0:
        raise InvalidConfigError(
            f"{name} = {w.tolist()}: expected non-negative weights with a positive sum"
        )
    return w / w.sum()


# --------------------------------------------------------------------------- policies
class MixedPolicy(ActPredictor):
    """A mixture of policies of one role: one component plays each episode.

    The component is drawn at :meth:`reset` (or by :meth:`select`, which the shared
    runner :func:`strategies.runner.run_episode` calls) from the mixture with a
    generator seeded by the episode's seed, so the same seed plays the same component
    with the same component seed; ``seed=None`` draws from the mixture's own generator
    (seeded by ``seed`` at construction).

    Args:
        policies: the components: registered names (``"evader/shooting"``) or policies.
        weights: non-negative weights (normalised; ``None``: uniform). Components with
            weight 0 are dropped.
        name: for reports (default ``"ROLE/mixture"``).
        seed: seeds the mixture's own generator (used when ``reset`` gets no seed).

    Raises:
        InvalidConfigError: no components, ``policies`` a single string rather than a
            list, a component that is neither a name nor a policy, weights of the wrong
            length or negative, components of different roles, or a seed that is no
            integer >= 0.

    Examples:
        >>> mix = MixedPolicy(["evader/straight", "evader/random"], [0.25, 0.75])
        >>> mix.role_name, mix.weights.tolist()
        ('evader', [0.25, 0.75])
    """

    def __init__(
        self,
        policies: Sequence[Any],
        weights: Sequence[float] | np.ndarray | None = None,
        *,
        name: str | None = None,
        seed: int | None = None,
    ) -> None:
        from envs import validation
        from strategies.policies import Policy, make_policy

        if isinstance(policies, (str, bytes)) or not hasattr(policies, "__iter__"):
            # a lone name was iterated as its letters ("unknown policy 'e'")
            raise InvalidConfigError(
                f"MixedPolicy: policies = {policies!r}: expected a list of policy names or "
                f"policies, e.g. ['evader/straight', 'evader/random'], got "
                f"{type(policies).__name__}"
            )
        pols = [make_policy(p) if isinstance(p, str) else p for p in policies]
        odd = [p for p in pols if not (isinstance(p, Policy) or hasattr(p, "select"))]
        if odd:  # was taken, and failed as the first episode reset it
            raise InvalidConfigError(
                f"MixedPolicy: components must be policy names or policies (reset, act, "
                f"predict), got {odd[0]!r} ({type(odd[0]).__name__})"
            )
        if seed is not None:  # numpy's own refusal named no argument
            seed = validation.integer("seed", seed, minimum=0, where="MixedPolicy")
        if not pols:
            raise InvalidConfigError("MixedPolicy: expected at least one component policy")
        w = np.ones(len(pols)) if weights is None else _mixture("weights", weights, len(pols))
        keep = w > 0
        self.components = [p for p, k in zip(pols, keep, strict=True) if k]
        self.weights = w[keep] / w[keep].sum()
        roles = {_role_of(p) for p in self.components} - {None}
        if len(roles) > 1:
            raise InvalidConfigError(
                f"MixedPolicy: components play different roles {sorted(roles)}: "
                f"{[getattr(p, 'name', p) for p in self.components]}"
            )
        self.role_name = roles.pop() if roles else None
        self.roles = (self.role_name,) if self.role_name else ("pursuer", "evader")
        self.name = name or f"{self.role_name or 'any'}/mixture"
        self.role: str | None = None
        self.current: Any = None
        self.rng = np.random.default_rng(seed)

    @classmethod
    def from_weights(cls, weights: Mapping[str, float], **kwargs: Any) -> MixedPolicy:
        """A mixture from ``{policy name: weight}`` (e.g. a tournament's Nash mixture)."""
        names = list(weights)
        return cls(names, [weights[n] for n in names], **kwargs)

    # --------------------------------------------------------------- selection
    def select(self, seed: int | None = None) -> Any:
        """Draw the component of one episode (``seed=None``: from the own generator)."""
        rng = self.rng if seed is None else np.random.default_rng(seed)
        k = int(rng.choice(len(self.components), p=self.weights))
        self.current = self.components[k]
        return self.current

    # --------------------------------------------------------------- Policy protocol
    @property
    def uses_state(self) -> bool:
        """True when every component reads the ``"state"`` observation."""
        return all(getattr(p, "uses_state", True) for p in self.components)

    @property
    def observation_options(self) -> dict[str, Any] | None:
        """The current component's observation options (after :meth:`reset`), else the
        options all components share, else ``None``."""
        from strategies.runner import observation_options

        if self.current is not None:
            return observation_options(self.current)
        opts = [observation_options(p) for p in self.components]
        return opts[0] if all(o == opts[0] for o in opts) else None

    def reset(self, *, role: str, map: Any, config: Any, seed: int | None = None) -> None:
        """Draw this episode's component and reset it (its seed derives from ``seed``).

        Raises:
            InvalidConfigError: ``seed`` is not None or an integer >= 0 (nothing drawn).
        """
        if seed is not None:
            from envs import validation

            seed = validation.integer("seed", seed, minimum=0, where=f"policy {self.name!r}: reset")
        rng = self.rng if seed is None else np.random.default_rng(seed)
        chosen = self.select(int(rng.integers(2**63)))
        self.role = role
        chosen.reset(role=role, map=map, config=config, seed=int(rng.integers(2**63)))

    def act(self, observation: np.ndarray) -> np.ndarray:
        """The current component's action."""
        if self.current is None or self.role is None:
            raise InvalidConfigError(f"policy {self.name!r}: call reset() before act()")
        return self.current.act(observation)

    def __repr__(self) -> str:
        parts = ", ".join(
            f"{getattr(p, 'name', p)}: {w:.3g}"
            for p, w in zip(self.components, self.weights, strict=True)
        )
        return f"MixedPolicy({self.name!r}, {{{parts}}})"


def _role_of(policy: Any) -> str | None:
    roles = tuple(getattr(policy, "roles", ()))
    if len(roles) == 1:
        return roles[0]
    name = getattr(policy, "name", "")
    head = name.partition("/")[0] if isinstance(name, str) else ""
    return head if head in ("pursuer", "evader") else None
