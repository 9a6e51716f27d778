"""The numbers of the replays: winners, causes, times and the tallies over ten seeds."""

from __future__ import annotations

from analysis.figures import cases
from analysis.figures.numbers import number


# ------------------------------------------------------------------ replays, footnote 4
def _play(key: str):
    return cases.play(cases.MATCHES[key])


for _k in ("corridor", "two_rooms", "corner_slow", "corner_fast", "charge", "run_away"):
    number(f"replay.{_k}.winner", f"winner of the {_k} replay")(lambda k=_k: _play(k).winner)
number("replay.two_rooms.time", "time of the two-rooms escape (s)", "{:.1f}")(
    lambda: _play("two_rooms").escape_time
)
number("replay.two_rooms.cause", "why surveillance broke")(lambda: _play("two_rooms").cause)
number("replay.two_rooms.feature", "the wall feature the rod hit")(
    lambda: _play("two_rooms").feature
)
number("replay.corner_fast.feature", "the wall feature the rod hit")(
    lambda: _play("corner_fast").feature
)
number("replay.corner_fast.time", "time of the fast corner escape (s)", "{:.1f}")(
    lambda: _play("corner_fast").escape_time
)
number("replay.corner_fast.cause", "why it broke")(lambda: _play("corner_fast").cause)
number("replay.charge.time", "time of the charge's escape (s)", "{:.2f}")(
    lambda: _play("charge").escape_time
)
number("replay.charge.cause", "why it broke")(lambda: _play("charge").cause)
for _k in cases.MATCHES:
    number(f"tally.{_k}", f"evader wins in seeds 0-9 of the {_k} match")(
        lambda k=_k: cases.evader_wins(k)
    )


@number("tally.corner_fast.on_corner", "of them, the rod occluded by the corner (5, 5)")
def _on_corner() -> int:
    return sum(
        cause == "occluded" and feature is not None and feature.endswith("(5, 5)")
        for _, cause, feature in cases.outcomes("corner_fast")
    )
