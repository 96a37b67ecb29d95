"""Every compiled kernel of the library is compiled under one set of numba flags (``docs/architecture.md``).

Claim: each ``njit`` in ``roughpaths`` and ``mechanics`` either is inlined (``inline="always"``: compiled
inside its callers) or has ``cache=True``, ``nogil=True`` and ``no_cfunc_wrapper=True`` (written out or
through a module-level ``dict(...)`` it unpacks). numba compiles the implementations of numpy functions
(``np.empty`` and the like) once per flag set, so kernels under mixed flags compile them again on a first
call; the cfunc wrapper (for first-class function use, which no kernel here has) is lowered and optimised
for every kernel. Read with :mod:`ast`: nothing is imported or compiled.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REQUIRED = {"cache": True, "nogil": True, "no_cfunc_wrapper": True}


def _keywords(call: ast.Call, dicts: dict) -> dict:
    out = {}
    for kw in call.keywords:
        if kw.arg is None:                                   # **NAME: a module-level dict(...)
            if isinstance(kw.value, ast.Name) and kw.value.id in dicts:
                out.update(dicts[kw.value.id])
            else:
                out["**"] = ast.unparse(kw.value)
        elif isinstance(kw.value, ast.Constant):
            out[kw.arg] = kw.value.value
        else:
            out[kw.arg] = ast.unparse(kw.value)
    return out


def flag_problems(source: str, where: str) -> list:
    """The ``njit`` calls of ``source`` that are neither inlined nor compiled under :data:`REQUIRED`."""
    tree = ast.parse(source)
    dicts = {}
    for node in tree.body:
        if (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)
                and isinstance(node.value, ast.Call) and getattr(node.value.func, "id", None) == "dict"):
            dicts[node.targets[0].id] = _keywords(node.value, {})
    bad = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        name = f.id if isinstance(f, ast.Name) else (f.attr if isinstance(f, ast.Attribute) else None)
        if name != "njit":
            continue
        kws = _keywords(node, dicts)
        if kws.get("inline") == "always":
            continue
        if any(kws.get(k) != v for k, v in REQUIRED.items()):
            bad.append(f"{where}:{node.lineno}: njit({', '.join(f'{k}={v!r}' for k, v in kws.items())})")
    return bad


def test_every_kernel_has_the_library_flags():
    bad = []
    for pkg in ("roughpaths", "mechanics"):
        for path in sorted((ROOT / pkg).rglob("*.py")):
            bad += flag_problems(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))
    assert not bad, "kernels outside the library's flag set:\n" + "\n".join(bad)


def test_the_check_can_fail():
    src = ("from numba import njit\n_F = dict(cache=True, nogil=True, no_cfunc_wrapper=True)\n"
           "@njit(cache=True)\ndef a(x):\n    return x\n"
           "@njit(**_F)\ndef b(x):\n    return x\n"
           "@njit(cache=True, inline='always')\ndef c(x):\n    return x\n"
           "@njit(cache=True, nogil=True, no_cfunc_wrapper=True)\ndef e(x):\n    return x\n")
    bad = flag_problems(src, "m.py")
    assert len(bad) == 1 and bad[0].startswith("m.py:3:")
