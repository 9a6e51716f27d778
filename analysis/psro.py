"""A PSRO-style loop: tournament, Nash mixture, a new learner against it, repeat.

Policy-Space Response Oracles (Lanctot et al., 2017) grow a population per role. Each
round here:

1. plays a tournament (:mod:`analysis.tournament`: common random starts, a resumable SQLite
   store) between everyone so far: the analytic anchors and baselines given, plus every
   learner of the earlier rounds (frozen snapshots);
2. solves the zero-sum game of the pooled payoff matrix (held rates) for its Nash mixtures;
3. trains a new learner of this round's role (roles alternate: self-play by rounds) with
   SB3 against an :class:`~training.pool.OpponentPool` of the other role weighted by that
   role's Nash mixture, plus a uniform ``floor`` so nobody is forgotten;
4. enters the snapshot in the next round's tournament.

A last tournament rates every snapshot (Bradley-Terry ratings, the game's value and each
policy's exploitability in the payoff matrix). Everything lives in ``output_dir``: the store
``psro.sqlite``, one training directory per round, and ``psro.json`` with the mixtures, the
values and the ratings; a rerun resumes (finished tournaments and trainings are reused).

Example::

    from analysis.psro import PsroConfig, psro
    result = psro(PsroConfig(maps=("corridor",), pursuers=("pursuer/greedy",),
                             evaders=("evader/straight", "evader/shooting"), rounds=2,
                             timesteps=20_000, output_dir="out/psro"))
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from envs import validation
from envs.errors import InvalidConfigError

__all__ = ["PsroConfig", "PsroResult", "psro"]


@dataclass(frozen=True)
class PsroConfig:
    """One PSRO run."""

    maps: tuple[str, ...]
    """Maps of the tournaments and of the training (one drawn per episode)."""
    pursuers: tuple[str, ...]
    """The pursuers' anchors and baselines (registered names)."""
    evaders: tuple[str, ...]
    """The evaders' anchors and baselines."""
    rounds: int = 2
    """Learners trained; round ``k`` trains ``first_role`` when ``k`` is even."""
    first_role: str = "pursuer"
    seeds: int = 4
    """Tournament starts per map."""
    start: str = "valid"
    timesteps: int = 20_000
    """SB3 env steps per learner."""
    algo: str = "ppo"
    observation: dict[str, Any] = field(
        default_factory=lambda: {"observation": "lidar_track", "n_rays": 16}
    )
    """What every learner sees (all learners share it: they play each other)."""
    max_cycles: int = 200
    floor: float = 0.1
    """Probability mass spread uniformly over the pool on top of the Nash mixture."""
    seed: int = 0
    output_dir: str = "out/psro"
    backend: str = "serial"
    """Tournament backend: ``"serial"``, ``"process"`` or ``"ray"``."""

    def __post_init__(self) -> None:
        where = "PsroConfig"
        put = lambda name, value: object.__setattr__(self, name, value)
        for name, role in (("pursuers", "pursuer"), ("evaders", "evader")):
            value = getattr(self, name)
            value = (value,) if isinstance(value, str) else tuple(value)
            if not value or not all(isinstance(v, str) and v.startswith(role + "/") for v in value):
                raise InvalidConfigError(
                    f"{where}: {name} = {value!r}: expected one or more '{role}/KIND' names"
                )
            put(name, value)
        put("maps", (self.maps,) if isinstance(self.maps, str) else tuple(self.maps))
        if not self.maps:
            raise InvalidConfigError(f"{where}: maps = (): expected at least one map")
        validation.choice("first_role", self.first_role, ("pursuer", "evader"), where=where)
        for name, lo in (("rounds", 1), ("seeds", 1), ("timesteps", 1), ("max_cycles", 1),
                         ("seed", 0)):  # fmt: skip
            validation.integer(name, getattr(self, name), minimum=lo, where=where)
        validation.unit_interval("floor", self.floor, where=where, open=False)

    def role_of(self, k: int) -> str:
        """The role trained in round ``k``."""
        other = "evader" if self.first_role == "pursuer" else "pursuer"
        return self.first_role if k % 2 == 0 else other


@dataclass
class PsroResult:
    """What :func:`psro` produced.

    Attributes:
        rounds: per round, its role, the pool (names and weights), the game value of the
            tournament before it, and the learner's label and model path.
        value: the value (pursuer's held rate) of the final tournament's game.
        ratings: label -> Bradley-Terry strength in the final tournament.
        exploitability: label -> exploitability in the final payoff matrix.
    """

    rounds: list[dict[str, Any]]
    value: float
    ratings: dict[str, float]
    exploitability: dict[str, float]


def _roster(names: tuple[str, ...], learned: list[tuple[str, str]]) -> list[Any]:
    return list(names) + [{"model": path, "label": label} for label, path in learned]


def _tournament(cfg: PsroConfig, k: int, learned: dict[str, list[tuple[str, str]]], store: Path):
    from analysis.tournament import run_tournament, spec_from_dict
    from analysis.tournament.report import analyse
    from analysis.tournament.statistics import payoff_matrices

    spec = spec_from_dict(
        {
            "name": f"psro_round_{k}",
            "maps": list(cfg.maps),
            "seeds": cfg.seeds,
            "start": cfg.start,
            "salt": f"psro seed {cfg.seed}",
            "pursuers": _roster(cfg.pursuers, learned["pursuer"]),
            "evaders": _roster(cfg.evaders, learned["evader"]),
            "env": {"max_cycles": cfg.max_cycles},
        },
        source=f"psro round {k}",
        base_dir=cfg.output_dir,
    )
    summary = run_tournament(spec, store, backend=cfg.backend, progress=False)
    a = analyse(store, summary.run_id)
    overall = [m for m in payoff_matrices(a.cells) if m.scope == "overall"] or payoff_matrices(
        a.cells
    )
    matrix = overall[0]
    if not matrix.complete:
        raise InvalidConfigError(
            f"psro round {k}: the payoff matrix has pairings without a decided match; "
            "raise seeds or check the errors in the store"
        )
    return a, matrix


def psro(cfg: PsroConfig, *, verbose: bool = False) -> PsroResult:
    """Run the loop (see the module docstring); resumes from ``cfg.output_dir``.

    Raises:
        InvalidConfigError: a bad config, or a tournament with an undecided pairing.
    """
    from strategies.mixed import solve_zero_sum
    from training.config import TrainConfig
    from training.pool import OpponentPool
    from training.train import train

    out = Path(cfg.output_dir)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "psro.sqlite"
    learned: dict[str, list[tuple[str, str]]] = {"pursuer": [], "evader": []}
    rounds: list[dict[str, Any]] = []
    for k in range(cfg.rounds):
        role = cfg.role_of(k)
        other = "evader" if role == "pursuer" else "pursuer"
        _, matrix = _tournament(cfg, k, learned, store)
        rate = np.asarray(matrix.rate, dtype=float)
        # the learner's role is the row player of its own payoff matrix
        payoff = rate if role == "pursuer" else 1.0 - rate.T
        game = solve_zero_sum(payoff)
        labels = matrix.evaders if role == "pursuer" else matrix.pursuers
        names = {lab: lab for lab in (cfg.pursuers + cfg.evaders)}
        names.update({lab: f"{r}/sb3:{path}" for r in learned for lab, path in learned[r]})
        members = [names[lab] for lab in labels]
        pool = OpponentPool.from_payoffs(members, payoff, floor=cfg.floor)
        label = f"psro_{role}_{k}"
        run_dir = out / f"round_{k}_{role}"
        train_cfg = TrainConfig(
            role=role,
            opponent=tuple(members),
            opponent_weights=pool.probabilities,
            map=cfg.maps if len(cfg.maps) > 1 else cfg.maps[0],
            env={**cfg.observation, "max_cycles": cfg.max_cycles},
            start=cfg.start,
            algo=cfg.algo,
            total_timesteps=cfg.timesteps,
            seed=cfg.seed + k,
            eval_episodes=0,
            checkpoint_freq=max(cfg.timesteps // 2, 1),
            output_dir=str(run_dir),
        )
        result = train(train_cfg)
        learned[role].append((label, str(result.model_path)))
        record = {
            "round": k,
            "role": role,
            "value_before": float(game.value if role == "pursuer" else 1.0 - game.value),
            "pool": dict(zip(labels, pool.probabilities, strict=True)),
            "learner": label,
            "model": str(result.model_path),
            "opponents": other,
        }
        rounds.append(record)
        if verbose:
            print(f"psro round {k}: {role} vs pool {record['pool']} -> {label}", flush=True)
    a, matrix = _tournament(cfg, cfg.rounds, learned, store)
    game = solve_zero_sum(np.asarray(matrix.rate, dtype=float))
    exploit = dict(zip(matrix.pursuers, map(float, game.row_exploitability), strict=True))
    exploit.update(zip(matrix.evaders, map(float, game.col_exploitability), strict=True))
    result = PsroResult(
        rounds=rounds,
        value=float(game.value),
        ratings={r.label: float(r.strength) for r in a.ratings},
        exploitability=exploit,
    )
    record = {"config": dataclasses.asdict(cfg), **dataclasses.asdict(result)}
    (out / "psro.json").write_text(json.dumps(record, indent=2, default=list) + "\n")
    return result
