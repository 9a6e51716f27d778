"""Every registered figure builds (at a reduced size), and the registry behaves."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.figures.registry import build_figure, figure_names, figure_spec, select
from envs.errors import InvalidConfigError, UnknownNameError

pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")

DOCS = Path(__file__).resolve().parents[3] / "docs" / "figures"

PAPER_FIGURES = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}


@pytest.mark.parametrize("name", figure_names())
def test_every_figure_builds(name, tmp_path):
    spec = figure_spec(name)
    path = build_figure(name, tmp_path, scale=0.35)
    assert path == tmp_path / spec.filename
    with Image.open(path) as img:
        assert img.format == spec.kind.upper()
        assert min(img.size) >= 40
        if spec.kind == "gif":
            assert img.n_frames >= 5  # a replay, not a still
    assert spec.caption and spec.title and spec.paper


def test_the_paper_is_covered():
    """A figure for each of the paper's Figs. 1-16 the text describes, and a replay for
    each claim the env can show in motion."""
    numbered = set()
    for s in select(None):
        head = s.paper.split()[1] if s.paper.startswith("Fig.") else ""
        digits = "".join(ch for ch in head if ch.isdigit())
        if digits:
            numbered.add(int(digits))
    assert numbered >= PAPER_FIGURES
    gifs = {s.name for s in select(None) if s.kind == "gif"}
    assert {"fig03-replay", "fig06-replay", "fig09-replay", "fn4-replay"} <= gifs


def test_documentation_figures_are_all_there_and_small():
    files = {p.name: p.stat().st_size for p in DOCS.iterdir()}
    assert {figure_spec(n).filename for n in figure_names()} == set(files)
    assert sum(files.values()) < 2.5 * 2**20
    assert max(files.values()) < 400 * 2**10


def test_select_takes_names_and_prefixes():
    assert [s.name for s in select(["fig12-greedy"])] == ["fig12-greedy"]
    assert {s.name for s in select(["fig03"])} == {"fig03-corridor", "fig03-replay"}
    assert len(select(None)) == len(figure_names())
    with pytest.raises(UnknownNameError, match="known figures"):
        select(["fig99"])
    with pytest.raises(UnknownNameError, match="ambiguous"):
        figure_spec("fig0")


def test_bad_scale_is_refused(tmp_path):
    with pytest.raises(InvalidConfigError, match="scale"):
        build_figure("fig12", tmp_path, scale=0)
    with pytest.raises(InvalidConfigError, match="scale"):
        build_figure("fig12", tmp_path, scale=True)
    with pytest.raises(InvalidConfigError, match=r"scale = 100.0: expected a size factor"):
        build_figure("fig12", tmp_path, scale=100.0)


def test_figures_are_deterministic(tmp_path):
    a = build_figure("fig11", tmp_path / "a", scale=0.3).read_bytes()
    b = build_figure("fig11", tmp_path / "b", scale=0.3).read_bytes()
    assert a == b
