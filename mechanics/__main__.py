"""Main job: ``python -m mechanics`` (also the console script ``levy-area-paper``).

Reproduces the paper's figures and theorem checks; see :mod:`mechanics.cli` and ``--help``.
"""

from __future__ import annotations

import sys

from .cli import main

__all__ = ["main"]

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
