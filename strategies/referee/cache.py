"""On-disk cache of solved bounds: ``.npz`` files (no pickle) keyed by map digest and parameters.

Files live in ``$SURVEIL_CACHE_DIR`` (default ``~/.cache/surveil``) under ``referee/``:

* the file name is a SHA-256 of :data:`FORMAT_VERSION`, the bound's kind, the game's key
  (the map's wall digest and every parameter, exactly) and the resolution's key, so a
  changed map or parameter never hits a stale file;
* the file also stores that key material as JSON and a SHA-256 checksum of the arrays,
  both checked on load: a renamed, truncated or corrupted file is ignored (and recomputed
  by the caller);
* writes are atomic (a temporary file in the same directory, then ``os.replace``), so
  concurrent solvers of the same game at worst both compute it.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from strategies.cspace.cache import resolve_cache_dir
from strategies.referee.spec import MARGIN_REL, GameSpec, Resolution

__all__ = ["FORMAT_VERSION", "cache_path", "load_arrays", "save_arrays"]

FORMAT_VERSION = 2
"""Bump when the solver's semantics or the file layout change (2: the pursuer bound's sweep
test keeps the evader its clearance from the walls beside a jamb, robust.sweep_hits_vertex)."""


def _key(kind: str, spec: GameSpec, res: Resolution) -> dict:
    return {
        "format": FORMAT_VERSION,
        "kind": kind,
        "margin_rel": float(MARGIN_REL).hex(),
        "game": spec.key(),
        "resolution": res.key(),
    }


def cache_path(
    kind: str, spec: GameSpec, res: Resolution, directory: str | os.PathLike | None = None
) -> Path:
    """The file that holds (or would hold) a solved bound."""
    key = json.dumps(_key(kind, spec, res), sort_keys=True)
    h = hashlib.sha256(key.encode()).hexdigest()[:40]
    return resolve_cache_dir(directory) / "referee" / f"{kind}-v{FORMAT_VERSION}-{h}.npz"


def _checksum(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def save_arrays(
    kind: str,
    spec: GameSpec,
    res: Resolution,
    arrays: dict[str, np.ndarray],
    directory: str | os.PathLike | None = None,
) -> Path:
    """Write ``arrays`` atomically to the cache file of (kind, spec, res)."""
    path = cache_path(kind, spec, res, directory)
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = json.dumps({"key": _key(kind, spec, res), "checksum": _checksum(arrays)}, sort_keys=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez_compressed(fh, __meta__=np.frombuffer(meta.encode(), dtype=np.uint8), **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def load_arrays(
    kind: str,
    spec: GameSpec,
    res: Resolution,
    names: tuple[str, ...],
    directory: str | os.PathLike | None = None,
) -> dict[str, np.ndarray] | None:
    """The cached arrays of (kind, spec, res), or None when absent, stale or corrupted."""
    path = cache_path(kind, spec, res, directory)
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(bytes(data["__meta__"]).decode())
            arrays = {n: data[n] for n in names}
    except (OSError, KeyError, ValueError, zipfile.BadZipFile, EOFError, UnicodeDecodeError):
        return None
    if not isinstance(meta, dict) or meta.get("key") != json.loads(
        json.dumps(_key(kind, spec, res))
    ):
        return None
    if meta.get("checksum") != _checksum(arrays):
        return None
    return arrays
