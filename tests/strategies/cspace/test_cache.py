"""The on-disk decomposition cache: keyed by map digest and parameters, atomic, never stale."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import strategies.cspace.cache as cache_mod
from strategies.cspace import decompose
from strategies.cspace.cache import cache_path, cached_decomposition, resolve_cache_dir
from tests.strategies.cspace._oracle import corridor, open_room


def _forbid_recompute(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("recomputed although cached")

    monkeypatch.setattr(cache_mod, "build_decomposition", boom)


def test_second_call_reads_the_cache(tmp_path, monkeypatch):
    world = corridor()
    first = decompose(world, 2.0, cache=True, cache_dir=tmp_path)
    path = cache_path(world, 2.0, None, tmp_path)
    assert path.exists()
    assert list(path.parent.glob("*.tmp")) == []  # atomic write left no temporary file
    _forbid_recompute(monkeypatch)
    second = decompose(world, 2.0, cache=True, cache_dir=tmp_path)
    assert second is not first
    assert len(second.cells) == len(first.cells)
    assert second.escapable == first.escapable
    for p in [(-3.0, 0.0), (5.0, 0.0), (0.5, 1.2)]:
        a = [(x.lo, x.hi) for x in first.safe_arcs(p)]
        b = [(x.lo, x.hi) for x in second.safe_arcs(p)]
        assert np.allclose(a, b)


def test_environment_variable_sets_the_default_directory(tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path / "here"))
    assert resolve_cache_dir() == tmp_path / "here"
    decompose(open_room(), 2.0, cache=True)
    assert list((tmp_path / "here" / "cspace").glob("decomposition-v*.pkl"))


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


def test_a_stale_file_for_another_map_is_never_read(tmp_path):
    """Even a file copied onto this map's path is rejected by the stored key."""
    room, corr = open_room(), corridor()
    cached_decomposition(room, 2.0, cache_dir=tmp_path)
    src = cache_path(room, 2.0, None, tmp_path)
    dst = cache_path(corr, 2.0, None, tmp_path)
    dst.write_bytes(src.read_bytes())
    dec = cached_decomposition(corr, 2.0, cache_dir=tmp_path)
    assert dec.map == corr and len(dec.regions) > 13
    with dst.open("rb") as fh:  # and the bad file was replaced by the right one
        assert pickle.load(fh)["key"]["map"] == corr.digest


@pytest.mark.parametrize("junk", [b"", b"not a pickle", pickle.dumps({"key": 1})])
def test_corrupt_files_are_recomputed(tmp_path, junk):
    world = open_room()
    path = cache_path(world, 2.0, None, tmp_path)
    path.parent.mkdir(parents=True)
    path.write_bytes(junk)
    dec = cached_decomposition(world, 2.0, cache_dir=tmp_path)
    assert len(dec.cells) == len(decompose(world, 2.0).cells)
