"""``python -m mechanics.paper``: the same as ``python -m mechanics``."""

import sys

from mechanics.paper.cli import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
