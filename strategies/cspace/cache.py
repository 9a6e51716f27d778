"""On-disk cache of decompositions: keyed, checksummed, verified on load, code-free.

Policies and tournaments ask for the same decomposition many times, across processes.
Files live in ``$SURVEIL_CACHE_DIR`` (default ``~/.cache/surveil``) under ``cspace/``:

* the file name is a SHA-256 of the key: :data:`FORMAT_VERSION`, a digest of every
  constant the result may depend on (:func:`constants_digest`), the map's wall digest
  (:attr:`envs.maps.Map.digest`), L and the chord tolerance, so a changed map, parameter
  or tolerance can never hit a stale file;
* the file is a one-line JSON header (the key again, the body's length and SHA-256, the
  build's statistics) followed by an ``.npz`` body of plain numeric arrays
  (:mod:`strategies.cspace._serial`), read with ``allow_pickle=False``: loading a cache
  file cannot run code;
* on load the header's key must equal the expected key and the body its checksum; a
  damaged or mismatched file (truncated, a flipped bit, empty, another map's entry
  copied over) is rebuilt and rewritten, with a one-line warning naming the file;
* a decomposition that is not exact warns when it is read back, as its build did;
* writes are atomic (a temporary file in the same directory, then ``os.replace``); a
  directory that cannot be written gets one warning per process, then the cache is
  skipped for it.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from envs.maps.map import Map
from strategies.cspace import tolerances as _tol
from strategies.cspace._serial import from_arrays, to_arrays
from strategies.cspace.decomposition import Decomposition

__all__ = [
    "FORMAT_VERSION",
    "CacheWarning",
    "cache_path",
    "cached_decomposition",
    "constants_digest",
    "resolve_cache_dir",
    "write_cache_file",
]

FORMAT_VERSION = 18  # 18: twin dangling edges are one (17: thin everywhere)
"""Bump when the decomposition's content or the file layout changes."""

MAGIC = b"SURVEIL-CSPACE-DECOMPOSITION\n"

_UNWRITABLE: set[str] = set()  # directories already warned about (one warning each)


class CacheWarning(RuntimeWarning):
    """A cache file was damaged or mismatched (rebuilt), or could not be written."""


def resolve_cache_dir(directory: str | os.PathLike[str] | None = None) -> Path:
    """The cache directory: the argument, ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``."""
    if directory is not None:
        return Path(directory)
    env = os.environ.get("SURVEIL_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "surveil"


def _key(world: Map, L: float, chord_tol: float | None) -> dict:
    return json.loads(json.dumps(_raw_key(world, L, chord_tol)))  # as read back from a file


_RESULT_MODULES = (
    "envs.tolerances",
    "strategies.cspace.tolerances",
    "strategies.cspace._arcs",
    "strategies.cspace._batch_arcs",
    "strategies.cspace._build",
    "strategies.cspace._candidates",
    "strategies.cspace._collinear",
    "strategies.cspace._intersect",
    "strategies.cspace._noding",
    "strategies.cspace._paths",
    "strategies.cspace._probing",
    "strategies.cspace._rod",
    "strategies.cspace._samples",
    "strategies.cspace._shapes",
    "strategies.cspace.arrangement",
    "strategies.cspace.curves",
    "strategies.cspace.decomposition",
)
"""The modules whose constants a decomposition may depend on (the kernel's tolerances and
the build's): every one is in the cache key (:func:`constants_digest`)."""


def _constant(value: object) -> bool:
    """Whether ``value`` is a constant of the build: a number, a tuple of them (or of
    names), or a non-empty table of numbers by name (not a module's cache, a growing dict)."""
    if isinstance(value, (int, float)):
        return True
    if isinstance(value, tuple):
        return all(isinstance(v, (int, float, str)) or _constant(v) for v in value)
    if isinstance(value, dict):
        return bool(value) and all(
            isinstance(k, str) and isinstance(v, (int, float)) for k, v in value.items()
        )
    return False


def constants_digest() -> str:
    """A SHA-256 of every upper-case constant (a number, a tuple or a table of numbers) of
    :data:`_RESULT_MODULES`: a change of any tolerance the decomposition depends on
    (``COLLAPSE_REL`` was not in the key) gives other cache files, not a stale one."""
    import importlib

    found = {}
    for name in _RESULT_MODULES:
        module = importlib.import_module(name)
        for attr, value in vars(module).items():
            if attr.lstrip("_")[:1].isupper() and attr.upper() == attr and _constant(value):
                found[f"{name}.{attr}"] = value
    text = json.dumps(found, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _raw_key(world: Map, L: float, chord_tol: float | None) -> dict:
    key = {
        "format": FORMAT_VERSION,
        "constants": constants_digest(),
        "map": world.digest,
        "L": float(L).hex(),
        "chord_tol": None if chord_tol is None else float(chord_tol).hex(),
    }
    # a map narrower than PASSAGE_REL * L is decomposed with smaller tolerances
    # (Tolerances.of): its files from before that rule are not read back
    passage = _tol.narrowest_passage(world, _tol.PASSAGE_REL * float(L))
    if math.isfinite(passage):
        key["passage"] = passage.hex()
    return key


def cache_path(
    world: Map, L: float, chord_tol: float | None = None, directory: str | os.PathLike | None = None
) -> Path:
    """The file that holds (or would hold) the decomposition of ``world`` at ``L``."""
    key = json.dumps(_key(world, L, chord_tol), sort_keys=True)
    h = hashlib.sha256(key.encode()).hexdigest()[:40]
    return resolve_cache_dir(directory) / "cspace" / f"decomposition-v{FORMAT_VERSION}-{h}.cache"


def _encode(key: dict, dec: Decomposition) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **to_arrays(dec))
    body = buf.getvalue()
    header = {
        "key": key,
        "bytes": len(body),
        "sha256": hashlib.sha256(body).hexdigest(),
        "stats": dec.stats,
    }
    return MAGIC + json.dumps(header, sort_keys=True).encode() + b"\n" + body


class _Bad(Exception):
    """Why a cache file cannot be used."""


def _decode(raw: bytes, key: dict, world: Map) -> Decomposition:
    if not raw:
        raise _Bad("empty file")
    if not raw.startswith(MAGIC):
        raise _Bad("not a decomposition cache file")
    end = raw.find(b"\n", len(MAGIC))
    if end < 0:
        raise _Bad("truncated header")
    try:
        header = json.loads(raw[len(MAGIC) : end].decode())
    except (UnicodeDecodeError, ValueError) as exc:
        raise _Bad(f"unreadable header ({exc})") from None
    if not isinstance(header, dict) or header.get("key") != key:
        raise _Bad("its key is another map's or another parameter's")
    body = raw[end + 1 :]
    if len(body) != header.get("bytes"):
        raise _Bad(f"truncated ({len(body)} of {header.get('bytes')} bytes)")
    if hashlib.sha256(body).hexdigest() != header.get("sha256"):
        raise _Bad("checksum mismatch (damaged)")
    try:
        with np.load(io.BytesIO(body), allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        return from_arrays(world, arrays, dict(header.get("stats") or {}))
    except Exception as exc:  # a valid checksum on content we cannot read: a bug or an old layout
        raise _Bad(f"unreadable content ({type(exc).__name__}: {exc})") from None


def _read(path: Path, key: dict, world: Map) -> Decomposition | None:
    try:
        raw = path.read_bytes()
    except (FileNotFoundError, NotADirectoryError):  # no entry (the write warns if it fails)
        return None
    except OSError as exc:
        warnings.warn(
            f"decomposition cache {path}: cannot read ({exc}); rebuilding",
            CacheWarning,
            stacklevel=4,
        )
        return None
    try:
        return _decode(raw, key, world)
    except _Bad as why:
        warnings.warn(
            f"decomposition cache {path}: {why}; rebuilding it", CacheWarning, stacklevel=4
        )
        return None


def _write(path: Path, key: dict, dec: Decomposition) -> None:
    write_cache_file(path, lambda fh: fh.write(_encode(key, dec)), "decomposition")


def write_cache_file(path: Path, write: Callable[[Any], Any], what: str) -> None:
    """Write a cache file atomically; never fail the caller over it.

    ``write(fh)`` fills a temporary file in the same directory, which then replaces
    ``path`` (readers see the old file or the new one, never half of one). A directory
    that cannot be written gets one :class:`CacheWarning` per process (``what`` names
    the kind of entry: "decomposition", "safety table"), then the cache is skipped; a
    failed write warns and leaves nothing behind.
    """
    directory = path.parent
    try:
        directory.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=directory)
    except OSError as exc:
        if str(directory) not in _UNWRITABLE:
            _UNWRITABLE.add(str(directory))
            warnings.warn(
                f"{what} cache directory {directory} is not writable ({exc}); entries "
                "will be recomputed (set SURVEIL_CACHE_DIR to change it)",
                CacheWarning,
                stacklevel=4,
            )
        return
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
        os.replace(tmp, path)
    except BaseException as exc:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, OSError):
            warnings.warn(f"{what} cache {path}: cannot write ({exc})", CacheWarning, stacklevel=4)
            return
        raise


def cached_decomposition(
    world: Map,
    L: float,
    *,
    chord_tol: float | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    build: Callable[[], Decomposition] | None = None,
) -> Decomposition:
    """The decomposition of ``world`` at ``L``, from the cache or built and stored.

    Args:
        world: the map.
        L: rod length.
        chord_tol: polyline tolerance (part of the key).
        cache_dir: directory (default ``$SURVEIL_CACHE_DIR`` or ``~/.cache/surveil``).
        build: how to build it on a miss (default: ``build_decomposition``).
    """
    key = _key(world, L, chord_tol)
    path = cache_path(world, L, chord_tol, cache_dir)
    dec = _read(path, key, world)
    if dec is not None and not dec.exact:  # warned at its build: warned at every load too
        from strategies.cspace._build import warn_cached

        warn_cached(dec, _tol.Tolerances.of(world, L, chord_tol), path)
    if dec is None:
        if build is None:
            from strategies.cspace._build import build_decomposition

            dec = build_decomposition(world, L, chord_tol)
        else:
            dec = build()
        _write(path, key, dec)
    return dec
