"""The safety table's disk cache is verified on load, and its size does not depend on units.

Each kind of damage a user has met (issue 11: truncated, one flipped bit, empty, another
map's table copied over) gives one warning naming the file, then the table is rebuilt
equal to a fresh build and the file rewritten intact. An unwritable cache directory gives
one warning, not silent recomputation. A map drawn in other units (scaled by 100 or
1/100, L scaled alike) gets the same grid; a table beyond the memory budget is refused up
front with the estimate and the resolution that would fit.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

from envs.errors import InfeasibleError, InvalidConfigError
from envs.maps import builtin_map
from strategies.policies.safety import (
    CacheWarning,
    default_resolution,
    safety_table,
    table_bytes,
)

L = 2.0
RES = 0.5
BINS = 36
ARRAYS = ("origin", "cell", "free", "safe", "guaranteed", "ccw", "cw")

build = safety_table.__wrapped__  # past the in-process lru cache: every call reads the disk


def _same(a, b) -> None:
    for k in ARRAYS:
        assert np.array_equal(getattr(a, k), getattr(b, k)), k


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(tmp_path))
    return tmp_path


def _damage(kind: str, path, other) -> None:
    raw = path.read_bytes()
    if kind == "truncated":
        path.write_bytes(raw[: len(raw) // 2])
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "flipped bit":
        # flip a bit inside the compressed body of the biggest array (not the zip index):
        # the zip CRC, zlib or our checksum must notice
        b = bytearray(raw)
        b[len(b) // 3] ^= 0x10
        path.write_bytes(bytes(b))
    elif kind == "another table":
        path.write_bytes(other.read_bytes())
    else:  # pragma: no cover
        raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["truncated", "empty", "flipped bit", "another table"])
def test_a_damaged_or_mismatched_file_is_rebuilt_with_one_warning(cache, kind):
    world = builtin_map("corridor")
    fresh = build(world, L, RES, BINS)
    (path,) = cache.glob("safety_*.npz")
    build(builtin_map("l_hall"), L, RES, BINS)  # a second, valid table of another map
    (other,) = [p for p in cache.glob("safety_*.npz") if p != path]
    _damage(kind, path, other)
    with pytest.warns(CacheWarning) as seen:
        again = build(world, L, RES, BINS)
    seen = [w for w in seen if issubclass(w.category, CacheWarning)]
    assert len(seen) == 1 and str(path) in str(seen[0].message)
    assert "rebuilding" in str(seen[0].message)
    _same(again, fresh)
    with warnings.catch_warnings():  # the rewritten file is intact: no warning now
        warnings.simplefilter("error", CacheWarning)
        _same(build(world, L, RES, BINS), fresh)


def test_a_file_for_other_parameters_is_never_used(cache):
    world = builtin_map("corridor")
    a = build(world, L, RES, BINS)
    b = build(world, L, RES, 24)  # another bin count: another file
    assert len(list(cache.glob("safety_*.npz"))) == 2
    assert a.free.shape[1] == BINS and b.free.shape[1] == 24


def test_a_table_built_with_other_decomposition_tolerances_is_never_used(cache, monkeypatch):
    """The table is built from the decomposition: its key names the decomposition's
    constants too (a changed COLLAPSE_REL read the old table back)."""
    world = builtin_map("corridor")
    build(world, L, RES, BINS)
    monkeypatch.setattr("strategies.cspace.tolerances.COLLAPSE_REL", 2e-5)
    build(world, L, RES, BINS)
    assert len(list(cache.glob("safety_*.npz"))) == 2


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")
def test_an_unwritable_cache_directory_warns_once(tmp_path, monkeypatch):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(ro))
    with pytest.warns(CacheWarning, match="not writable"):
        build(builtin_map("corridor"), L, RES, BINS)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        build(builtin_map("corridor"), L, RES, 24)


def test_a_cache_path_that_is_a_file_warns_once(tmp_path, monkeypatch):
    blocker = tmp_path / "not_a_dir"
    blocker.write_text("x")
    monkeypatch.setenv("SURVEIL_CACHE_DIR", str(blocker))
    with pytest.warns(CacheWarning, match="not writable"):
        t = build(builtin_map("corridor"), L, RES, 28)
    assert t.free.any()


@pytest.mark.parametrize("scale", [0.01, 100.0])
def test_units_do_not_matter(scale):
    room = builtin_map("corridor")
    scaled = room.transformed(np.eye(2) * scale)
    a = safety_table(room, L, None, BINS, disk_cache=False)
    b = safety_table(scaled, L * scale, None, BINS, disk_cache=False)
    assert a.resolution == default_resolution(L) and b.resolution == pytest.approx(
        a.resolution * scale
    )
    assert a.shape == b.shape
    assert np.array_equal(a.cell >= 0, b.cell >= 0)
    # the same orientations are free at the same (scaled) grid points, up to bins that
    # a rounding of the scaled coordinates can flip at an arc's end
    assert np.mean(a.free != b.free) < 1e-3


def test_a_table_beyond_the_memory_budget_is_refused_up_front():
    world = builtin_map("corridor")
    need = table_bytes(world, 0.01, 144)
    assert need > 1e8
    with pytest.raises(InfeasibleError, match=r"GB.*resolution >= ") as err:
        safety_table(world, L, 0.01, 144, disk_cache=False, memory_budget="100MB")
    # the suggested resolution fits
    fit = float(str(err.value).split("resolution >= ")[1].split()[0])
    assert table_bytes(world, fit, 144) <= 1e8


@pytest.mark.parametrize(
    "kwargs",
    [{"L": -1.0}, {"resolution": 0.0}, {"resolution": True}, {"n_bins": 4}, {"n_bins": 2.5}],
)
def test_bad_parameters_name_the_value(kwargs):
    args = {"L": L, "resolution": RES, "n_bins": BINS, **kwargs}
    with pytest.raises(InvalidConfigError, match=next(iter(kwargs))):
        safety_table(builtin_map("corridor"), args["L"], args["resolution"], args["n_bins"])
