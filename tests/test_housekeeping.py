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


def test_the_set_up_scripts_take_torch_from_the_cpu_index() -> None:
    """The README: scripts/setup.sh installs the CPU build of torch first. A bare
    ``pip install torch==2.13.0`` takes PyPI's, which on Linux is the CUDA build (a 527 MB
    wheel needing the nvidia-*-cu13 wheels); only a pip configured with a local CPU wheel
    (this project's own machines) got the CPU one. Both set-up scripts install torch with
    scripts/install_torch.sh, which asks PyPI's CPU index when it answers and falls back to
    pip's own configuration (where the index is unreachable, pip's retries cost ~75 s)."""
    for script in ("setup.sh", "check_min_versions.sh"):
        text = (ROOT / "scripts" / script).read_text()
        assert "bash scripts/install_torch.sh " in text, script
        assert "torch==" not in text, script  # one pin, in install_torch.sh
    text = (ROOT / "scripts" / "install_torch.sh").read_text()
    assert "INDEX=https://download.pytorch.org/whl/cpu" in text
    assert '-m pip install --quiet --index-url "$INDEX" "$TORCH"' in text
    assert 'TORCH="torch==2.13.0"' in text
    assert "timeout=5" in text  # the reachability check cannot hang the set-up


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
