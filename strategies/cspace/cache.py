"""On-disk cache of decompositions, keyed by the map's digest and the parameters.

Policies and tournaments ask for the same decomposition many times, across processes.
Files live in ``$SURVEIL_CACHE_DIR`` (default ``~/.cache/surveil``) under ``cspace/``:

* the file name is a SHA-256 of :data:`FORMAT_VERSION`, the numerical constants the
  result depends on, the map's wall digest (:attr:`envs.maps.Map.digest`), L and the
  chord tolerance, so a changed map or parameter can never hit a stale file;
* the pickle also stores the key material, checked again on load (a renamed or
  corrupted file is ignored and recomputed);
* writes are atomic: a temporary file in the same directory, then ``os.replace``.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from pathlib import Path

from envs.maps.map import Map
from strategies.cspace import tolerances as _tol
from strategies.cspace._build import build_decomposition
from strategies.cspace.decomposition import Decomposition

__all__ = ["FORMAT_VERSION", "cache_path", "cached_decomposition", "resolve_cache_dir"]

FORMAT_VERSION = 2
"""Bump when the decomposition's content or pickle layout changes."""


def resolve_cache_dir(directory: str | os.PathLike[str] | None = None) -> Path:
    """The cache directory: the argument, ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``."""
    if directory is not None:
        return Path(directory)
    env = os.environ.get("SURVEIL_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "surveil"


def _key(world: Map, L: float, chord_tol: float | None) -> dict:
    return {
        "format": FORMAT_VERSION,
        "constants": (
            _tol.CHORD_TOL_REL,
            _tol.MERGE_REL,
            _tol.TOUCH_REL,
            _tol.THIN_REL,
            _tol.PROBE_REL,
            tuple(sorted(_tol.KERNEL_FLOOR.items())),
        ),
        "map": world.digest,
        "L": float(L).hex(),
        "chord_tol": None if chord_tol is None else float(chord_tol).hex(),
    }


def cache_path(
    world: Map, L: float, chord_tol: float | None = None, directory: str | os.PathLike | None = None
) -> Path:
    """The file that holds (or would hold) the decomposition of ``world`` at ``L``."""
    key = _key(world, L, chord_tol)
    h = hashlib.sha256(repr(sorted(key.items())).encode()).hexdigest()[:40]
    return resolve_cache_dir(directory) / "cspace" / f"decomposition-v{FORMAT_VERSION}-{h}.pkl"


def _read(path: Path, key: dict) -> Decomposition | None:
    try:
        with path.open("rb") as fh:
            payload = pickle.load(fh)
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, ValueError):
        return None
    if not isinstance(payload, dict) or payload.get("key") != key:
        return None
    dec = payload.get("decomposition")
    if not isinstance(dec, Decomposition) or dec.map.digest != key["map"]:
        return None
    return dec


def _write(path: Path, key: dict, dec: Decomposition) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            pickle.dump({"key": key, "decomposition": dec}, fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def cached_decomposition(
    world: Map,
    L: float,
    *,
    chord_tol: float | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
) -> Decomposition:
    """The decomposition of ``world`` at ``L``, from the cache or computed and stored.

    Args:
        world: the map.
        L: rod length.
        chord_tol: polyline tolerance (part of the key).
        cache_dir: directory (default ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``).
    """
    key = _key(world, L, chord_tol)
    path = cache_path(world, L, chord_tol, cache_dir)
    dec = _read(path, key) if path.exists() else None
    if dec is None:
        dec = build_decomposition(world, L, chord_tol)
        try:
            _write(path, key, dec)
        except OSError:
            pass  # a read-only or full disk only costs the recomputation next time
    return dec
