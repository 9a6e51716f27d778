#!/usr/bin/env bash
# Check the lower bounds in pyproject.toml: install every dependency at exactly its
# minimum (">=X" becomes "==X") in a separate virtualenv, .venv-min, and run a quick
# subset of the tests there. A bound that is too low fails here (an ImportError, a
# resolver conflict or a failing test) instead of on a user's machine.
#
#   bash scripts/check_min_versions.sh            # set up .venv-min (once) and test
#   bash scripts/check_min_versions.sh --fresh    # rebuild .venv-min from scratch
#
# torch is installed first at the pinned CPU build, as in scripts/setup.sh (never let pip
# pull another one). Runs in CI from .ci/run; takes a few minutes on a clean machine.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=.venv-min
if [ "${1:-}" = "--fresh" ]; then
    rm -rf "$VENV"
fi
if [ ! -x "$VENV/bin/python" ]; then
    "$PY" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
bash scripts/install_torch.sh "$VENV/bin/python"
CONSTRAINTS="$VENV/min-constraints.txt"
# every extra's bounds too (render, analysis, train, bench, test); tomli reads
# pyproject.toml on Python 3.10
"$VENV/bin/python" -m pip install --quiet "tomli>=2.0; python_version < '3.11'"
"$VENV/bin/python" - "$CONSTRAINTS" <<'EOF'
import re
import sys

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

with open("pyproject.toml", "rb") as f:
    project = tomllib.load(f)["project"]
reqs = list(project["dependencies"])
for extra in ("render", "analysis", "train", "bench", "test"):
    reqs += project["optional-dependencies"][extra]
pins = {}
for req in reqs:
    spec, _, marker = req.partition(";")
    if marker.strip() and "python_version < '3.11'" in marker and sys.version_info >= (3, 11):
        continue
    m = re.fullmatch(r"\s*([A-Za-z0-9_.\-]+)(\[[^\]]*\])?\s*>=\s*([0-9][^,\s]*)\s*", spec)
    if m and not m.group(1).startswith("surveil"):
        pins[m.group(1).lower()] = m.group(3)
with open(sys.argv[1], "w") as out:
    for name, version in sorted(pins.items()):
        out.write(f"{name}=={version}\n")
EOF
echo "minimum versions:" $(tr '\n' ' ' < "$CONSTRAINTS")
"$VENV/bin/python" -m pip install --quiet -c "$CONSTRAINTS" -e ".[all]"
"$VENV/bin/python" -m pip check
# caches written by other versions (pickles) stay out of this run, and in
export SDL_VIDEODRIVER=dummy MPLBACKEND=Agg
export SURVEIL_CACHE_DIR="$PWD/$VENV/cache" SB3_LOGDIR="$PWD/$VENV/sb3-logs"
# a quick subset (the whole suite passes too, in about twice the time): the env with
# PettingZoo's suites, maps and geometry, the control theory, the policies' protocol,
# loading the zoo's SB3 models, the replay writer and the CLI's error handling
"$VENV/bin/python" -m pytest -q -p no:cacheprovider -n 2 \
    tests/envs \
    tests/strategies/control \
    tests/strategies/policies/test_protocol.py \
    tests/strategies/policies/test_parameters.py \
    tests/training/test_zoo.py \
    tests/analysis/test_replay.py \
    tests/analysis/test_cli_errors.py
