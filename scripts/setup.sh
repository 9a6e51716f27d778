#!/usr/bin/env bash
# Set up a development environment in .venv (idempotent): Python >= 3.10 and pip are all
# a fresh machine needs. torch is installed first, pinned, from PyTorch's CPU index, so that
# pip takes the CPU wheel instead of pulling a multi-GB CUDA build when stable-baselines3 asks
# for torch (PyPI's Linux torch==2.13.0 is the CUDA build: a 527 MB wheel needing the
# nvidia-*-cu13 wheels). A local wheel from pip's configuration (--find-links) still counts.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
if ! .venv/bin/python -c "import torch" 2>/dev/null; then
    .venv/bin/python -m pip install --quiet --index-url https://download.pytorch.org/whl/cpu \
        "torch==2.13.0"
fi
.venv/bin/python -m pip install --quiet -e ".[all]"
echo "surveil is set up in .venv (activate with: source .venv/bin/activate)"
