"""benchmarks/fixed_starts.py: the shipped certified starts are what the referee certifies,
and a bad starts file is refused naming it."""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

from envs.errors import InvalidConfigError

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture
def fs(monkeypatch):
    """The module (it imports the benchmark scripts from beside it)."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("fixed_starts")


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::envs.errors.VacuousBoundWarning")  # the evader's worlds
@pytest.mark.parametrize(("role", "label"), [("pursuer", "plus_w6"), ("evader", "plus_w1.6a4.5")])
def test_the_shipped_certified_starts_are_the_referee_s(fs, role, label):
    """Certifying the world again draws the shipped starts (the same solve, the same
    generator), and the referee labels each of them for ``role``: the file cannot drift
    from the referee or from the worlds' definitions unnoticed (the two worlds whose
    solves are quickest, ~10 s and ~2 s)."""
    import referee_labels

    (shipped,) = [w for w in fs.load_certified() if (w["role"], w["world"]) == (role, label)]
    combo = dict(fs.CERTIFY[role])[label]
    assert shipped["combo"] == list(combo) and len(shipped["starts"]) == fs.N_STARTS[role]
    assert fs.certify_world(role, label, combo) == shipped
    m, ov = fs.world(role, label, combo)
    for start in shipped["starts"]:
        assert referee_labels.verdict(m, ov, start, fs.CPL) == role
        if role == "evader":
            assert 0 < start["escape_bound"] < 60


def test_every_world_to_certify_is_in_the_shipped_file(fs):
    """Each world of CERTIFY has its starts in the file (a world the referee certifies
    nothing on was replaced, not left out silently)."""
    shipped = {(w["role"], w["world"], tuple(w["combo"])) for w in fs.load_certified()}
    assert shipped == {(r, label, c) for r, worlds in fs.CERTIFY.items() for label, c in worlds}
    doc = json.loads(Path(fs.CERTIFIED).read_text())
    assert (doc["cpl"], doc["seed"], doc["solve"]) == (fs.CPL, fs.SEED, fs.referee_labels.SOLVE)


def test_a_bad_starts_file_is_refused_naming_it(fs, tmp_path):
    (tmp_path / "a.json").write_text('{"worlds": [{"role": "pursuer", "world": "corner"}]}')
    with pytest.raises(InvalidConfigError, match=r"a.json'.*a world without combo, starts; "
                       r"expected the JSON document fixed_starts.py --certify writes"):  # fmt: skip
        fs.load_certified(str(tmp_path / "a.json"))
    (tmp_path / "b.json").write_text("[1, 2")
    with pytest.raises(InvalidConfigError, match=r"b.json'"):
        fs.load_certified(str(tmp_path / "b.json"))
