"""The on-disk decomposition cache: keyed, checksummed, verified, code-free, never stale.

Every kind of damage (issue 11) is rebuilt with one warning naming the file: truncated,
one flipped bit (in the body and in the header), empty, another map's entry copied
over, a pickle where the file should be; an unwritable directory warns once.
"""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

import strategies.cspace.cache as cache_mod
from strategies.cspace import decompose
from strategies.cspace.cache import (
    CacheWarning,
    cache_path,
    cached_decomposition,
    resolve_cache_dir,
)
from tests.strategies.cspace._oracle import corridor, open_room, tilted_block


def _forbid_recompute(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("recomputed although cached")

    monkeypatch.setattr("strategies.cspace._build.build_decomposition", boom)


def _same(a, b):
    assert len(a.regions) == len(b.regions) and len(a.cells) == len(b.cells)
    assert a.escapable == b.escapable and a.stats == b.stats
    assert [c.stops for c in a.cells] == [c.stops for c in b.cells]
    assert [bd.adjacent for bd in a.boundaries] == [bd.adjacent for bd in b.boundaries]
    for p in [(-3.0, 0.0), (5.0, 0.0), (0.5, 1.2), (2.0, -4.0), (8.0, 3.5)]:
        x = [(arc.lo, arc.hi) for arc in a.safe_arcs(p)]
        y = [(arc.lo, arc.hi) for arc in b.safe_arcs(p)]
        assert np.allclose(x, y)
        assert a.locate(p) == b.locate(p)


def test_second_call_reads_the_cache(tmp_path, monkeypatch):
    world = corridor()
    first = decompose(world, 2.0, cache=True, cache_dir=tmp_path)
    path = cache_path(world, 2.0, None, tmp_path)
    assert path.exists()
    assert list(path.parent.glob("*.tmp")) == []  # atomic write left no temporary file
    _forbid_recompute(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        second = decompose(world, 2.0, cache=True, cache_dir=tmp_path)
    assert second is not first and second.map == world
    _same(first, second)
    assert second.graph.number_of_edges() == first.graph.number_of_edges()


def test_the_file_holds_no_pickle(tmp_path):
    world = tilted_block()
    decompose(world, 2.9, cache=True, cache_dir=tmp_path)
    raw = cache_path(world, 2.9, None, tmp_path).read_bytes()
    assert raw.startswith(cache_mod.MAGIC)
    body = raw[raw.index(b"\n", len(cache_mod.MAGIC)) + 1 :]
    with np.load(__import__("io").BytesIO(body), allow_pickle=False) as data:
        assert all(data[k].dtype != object for k in data.files)


def test_environment_variable_sets_the_default_directory(tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "here"))
    assert resolve_cache_dir() == tmp_path / "here"
    decompose(open_room(), 2.0, cache=True)
    assert list((tmp_path / "here" / "cspace").glob("decomposition-v*.cache"))


def test_key_depends_on_map_and_parameters(tmp_path):
    a, b = corridor(), open_room()
    paths = {
        cache_path(a, 2.0, None, tmp_path),
        cache_path(b, 2.0, None, tmp_path),
        cache_path(a, 2.0 + 1e-12, None, tmp_path),
        cache_path(a, 2.0, 1e-4, tmp_path),
    }
    assert len(paths) == 4
    assert f"v{cache_mod.FORMAT_VERSION}" in cache_path(a, 2.0, None, tmp_path).name


@pytest.mark.parametrize(
    ("module", "name"),
    [
        ("strategies.cspace.tolerances", "COLLAPSE_REL"),  # was not in the key (helper-142)
        ("strategies.cspace.tolerances", "COLLAPSE_FLOOR_REL"),
        ("strategies.cspace.tolerances", "PASSAGE_REL"),
        ("strategies.cspace.tolerances", "RESOLVED_PASSAGE"),
        ("strategies.cspace.tolerances", "KERNEL_FLOOR"),
        ("strategies.cspace.tolerances", "PROBE_REL"),
        ("strategies.cspace._probing", "CUSP_MARGIN"),
        ("strategies.cspace._rod", "WEDGE_TOL"),
        ("envs.tolerances", "ANGLE_TOL"),
    ],
)
def test_key_depends_on_every_constant_of_the_build(tmp_path, monkeypatch, module, name):
    """A changed tolerance must not read the files built with the old one: the key held
    five of the tolerances module's constants and not COLLAPSE_REL, the speck size."""
    import importlib

    world = corridor()
    before = cache_path(world, 2.0, None, tmp_path)
    value = getattr(importlib.import_module(module), name)
    changed = {k: 2 * v for k, v in value.items()} if isinstance(value, dict) else 2 * value
    monkeypatch.setattr(f"{module}.{name}", changed)
    assert cache_path(world, 2.0, None, tmp_path) != before
    monkeypatch.undo()
    assert cache_path(world, 2.0, None, tmp_path) == before


def test_the_key_is_the_same_after_a_build(tmp_path):
    """The constants' digest reads no module cache that a build fills (``_INDEX``...)."""
    world = open_room()
    before = cache_mod.constants_digest()
    decompose(world, 2.0, cache=False)
    assert cache_mod.constants_digest() == before


def _damaged(tmp_path, damage):
    """Build corridor's entry, damage the file, read it again: (path, dec, warnings)."""
    world = corridor()
    good = cached_decomposition(world, 2.0, cache_dir=tmp_path)
    path = cache_path(world, 2.0, None, tmp_path)
    damage(path)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        dec = cached_decomposition(world, 2.0, cache_dir=tmp_path)
    _same(good, dec)
    ours = [w for w in rec if issubclass(w.category, CacheWarning)]
    # and the file was rewritten whole: the next read is silent
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cached_decomposition(world, 2.0, cache_dir=tmp_path)
    return path, ours


def _flip(offset_from_end: int | None = None, at_header: bool = False):
    def damage(path):
        raw = bytearray(path.read_bytes())
        i = len(cache_mod.MAGIC) + 5 if at_header else len(raw) - (offset_from_end or 1000)
        raw[i] ^= 0x10
        path.write_bytes(bytes(raw))

    return damage


@pytest.mark.parametrize(
    ("damage", "why"),
    [
        (lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]), "truncated"),
        (lambda p: p.write_bytes(b""), "empty"),
        (_flip(1000), "checksum"),
        (_flip(at_header=True), ""),
        (lambda p: p.write_bytes(pickle.dumps({"key": 1})), "not a decomposition cache"),
        (lambda p: p.write_bytes(cache_mod.MAGIC + b"{not json\n" + b"x" * 50), "header"),
    ],
    ids=["truncated", "empty", "bit_in_body", "bit_in_header", "a_pickle", "bad_header"],
)
def test_every_damaged_file_is_rebuilt_with_one_warning_naming_it(tmp_path, damage, why):
    path, ours = _damaged(tmp_path, damage)
    assert len(ours) == 1, [str(w.message) for w in ours]
    message = str(ours[0].message)
    assert str(path) in message and "rebuilding" in message and why in message
    assert "\n" not in message


def test_another_maps_entry_copied_over_is_rejected_by_its_key(tmp_path):
    room, corr = open_room(), corridor()
    cached_decomposition(room, 2.0, cache_dir=tmp_path)
    src = cache_path(room, 2.0, None, tmp_path)
    dst = cache_path(corr, 2.0, None, tmp_path)
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_bytes(src.read_bytes())
    with pytest.warns(CacheWarning, match="another map's"):
        dec = cached_decomposition(corr, 2.0, cache_dir=tmp_path)
    assert dec.map == corr and len(dec.regions) > 13
    assert cache_mod._decode(dst.read_bytes(), cache_mod._key(corr, 2.0, None), corr)


def test_an_unwritable_directory_warns_once_and_still_answers(tmp_path):
    blocker = tmp_path / "not_a_directory"
    blocker.write_text("a file where the cache directory should be")
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        a = decompose(corridor(), 2.0, cache=True, cache_dir=blocker)
        b = decompose(open_room(), 2.0, cache=True, cache_dir=blocker)
    ours = [w for w in rec if issubclass(w.category, CacheWarning)]
    assert len(ours) == 1 and "not writable" in str(ours[0].message)
    assert str(blocker) in str(ours[0].message)
    assert a.cells and b.cells
