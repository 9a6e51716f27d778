#!/usr/bin/env bash
# Install the CPU build of torch, pinned, into the virtualenv whose python is $1 (nothing to
# do when it already imports torch). Used by setup.sh and check_min_versions.sh before
# anything that needs torch, so that pip never picks a torch of its own.
#
# From PyTorch's CPU index when it answers (on stock PyPI, Linux torch==2.13.0 is the CUDA
# build: a 527 MB wheel that pulls the nvidia-*-cu13 wheels, several GB); otherwise from
# pip's own configuration (a machine without that index, whose pip finds a local +cpu wheel
# through --find-links). The reachability check takes at most 5 s and honours the proxy
# settings pip uses; asking pip itself to try an unreachable index costs ~75 s of retries.
set -euo pipefail
PYBIN=$1
TORCH="torch==2.13.0"
INDEX=https://download.pytorch.org/whl/cpu
if "$PYBIN" -c "import torch" 2>/dev/null; then
    exit 0
fi
if "$PYBIN" -c "import sys, urllib.request; urllib.request.urlopen(sys.argv[1] + '/torch/', timeout=5)" "$INDEX" 2>/dev/null; then
    "$PYBIN" -m pip install --quiet --index-url "$INDEX" "$TORCH"
else
    "$PYBIN" -m pip install --quiet "$TORCH"
fi
