"""``import roughpaths`` never imports torch or jax.

The front ends ``roughpaths.torch`` and ``roughpaths.jax`` are opt-in: a fresh interpreter that imports
the packages (and calls a signature) must not have loaded either framework, which would cost seconds of
start-up and make the extras mandatory.
"""

import subprocess
import sys

CODE = """
import sys
import numpy as np
import roughpaths
roughpaths.signature(np.zeros((3, 2)), 2)
print(sorted(m for m in ("torch", "jax", "jaxlib") if m in sys.modules))
"""


def test_import_roughpaths_loads_no_framework():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]", out.stdout
