"""Main job: ``python -m mechanics`` (also the console script ``levy-area-paper``).

Reproduces the paper's figures and theorem checks; the application lives in :mod:`mechanics.paper`
(see :mod:`mechanics.paper.cli` and ``--help``).
"""

from __future__ import annotations

import sys

from mechanics.paper.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
