#!/usr/bin/env bash
# Set up a development environment in .venv (idempotent): Python >= 3.10 and pip are all
# a fresh machine needs. torch is installed first, pinned, the CPU build
# (scripts/install_torch.sh), so that pip does not pull a multi-GB CUDA build when
# stable-baselines3 asks for torch.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
bash scripts/install_torch.sh .venv/bin/python
.venv/bin/python -m pip install --quiet -e ".[all]"
echo "surveil is set up in .venv (activate with: source .venv/bin/activate)"
