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
