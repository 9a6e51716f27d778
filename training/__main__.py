"""``python -m training CONFIG ...``: the same as ``surveil train`` (see :mod:`training.cli`)."""

from __future__ import annotations

import sys

from training.cli import cli_train

if __name__ == "__main__":
    sys.exit(cli_train())
