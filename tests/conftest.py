"""Test-wide set-up: headless rendering before anything imports pygame (as Gymnasium does)."""

from __future__ import annotations

import os

# SDL reads these when pygame initialises a subsystem; set them before any test module
# (or the package under test) imports pygame, so "human" rendering opens no real window
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
