#!/usr/bin/env bash
# Set up a development environment in .venv (idempotent): Python >= 3.10 and pip are all
# a fresh machine needs. torch is installed first, pinned, so that pip takes the CPU wheel
# instead of pulling a multi-GB CUDA build when stable-baselines3 asks for torch.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
if ! .venv/bin/python -c "import torch" 2>/dev/null; then
    .venv/bin/python -m pip install --quiet "torch==2.13.0"
fi
.venv/bin/python -m pip install --quiet -e ".[all]"
echo "surveil is set up in .venv (activate with: source .venv/bin/activate)"
