"""Repository hygiene that would otherwise creep back."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_benchmarks_use_the_installed_package() -> None:
    """Benchmarks import the installed package; none edits sys.path to find the checkout."""
    offenders = [
        p.name for p in sorted((ROOT / "benchmarks").glob("*.py")) if "sys.path" in p.read_text()
    ]
    assert offenders == []


def test_ci_runs_the_linter_the_formatter_and_the_lower_bounds() -> None:
    ci = (ROOT / ".ci" / "run").read_text()
    for step in ("ruff check .", "ruff format --check .", "scripts/check_min_versions.sh"):
        assert step in ci, step
    assert (ROOT / "scripts" / "check_min_versions.sh").exists()


def test_every_user_of_the_env_names_the_current_version() -> None:
    """The runner (hence evaluate, tournaments, benchmarks), the tournament's match
    identity and training's provenance all name the latest registered version: a new
    surveillance_vN that forgets one of them fails here."""
    import importlib

    from analysis.tournament import identity
    from envs import surveillance_v1
    from envs.surveillance.registry import ENV_ID, ENV_IDS
    from strategies.runner import build_env

    train = importlib.import_module("training.train")  # the package exports train()

    latest = f"surveillance_v{max(ENV_IDS)}"
    assert ENV_ID == f"surveil/surveillance-v{max(ENV_IDS)}" == train.ENV_ID
    assert identity.ENV_ID == train.ENV_NAME == latest
    assert build_env("open_room").metadata["name"] == latest
    assert surveillance_v1.parallel_env.metadata["name"] == latest
