"""A passage narrower than the decomposition's L-relative tolerances (E.md probe, s23).

Two blocks in a room, a vertical slit ``gap`` wide between them. With the rod in the
slit, the evader walks out of its far mouth and turns the corner: every cell above the
slit is escapable, and the evader wins (Prop. 2), as it does across the corridor of the
paper's Fig. 6. The tolerances were relative to L only (probe offset and speck size
1e-5 L): with a slit 2e-5 wide at L = 1.5 the faces at its mouths collapsed to points
and probes landed in the walls; half the slit's cells turned non-escapable and the
verdict flipped to "the pursuer holds", with every exactness check passing. The
tolerances now shrink with the map's narrowest passage; a slit too narrow even for the
kernel's floors is reported, not decided silently.
"""

from __future__ import annotations

import math
import warnings

import pytest

from envs.maps import Map, builtin_map, builtin_names, load_map
from envs.tolerances import REL_LENGTH_TOL
from strategies.cspace import decompose
from strategies.cspace.tolerances import (
    CHORD_TOL_REL,
    COLLAPSE_REL,
    KERNEL_FLOOR,
    MERGE_REL,
    PROBE_REL,
    THIN_REL,
    TOUCH_REL,
    Tolerances,
    diameter,
    narrowest_passage,
)


def _box(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def _slit(gap: float, scale: float = 1.0) -> Map:
    world = Map(_box(0, 0, 10, 10), [_box(2, 2, 5, 8), _box(5 + gap, 2, 8, 8)], name="slit")
    return world.transformed([[scale, 0.0], [0.0, scale]])


def _in_slit(dec, gap: float, scale: float) -> list:
    lo, hi = 5.0 * scale, (5.0 + gap) * scale
    eps = 1e-9 * scale
    return [
        r
        for r in dec.regions
        if r.polygon.bounds[0] >= lo - eps and r.polygon.bounds[2] <= hi + eps and r.cells
    ]


@pytest.mark.parametrize("scale", [1.0, 1e3])
@pytest.mark.parametrize(("gap", "L"), [(2e-5, 1.5), (2e-5, 0.5), (1e-4, 1.5)])
def test_every_cell_above_a_narrow_slit_is_escapable(gap, L, scale):
    world = _slit(gap, scale)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dec = decompose(world, L * scale)
    assert dec.exact
    assert dec.stats["unresolved_passages"] == 0
    slit = _in_slit(dec, gap, scale)
    assert len(slit) >= 3  # the slit's regions along its length and at its mouths
    not_escapable = [(r.id, c) for r in slit for c in r.cells if not dec.cells[c].escapable]
    assert not_escapable == []
    assert dec.evader_wins


def test_a_slit_too_narrow_to_resolve_is_reported_not_decided_silently():
    world = _slit(5e-6)  # above the map's gap tolerance (1.4e-6), below 2 probe floors
    with pytest.warns(
        RuntimeWarning, match=r"a passage 5e-06 wide between its walls, narrower than it"
    ):
        dec = decompose(world, 0.5)
    assert not dec.exact
    assert dec.stats["unresolved_passages"] == 1
    assert "UNRELIABLE" in dec.summary()


def test_a_cached_decomposition_that_is_not_exact_warns_when_read_back(tmp_path, monkeypatch):
    """It warned at its build only: read back from the cache it loaded silently, and only
    ``summary()`` said UNRELIABLE (helper-142)."""
    world = _slit(5e-6)
    with pytest.warns(RuntimeWarning, match="a passage 5e-06 wide"):
        built = decompose(world, 0.5, cache=True, cache_dir=tmp_path)

    def boom(*args, **kwargs):
        raise AssertionError("rebuilt although cached")

    monkeypatch.setattr("strategies.cspace._build.build_decomposition", boom)
    with pytest.warns(RuntimeWarning) as caught:
        again = decompose(world, 0.5, cache=True, cache_dir=tmp_path)
    (message,) = [str(w.message) for w in caught if w.category is RuntimeWarning]
    assert message.startswith("decompose('slit', L=0.5): the arrangement is not exact: ")
    assert "a passage 5e-06 wide between its walls, narrower than it resolves" in message
    assert "(read from the cache file " in message and str(tmp_path) in message
    assert not again.exact and again.stats == built.stats


@pytest.mark.parametrize(("width", "L"), [(1e-5, 2.0), (5e-6, 0.5)])
def test_a_room_thinner_than_the_probes_keeps_its_escapes(width, L):
    """A room 10 long and ``width`` wide, no vertex between its ends: the rod lies along
    it, and with the rod pointing one way the evader walks the other way until the rod's
    far end meets the end wall: both cells of the middle are escapable, the evader wins.
    The probe offset (1e-5 L, floored at 2.8e-6 here) exceeded the width, probes fell
    outside the room and the verdict was "the pursuer holds" (1e-5 wide at L = 2, 5e-6
    at L = 0.5), exact. Its walls join only at its short ends: a strip, not a passage
    round the walls; the tolerances now shrink for it too (5e-6 is below twice the
    kernel's probe floor: reported as well)."""
    room = Map([(0, 0), (10, 0), (10, width), (0, width)])
    assert narrowest_passage(room, 1e-3) == pytest.approx(width, rel=1e-9)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        dec = decompose(room, L)
    middle = dec.regions[dec.locate((5.0, 0.5 * width))]
    assert len(middle.cells) == 2
    assert all(dec.cells[c].escapable for c in middle.cells)
    assert dec.evader_wins
    assert dec.exact == (not caught) == (width > 2 * 2.8e-6)


def test_a_neck_too_narrow_is_reported_and_a_notch_as_narrow_is_not():
    """A notch 5e-6 wide and 1 deep holds one thin region with no piece inside to probe
    (its cells are those of its wider twins), a neck as narrow into a room is a passage."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        notch = decompose(_notch(5e-6, 1.0), 1.5)
    assert notch.exact and notch.stats["unresolved_passages"] == 0
    with pytest.warns(RuntimeWarning, match=r"a passage 5e-06 wide"):
        bottle = decompose(_bottle(5e-6), 1.5)
    assert not bottle.exact and bottle.stats["unresolved_passages"] == 1


def _notch(width: float, depth: float) -> Map:
    x, y = 5.0 + width, 10.0 + depth
    return Map([(0, 0), (10, 0), (10, 10), (x, 10), (x, y), (5, y), (5, 10), (0, 10)])


def _bottle(neck: float) -> Map:
    """The notch's room above the ceiling, reached through a neck ``neck`` wide, 0.5 long."""
    x = 5.0 + neck
    return Map(
        [(0, 0), (10, 0), (10, 10), (x, 10), (x, 10.5), (8, 10.5), (8, 12), (2, 12),
         (2, 10.5), (5, 10.5), (5, 10), (0, 10)]
    )  # fmt: skip


def test_a_passage_is_walls_near_each_other_that_join_only_the_long_way_round():
    assert narrowest_passage(_slit(2e-5), 1e-3) == pytest.approx(2e-5, rel=1e-9)
    assert narrowest_passage(_slit(2e-5), 1e-5) == math.inf  # none below the bound
    # a notch 3e-4 wide: a passage 1 deep, none 1e-4 deep (its walls join 7e-4 away)
    assert narrowest_passage(_notch(3e-4, 1.0), 1e-2) == pytest.approx(3e-4, rel=1e-9)
    assert narrowest_passage(_notch(3e-4, 1e-4), 1e-2) == math.inf
    # nor does a tooth 3e-4 wide and 1 high: its corners face each other across it
    tooth = Map([(0, 0), (5, 0), (5, 1), (5.0003, 1), (5.0003, 0), (10, 0), (10, 10), (0, 10)])
    assert narrowest_passage(tooth, 1e-2) == math.inf
    # a notch thin all along is a dead end, a strip 1 long (counted beyond a length given);
    # a neck as narrow into a room behind is a passage
    assert narrowest_passage(_notch(3e-4, 1.0), 1e-2, dead_ends=False, strips_over=2.0) == math.inf
    notch = narrowest_passage(_notch(3e-4, 1.0), 1e-2, dead_ends=False, strips_over=0.5)
    assert notch == pytest.approx(3e-4, rel=1e-9)
    neck = narrowest_passage(_bottle(3e-4), 1e-2, dead_ends=False)
    assert neck == pytest.approx(3e-4, rel=1e-9)
    # walls that touch (two merged blocks meeting at a corner) bound no passage
    touching = Map(_box(0, 0, 10, 10), [_box(2, 2, 4, 4), _box(4, 4, 6, 6)], merge=True)
    assert narrowest_passage(touching, 1.0) == math.inf


@pytest.mark.parametrize(
    "name", [*builtin_names(), "random:polygons:21", "random:star:12", "corner~x1e-3"]
)
def test_maps_without_narrow_passages_keep_their_tolerances(name):
    world = builtin_map(name) if name in builtin_names() else load_map(name)
    k = REL_LENGTH_TOL * math.sqrt(2.0) * diameter(world)
    for L in (0.05 * diameter(world), 0.5 * diameter(world), 0.99 * diameter(world)):
        tol = Tolerances.of(world, L)
        assert tol.passage == math.inf and not tol.unresolved
        assert (tol.chord, tol.merge, tol.touch, tol.thin, tol.probe, tol.collapse) == (
            CHORD_TOL_REL * L,
            max(MERGE_REL * L, KERNEL_FLOOR["merge"] * k),
            max(TOUCH_REL * L, KERNEL_FLOOR["touch"] * k),
            max(THIN_REL * L, KERNEL_FLOOR["thin"] * k),
            max(PROBE_REL * L, KERNEL_FLOOR["probe"] * k),
            max(COLLAPSE_REL * L, KERNEL_FLOOR["collapse"] * k),
        )


def test_cache_keys_change_only_for_narrow_passages():
    """A narrow map's files from before the rule (other tolerances) are not read back;
    every other map keeps its key, so its cached decompositions stay valid."""
    from strategies.cspace.cache import _raw_key

    narrow = _raw_key(_slit(2e-5), 1.5, None)
    assert float.fromhex(narrow["passage"]) == pytest.approx(2e-5, rel=1e-9)
    keys = {"format", "constants", "map", "L", "chord_tol"}
    assert set(_raw_key(builtin_map("corridor"), 2.0, None)) == keys
    assert set(_raw_key(_slit(0.01), 1.5, None)) == keys
