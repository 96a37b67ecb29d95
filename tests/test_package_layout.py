"""The library's layout rules (``docs/architecture.md``), read from the code's own imports.

* No import circle between library modules, counting imports inside functions.
* A private name (``_x``, or anything reached through a ``_module``) is used only inside the package
  that holds it; ``mechanics`` reaches ``roughpaths`` only through the package itself and its public
  modules ``roughpaths.validation`` and ``roughpaths.io``.
* No library module is over 500 lines.
* No library code warns of deprecation: this project keeps no deprecated shims.

The imports are read with :mod:`ast` (nothing is executed), so a test module's own oracle cannot hide
what the code does.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("roughpaths", "mechanics")
MAX_LINES = 500
ROUGHPATHS_DOORS = ("roughpaths", "roughpaths.validation", "roughpaths.io")


def _modules() -> dict:
    """Dotted name -> (path, is_package) of every library module."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            if is_pkg:
                parts = parts[:-1]
            out[".".join(parts)] = (path, is_pkg)
    return out


MODULES = _modules()


def _imports(name: str) -> list:
    """``(line, target module, imported name or None)`` for every import statement of module ``name``."""
    path, is_pkg = MODULES[name]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name, None) for a in node.names if a.name.split(".")[0] in PACKAGES]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[:len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] not in PACKAGES:
                continue
            for a in node.names:
                sub = f"{target}.{a.name}"
                if sub in MODULES and not _defines(target, a.name):
                    found.append((node.lineno, sub, None))
                else:
                    found.append((node.lineno, target, a.name))
    return found


def _defines(module: str, attr: str) -> bool:
    """Whether the package ``module``'s ``__init__`` binds ``attr`` itself (an exported function named like a submodule)."""
    path, is_pkg = MODULES.get(module, (None, False))
    if not is_pkg:
        return False
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.ImportFrom) and node.module and any((a.asname or a.name) == attr for a in node.names):
            return True
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and node.name == attr:
            return True
    return False


def _graph() -> dict:
    return {m: sorted({t for _, t, _ in _imports(m) if t in MODULES and t != m}) for m in MODULES}


def _cycles(graph: dict) -> list:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_circles():
    assert _cycles(_graph()) == []


def _owner_of_private(target: str, attr) -> str | None:
    """The package a private thing belongs to, or None if ``target.attr`` is public."""
    parts = target.split(".")
    for k, part in enumerate(parts):
        if part.startswith("_") and not part.startswith("__"):
            return ".".join(parts[:k])
    if attr is not None and attr.startswith("_") and not attr.startswith("__"):
        _, is_pkg = MODULES.get(target, (None, False))
        return target if is_pkg else ".".join(parts[:-1])
    return None


def _violations() -> list:
    bad = []
    for name in MODULES:
        for line, target, attr in _imports(name):
            where = f"{MODULES[name][0].relative_to(ROOT)}:{line}"
            what = target + (f".{attr}" if attr else "")
            owner = _owner_of_private(target, attr)
            if owner is not None and not (name == owner or name.startswith(owner + ".")):
                bad.append(f"{where} uses the private {what} (private to {owner})")
            if name.startswith("mechanics") and target.startswith("roughpaths") and target not in ROUGHPATHS_DOORS:
                bad.append(f"{where} reaches into {target}: import it from roughpaths")
    return bad


def test_private_names_stay_in_their_package():
    assert _violations() == []


def test_no_library_module_over_500_lines():
    long = {n: len(p.read_text(encoding="utf-8").splitlines()) for n, (p, _) in MODULES.items()}
    assert {n: k for n, k in long.items() if k > MAX_LINES} == {}


def test_no_deprecation_shims_in_library_code():
    hits = [f"{p.relative_to(ROOT)}" for p, _ in MODULES.values() if "DeprecationWarning" in p.read_text(encoding="utf-8")]
    assert hits == []


@pytest.mark.parametrize("name", ["roughpaths", "mechanics"])
def test_public_names_resolve(name):
    """Every name in a package's ``__all__`` (top level and subpackages) is importable from it."""
    import importlib

    for mod in [m for m, (_, is_pkg) in MODULES.items() if is_pkg and m.split(".")[0] == name]:
        module = importlib.import_module(mod)
        missing = [n for n in getattr(module, "__all__", []) if not hasattr(module, n)]
        assert missing == [], (mod, missing)


def test_the_checks_can_fail(tmp_path, monkeypatch):
    """The circle finder and the private-name rule catch a planted violation."""
    assert _cycles({"a": ["b"], "b": ["c"], "c": ["a"], "d": ["a"]}) == [["a", "b", "c"]]
    assert _owner_of_private("roughpaths.signatures._lanes", None) == "roughpaths.signatures"
    assert _owner_of_private("roughpaths.algebra.tensor", "_offsets") == "roughpaths.algebra"
    assert _owner_of_private("roughpaths.validation", "as_float_array") is None
