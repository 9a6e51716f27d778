"""The seeded episodes the replays show and the report tallies (the shared runner)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

__all__ = ["MATCHES", "TALLY_SEEDS", "Match", "evader_wins", "outcomes", "play"]


# --------------------------------------------------------------------------- replays
@dataclass(frozen=True)
class Match:
    """One seeded episode between two registered policies on a built-in world.

    Attributes:
        map: built-in map name (its recommended L_min, L_max and speeds apply).
        pursuer, evader: registered policy names.
        seed: the episode seed.
        overrides: env overrides as ``(key, value)`` pairs (e.g. ``(("v_evader", 1.5),)``).
        evader_params: the evader policy's parameters as ``(key, value)`` pairs.
    """

    map: str
    pursuer: str
    evader: str
    seed: int = 0
    overrides: tuple[tuple[str, float], ...] = ()
    evader_params: tuple[tuple[str, object], ...] = ()

    @property
    def command(self) -> str:
        """The ``surveil play`` command that replays it."""
        import json

        cmd = f"surveil play --map {self.map} --pursuer {self.pursuer} --evader {self.evader}"
        cmd += f" --seed {self.seed}"
        if self.evader_params:
            cmd += f" --evader-params '{json.dumps(dict(self.evader_params))}'"
        if self.overrides:
            cmd += f" --config '{json.dumps(dict(self.overrides))}'"
        return cmd


MATCHES = {
    "corridor": Match("corridor", "pursuer/decomposition", "evader/shooting", 0),
    "two_rooms": Match("two_rooms", "pursuer/decomposition", "evader/shooting", 1),
    "corner_slow": Match("corner", "pursuer/decomposition", "evader/wall_hugging", 3),
    "corner_fast": Match(
        "corner", "pursuer/decomposition", "evader/wall_hugging", 1, (("v_evader", 1.0),)
    ),
    "charge": Match(
        "open_room",
        "pursuer/decomposition",
        "evader/toward_away",
        0,
        (("v_evader", 1.5),),
        (("mode", "toward"),),
    ),
    "run_away": Match(
        "open_room",
        "pursuer/decomposition",
        "evader/toward_away",
        0,
        (("v_evader", 1.5),),
        (("mode", "away"), ("pure", True)),  # footnote 4's escape as worded: straight away
    ),
    "corner_charge": Match(
        "corner", "pursuer/decomposition", "evader/toward_away", 0, (), (("mode", "toward"),)
    ),
}
"""The episodes the replays show and the report quotes (``corner_charge``: Fig. 9(a)'s
charge at rho = 0.5 in the world of Fig. 9(b), quoted as a tally only)."""


@functools.cache
def play(match: Match):
    """Play ``match`` with the shared episode runner (deterministic: one seed drives env,
    start and both policies). A rho > 1 match is deliberate here, so its warning is not
    repeated."""
    import warnings

    from envs.errors import RhoAboveOneWarning
    from strategies.policies import make_policy
    from strategies.runner import run_episode

    evader = make_policy(match.evader, **dict(match.evader_params))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RhoAboveOneWarning)
        return run_episode(
            match.map, match.pursuer, evader, seed=match.seed, overrides=dict(match.overrides)
        )


TALLY_SEEDS = 10
"""Seeds each replay's match is also played with, so a replay is not a lucky pick."""


@functools.cache
def outcomes(key: str, seeds: int = TALLY_SEEDS) -> tuple[tuple[str, str | None, str | None], ...]:
    """``(winner, cause, feature)`` of ``MATCHES[key]`` played with seeds 0..``seeds - 1``."""
    m = MATCHES[key]
    out = []
    for s in range(seeds):
        r = play(Match(m.map, m.pursuer, m.evader, s, m.overrides, m.evader_params))
        out.append((r.winner, r.cause, r.feature))
    return tuple(out)


def evader_wins(key: str, seeds: int = TALLY_SEEDS) -> int:
    """In how many of seeds 0..``seeds - 1`` the evader of ``MATCHES[key]`` wins."""
    return sum(w == "evader" for w, _, _ in outcomes(key, seeds))
