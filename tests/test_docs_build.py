"""The documentation site builds with ``mkdocs build --strict`` (no warning tolerated).

Claim: every page, cross-reference, included tutorial file and API reference (mkdocstrings from the
numpydoc docstrings) resolves. Skipped, with the reason, when mkdocs or its plugins are not
installed (they are in the ``docs`` extra: ``pip install -e ".[docs]"``).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_mkdocs_build_strict(tmp_path):
    missing = [m for m in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")
               if importlib.util.find_spec(m.split(".")[0]) is None
               or (m.count(".") and importlib.util.find_spec(m) is None)]
    if missing and os.environ.get("CI"):
        pytest.fail(f"docs toolchain not installed in CI ({', '.join(missing)}); ./test.sh installs the "
                    f"docs extra, so the strict build must run there.")
    if missing:
        pytest.skip(f"docs toolchain not installed ({', '.join(missing)}); install the docs extra: "
                    f"pip install -e '.[docs]'")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                          cwd=ROOT, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"}, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert (tmp_path / "site" / "index.html").exists()
