"""Opponent pools: the other role's policies, one drawn per episode.

A learner trained against one opponent learns to beat that opponent. Training against a
pool -- the analytic anchors and baselines of the other role plus frozen snapshots of
past learners -- is what makes it hold up against policies it did not see. An
:class:`OpponentPool` is a *mixture*: it has ``select(seed) -> Policy``, the protocol the
shared episode runner (:func:`strategies.runner.run_episode`) and
:class:`training.single_agent.SingleAgentEnv` already draw from, so a pool goes wherever
one opponent goes.

Weights are uniform by default; :meth:`OpponentPool.from_payoffs` takes them from the
Nash equilibrium of a tournament's payoff matrix (the PSRO step: the next learner trains
against the mixture the current population's best play uses).

Examples:
    >>> pool = OpponentPool(["evader/straight", "evader/shooting"], weights=[3, 1])
    >>> pool.probabilities
    (0.75, 0.25)
    >>> pool.select(0).name in ("evader/straight", "evader/shooting")
    True
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from envs.errors import InvalidConfigError
from strategies.policies.model_files import (
    is_model_reference,
    model_path,
    model_policy_name,
    read_provenance,
)

__all__ = ["OpponentPool"]


class OpponentPool:
    """A weighted set of policies of one role; ``select(seed)`` draws one.

    Args:
        members: policy names (``"evader/shooting"``, ``"evader/sb3:PATH"``), models as
            users name them (``"zoo:NAME"``, a ``.zip`` path) or Policy objects, all of
            one role.
        weights: non-negative weights, one per member, not all zero (default: uniform).
            They are normalised into :attr:`probabilities`.
        role: the role every member must play (default: the first member's).

    Raises:
        InvalidConfigError: an empty pool, mixed roles, or bad weights (naming them).
    """

    def __init__(
        self,
        members: Sequence[Any],
        weights: Sequence[float] | None = None,
        *,
        role: str | None = None,
    ) -> None:
        if isinstance(members, (str, bytes)) or not len(members):
            raise InvalidConfigError(
                f"opponent pool: expected a non-empty list of policies, got {members!r}"
            )
        self.members = list(members)
        roles = [_role_of(m, role) for m in self.members]
        self.role = role or roles[0]
        wrong = [str(m) for m, r in zip(self.members, roles, strict=True) if r != self.role]
        if wrong:
            raise InvalidConfigError(
                f"opponent pool: every member must play the {self.role}; {wrong} do not"
            )
        if weights is None:
            weights = [1.0] * len(self.members)
        w = [float(x) for x in weights]
        if len(w) != len(self.members):
            raise InvalidConfigError(
                f"opponent pool: {len(w)} weights for {len(self.members)} members"
            )
        bad = [x for x in w if not math.isfinite(x) or x < 0.0]
        if bad or sum(w) <= 0.0:
            raise InvalidConfigError(
                f"opponent pool: weights = {list(weights)!r}: expected finite values >= 0, "
                "not all zero"
            )
        total = sum(w)
        self.probabilities = tuple(x / total for x in w)
        self._cumulative = np.cumsum(self.probabilities)
        self._built: dict[int, Any] = {}

    @classmethod
    def from_payoffs(
        cls, members: Sequence[Any], payoffs: Any, *, floor: float = 0.0
    ) -> OpponentPool:
        """A pool weighted by the Nash mixture of a zero-sum payoff matrix.

        Args:
            members: the policies of this pool's role, in the order of the matrix's
                columns (the role that *minimises* the row player's payoff).
            payoffs: the row player's (the learner's role) payoff matrix, rows the
                learner's population, columns ``members``.
            floor: a probability mass spread uniformly over all members on top of the
                Nash mixture (PSRO's exploration; 0 keeps the pure equilibrium).
        """
        from strategies.mixed import solve_zero_sum

        a = np.asarray(payoffs, dtype=float)
        if a.ndim != 2 or a.shape[1] != len(members):
            raise InvalidConfigError(
                f"opponent pool: a payoff matrix with {len(members)} columns expected, "
                f"got shape {a.shape}"
            )
        if not 0.0 <= floor <= 1.0:
            raise InvalidConfigError(
                f"opponent pool: floor = {floor!r}: expected a value in [0, 1]"
            )
        col = np.clip(solve_zero_sum(a).col, 0.0, None)
        weights = (1.0 - floor) * col / col.sum() + floor / len(members)
        return cls(members, weights=list(weights))

    def index(self, seed: int) -> int:
        """The member drawn for ``seed`` (a pure function of the seed)."""
        u = np.random.default_rng(int(seed)).random()
        return int(min(np.searchsorted(self._cumulative, u, side="right"), len(self.members) - 1))

    def select(self, seed: int) -> Any:
        """The member drawn for ``seed``, as a Policy (built once, then reused)."""
        i = self.index(seed)
        if i not in self._built:
            member = self.members[i]
            if isinstance(member, str):
                from strategies.policies import make_policy
                from training.single_agent import sb3_params

                member = model_policy_name(member, self.role, f"opponent pool: {member!r}")
                member = make_policy(member, **sb3_params(member))
            self._built[i] = member
        return self._built[i]

    @property
    def name(self) -> str:
        names = [m if isinstance(m, str) else getattr(m, "name", repr(m)) for m in self.members]
        return (
            "pool("
            + ", ".join(f"{n}:{p:.2f}" for n, p in zip(names, self.probabilities, strict=True))
            + ")"
        )

    def __repr__(self) -> str:
        return f"OpponentPool({self.name})"


def _role_of(member: Any, role: str | None = None) -> str:
    if isinstance(member, str) and is_model_reference(member):  # zoo:NAME, a .zip
        what = f"opponent pool: {member!r}"
        trained = (read_provenance(model_path(member, what)) or {}).get("role")
        if trained is None and role is None:
            raise InvalidConfigError(
                f"{what}: cannot tell which role this model plays (no provenance.json "
                "beside it); pass role= or name it 'ROLE/sb3:PATH'"
            )
        return trained or role
    if isinstance(member, str):
        role = member.partition("/")[0]
        if role not in ("pursuer", "evader"):
            raise InvalidConfigError(
                f"opponent pool: {member!r} is not a policy name ('pursuer/KIND' or 'evader/KIND')"
            )
        return role
    roles = tuple(getattr(member, "roles", ()))
    if len(roles) == 1:
        return roles[0]
    role = getattr(member, "role", None)
    if role in ("pursuer", "evader"):
        return role
    raise InvalidConfigError(f"opponent pool: cannot tell which role {member!r} plays")
