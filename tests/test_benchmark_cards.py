"""Model cards written by ``benchmarks/learned_vs_analytic.py --cards`` say where their
figures come from: the env version the matches played, the commit, the command, and the
env version the model trained on (issue 9/13: the shipped models trained on v0)."""

from __future__ import annotations

import importlib
import json
import shutil
from pathlib import Path

import pytest

from analysis.tournament.identity import ENV_ID
from training import zoo
from training.train import _git

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
MODEL = "dagger_pursuer_corridor"  # a specialist: one seen map, quick to play


@pytest.fixture
def lva(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    return importlib.import_module("learned_vs_analytic")


@pytest.fixture
def tmp_zoo(tmp_path, monkeypatch):
    """A zoo holding a copy of MODEL, so a card written by a test leaves the shipped one."""
    root = tmp_path / "zoo"
    shutil.copytree(zoo.MODELS_DIR / MODEL, root / MODEL)
    monkeypatch.setattr(zoo, "MODELS_DIR", root)
    return root


def test_a_card_from_a_small_run_names_the_env_it_played_the_commit_and_the_command(
    lva, tmp_zoo, tmp_path, capsys
):
    card = tmp_zoo / MODEL / "CARD.md"
    # the old figure is a word no card writes (it was "0.99", which the new card held
    # whenever the measured decision time read "0.999 ms": the test failed by chance)
    card.write_text("# old card\n\n## Measured\n\nOLD-FIGURE\n\n## Notes\n\nHand-written.\n")
    argv = ["--models", MODEL, "--seeds", "1", "--max-cycles", "40", "--maps", "corridor",
            "--workers", "1", "--store", str(tmp_path / "s.sqlite"), "--cards"]  # fmt: skip
    assert lva.main(argv) == 0
    text = card.read_text()
    assert ENV_ID == "surveillance_v1"
    assert "## Measured on surveillance_v1 (1 seeded safe starts per map, max_cycles 40)" in text
    head = _git("rev-parse", "HEAD")
    if head:
        assert f"Measured at {head[:12]}" in text
    command = ("python benchmarks/learned_vs_analytic.py --seeds 1 --max-cycles 40 --models "
               f"{MODEL} --maps corridor --cards")  # fmt: skip
    assert f"by `{command}`" in text
    trained = zoo.trained_env(MODEL)
    assert f"- trained on `{trained}`" in text
    if trained == "surveillance_v0":
        assert "Trained on `surveillance_v0`, measured on `surveillance_v1`" in text
    assert "| seen: corridor | evader/shooting |" in text
    # the old figures are gone, the hand-written notes are kept, at the end
    assert "OLD-FIGURE" not in text and "# old card" not in text
    assert text.endswith("\n\n## Notes\n\nHand-written.\n")


def test_a_card_without_notes_gets_none_and_notes_are_not_doubled(lva):
    assert lva.with_notes("# card\n", None) == "# card\n"
    assert lva.with_notes("# card\n", "# old\n\nno notes\n") == "# card\n"
    old = "# old\n\n## Notes\n\nkeep me\n"
    once = lva.with_notes("# card\n", old)
    assert once == "# card\n\n## Notes\n\nkeep me\n"
    assert lva.with_notes("# card\n", once) == once  # a second rewrite keeps them once


def test_trained_env_reads_the_provenance_else_the_training_commit(tmp_zoo):
    prov_path = tmp_zoo / MODEL / "provenance.json"
    prov = json.loads(prov_path.read_text())
    # trained before surveillance_v1 existed, by a DAgger writer that did not record it
    assert "env_id" not in prov
    if _git("cat-file", "-e", f"{prov['git_sha']}^{{commit}}") is None:
        pytest.skip("this clone does not have the model's training commit")
    assert zoo.trained_env(MODEL) == "surveillance_v0"
    prov_path.write_text(json.dumps({**prov, "git_sha": "0" * 40}))
    assert zoo.trained_env(MODEL) is None  # a commit git does not know: it cannot tell
    prov_path.write_text(json.dumps({**prov, "env_id": "surveillance_v1"}))
    assert zoo.trained_env(MODEL) == "surveillance_v1"  # a recorded version wins


def test_an_rl_models_card_names_its_network_and_timesteps(lva):
    """An RL run's provenance has no net_arch, parameters or samples: the card said
    "network: None (None parameters)" and "labelled states: -"."""
    import argparse

    name = "ppo_pursuer_vs_straight_open_room"
    args = argparse.Namespace(seeds=1, max_cycles=300, models=[name], maps=None)
    measured = {"env": ENV_ID, "sha": "0" * 40, "dirty": False, "command": "python x"}
    text = lva.card(name, "pursuer", [], args, measured=measured)
    assert "network: None" not in text and "None parameters" not in text
    assert "- network: PPO's default MLP, model file" in text
    assert f"- timesteps: {zoo.info(name)['timesteps']}; wall time" in text
    general = lva.card("dagger_pursuer_generalist", "pursuer", [], args, measured=measured)
    assert "- network: [128, 128] (43909 parameters)" in general
    assert "- labelled states: 62809; wall time" in general


def test_a_run_that_leaves_out_a_models_target_maps_gives_no_verdict_not_nan(lva, tmp_path, capsys):
    """``--maps open_room`` for the corridor specialist: its target map was not played, so
    the targets line says so (it printed 'held nan / decomposition nan = nan ... NOT met')."""
    argv = ["--models", MODEL, "--seeds", "1", "--max-cycles", "20", "--maps", "open_room",
            "--workers", "1", "--store", str(tmp_path / "s.sqlite")]  # fmt: skip
    assert lva.main(argv) == 0
    out = capsys.readouterr().out
    targets = out[out.index("targets (ratios measured in this run)") :]
    assert "nan" not in targets and "NOT met" not in targets
    assert f"{MODEL}: its target maps (corridor) were not played in this run" in targets


def test_a_run_on_none_of_a_models_card_maps_leaves_its_card(lva, tmp_zoo, tmp_path, capsys):
    """``--maps 'corner~rot0.4' --cards`` replaced the shipped card (20 seeds, eight rows)
    by one whose table had no row: neither a map the model trained on nor a held-out one
    was played."""
    card = tmp_zoo / MODEL / "CARD.md"
    before = card.read_text()
    argv = ["--models", MODEL, "--seeds", "1", "--max-cycles", "20", "--maps", "corner~rot0.4",
            "--workers", "1", "--store", str(tmp_path / "s.sqlite"), "--cards"]  # fmt: skip
    assert lva.main(argv) == 0
    assert card.read_text() == before
    out = capsys.readouterr().out
    assert f"card: {card} left as it was: this run played none of the maps {MODEL} " in out


def test_a_run_on_some_held_out_maps_names_only_those(lva, tmp_zoo, tmp_path, capsys):
    """``--maps corridor pillars``: the printed group and the card's rows were labelled
    'held out: pillars, random:9001, random:9002, random:rectangles:9003' over matches
    played on pillars alone."""
    argv = ["--models", MODEL, "--seeds", "1", "--max-cycles", "20", "--maps", "corridor",
            "pillars", "--workers", "1", "--store", str(tmp_path / "s.sqlite"),
            "--cards"]  # fmt: skip
    assert lva.main(argv) == 0
    out = capsys.readouterr().out
    assert "\n== held out: pillars\n" in out
    text = (tmp_zoo / MODEL / "CARD.md").read_text()
    assert "| held out: pillars | evader/shooting |" in text
    assert "random:9001" not in out and "random:9001" not in text
