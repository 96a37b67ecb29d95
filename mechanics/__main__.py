"""Main job: ``python -m mechanics`` (placeholder demo until the paper's reproduction lands)."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    import numpy as np

    import roughpaths as rp

    rng = np.random.default_rng(0)
    values = np.cumsum(rng.standard_normal((1001, 2)) * np.sqrt(1e-3), axis=0)
    X = rp.RoughPath.from_path(values, times=np.linspace(0.0, 1.0, 1001))
    coarse = X.restrict(X.times[::100])
    print(X)
    print("Lévy area over [0, 1]:", X.levy_area(0.0, 1.0)[0, 1])
    print("Chen defect of the restriction:", rp.chen_defect(X, coarse))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
