"""Test-wide set-up: headless rendering before anything imports pygame (as Gymnasium does)."""

from __future__ import annotations

import os

# SDL reads these when pygame initialises a subsystem; set them before any test module
# (or the package under test) imports pygame, so "human" rendering opens no real window
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

# decompositions and safety tables are cached on disk; tests keep theirs inside the
# checkout (git-ignored) instead of the user's ~/.cache/surveil
os.environ.setdefault(
    "SURVEIL_CACHE_DIR",
    os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))), ".pytest_cache", "surveil"
    ),
)

# SB3 creates a logger folder for every model it trains, tempdir/SB3-<date> unless
# SB3_LOGDIR names one (stable_baselines3.common.logger.configure): keep the suite's
# in one reused folder of the checkout instead of a dozen new ones in /tmp per run
os.environ.setdefault(
    "SB3_LOGDIR",
    os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))), ".pytest_cache", "sb3-logs"
    ),
)

# property tests draw fresh examples on every run; CI (SURVEIL_CI=1, set by .ci/run) plays
# a fixed derandomised sequence so a landing cannot hinge on a lucky draw, while local runs
# keep exploring
from hypothesis import settings as _hypothesis_settings

_hypothesis_settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("SURVEIL_CI"):
    _hypothesis_settings.load_profile("ci")
