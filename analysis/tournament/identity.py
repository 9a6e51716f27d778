"""Match identity: a content hash of everything that decides a match's outcome.

A match is one episode: a map, an env configuration, a pursuer, an evader, a start kind
and a seed, played under a time limit. Its identity hashes the map's *geometry* digest
(not its path or name), the resolved env parameters, each policy's name, parameters,
observation and, for a learned model, the SHA-256 of its file (not its path), the start
kind, the seed, the time limit (a slow policy forfeits under a short one, not under a
long one) and the spec's ``salt``. The same identity means the same record, bit for bit,
so a store reuses it; anything changed (an edited map file, a retrained model at the same
path, a parameter, the time limit) is a new match. Policy *code* is not hashed: set the
spec's ``salt`` (e.g. to a git SHA) to invalidate results after changing a policy's
implementation.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from analysis.tournament.spec import Spec

__all__ = ["IDENTITY_VERSION", "Match", "match_identity", "plan"]

IDENTITY_VERSION = 2
"""Bumped when the meaning of an identity field changes (all old matches become new).

2: the time limit is each role's decision clock (it was the whole match's wall-clock
time, the env's set-up included, blamed on the side that had decided slower), and it is
part of the identity (a forfeit on time under one limit was reused under another)."""

ENV_ID = "surveillance_v1"


@dataclass(frozen=True)
class Match:
    """One planned episode, by labels (the worker context resolves them).

    Attributes:
        match_id: the identity hash (hex).
        map: map label.
        variant: grid variant label (``""`` without a grid).
        pursuer, evader: roster labels.
        start: ``"safe"`` or ``"valid"``.
        seed: the episode seed.
    """

    match_id: str
    map: str
    variant: str
    pursuer: str
    evader: str
    start: str
    seed: int


def match_identity(
    *,
    map_digest: str,
    env: dict[str, Any],
    pursuer: dict[str, Any],
    evader: dict[str, Any],
    start: str,
    seed: int,
    time_limit: float,
    salt: str = "",
) -> tuple[str, dict[str, Any]]:
    """The identity hash of a match and the canonical dict it hashes."""
    doc = {
        "version": IDENTITY_VERSION,
        "env_id": ENV_ID,
        "map": map_digest,
        "env": env,
        "pursuer": pursuer,
        "evader": evader,
        "start": start,
        "seed": int(seed),
        "time_limit": float(time_limit),
        "salt": salt,
    }
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest(), doc


def plan(spec: Spec) -> Iterator[tuple[Match, dict[str, Any]]]:
    """Every match of ``spec`` with its identity document, seed-major.

    Seed-major order (all pairings play seed 0, then seed 1...) keeps an interrupted run
    balanced: every cell has about the same number of episodes.
    """
    configs = {(m.label, v.label): spec.env_config(m, v) for m in spec.maps for v in spec.variants}
    for seed in spec.seeds:
        for v in spec.variants:
            for m in spec.maps:
                env = configs[(m.label, v.label)]
                for start in spec.starts:
                    for p in spec.pursuers:
                        for e in spec.evaders:
                            mid, doc = match_identity(
                                map_digest=m.digest,
                                env=env,
                                pursuer=p.identity(),
                                evader=e.identity(),
                                start=start,
                                seed=seed,
                                time_limit=spec.time_limit,
                                salt=spec.salt,
                            )
                            yield Match(mid, m.label, v.label, p.label, e.label, start, seed), doc
