"""The mechanics package keeps its import rules (``docs/architecture.md``, issue "One house").

Claims, checked on the source by resolving every ``import`` / ``from ... import`` in ``mechanics/``,
module-level and function-level alike:

* no import circle between modules;
* a private name (``_x``) or a private module is imported only inside its own subpackage;
* ``roughpaths`` is used only through its public top level and ``roughpaths.validation`` /
  ``roughpaths.io``;
* the library never imports the paper's application (``mechanics.paper``);
* no module is over 500 lines, no library code raises a ``DeprecationWarning``, and no doctest
  imports a ``roughpaths`` submodule other than ``validation`` / ``io``.

The checker also finds the former ``equilibria`` <-> ``phase_portrait`` circle and the former
``roughpaths.coloured_noise`` imports when run on the old layout, so the test can fail.
"""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PKG = ROOT / "mechanics"
PUBLIC_ROUGHPATHS = ("roughpaths", "roughpaths.validation", "roughpaths.io")


def _modules():
    mods = {}
    for p in PKG.rglob("*.py"):
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        mods[".".join(parts[:-1] if is_pkg else parts)] = (p, is_pkg)
    return mods


def _subpackage(name, is_pkg):
    parts = name.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and is_pkg) else None


def _imports(mods):
    """Yield ``(module, base, name)`` for every import statement (``name`` None for ``import x``)."""
    for mod, (path, is_pkg) in mods.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                for a in node.names:
                    yield mod, a.name, None
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = mod.split(".")[: None if is_pkg else -1]
                    base = base[: len(base) - (node.level - 1)]
                    base = ".".join(base + ([node.module] if node.module else []))
                else:
                    base = node.module
                for a in node.names:
                    yield mod, base, a.name


def _graph_and_problems():
    mods = _modules()
    edges = {m: set() for m in mods}
    problems = []
    for mod, base, name in _imports(mods):
        if base.split(".")[0] == "roughpaths":
            if base not in PUBLIC_ROUGHPATHS or (name or "").startswith("_"):
                problems.append(f"{mod}: non-public roughpaths import {base} {name or ''}")
            continue
        if base.split(".")[0] != "mechanics":
            continue
        target = f"{base}.{name}" if name and f"{base}.{name}" in mods else base
        assert target in mods, f"{mod}: cannot resolve {base} {name}"
        edges[mod].add(target)
        here, there = _subpackage(mod, mods[mod][1]), _subpackage(target, mods[target][1])
        private_module = any(p.startswith("_") and p not in ("__init__", "__main__") for p in target.split("."))
        if ((name or "").startswith("_") or private_module) and name != "__version__" and here != there:
            problems.append(f"{mod}: private {name or target} of {target} used outside its subpackage")
        if target.startswith("mechanics.paper") and not mod.startswith(("mechanics.paper", "mechanics.__main__")):
            problems.append(f"{mod}: library code imports the paper ({target})")
    return edges, problems


def _cycles(edges):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
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
            if len(comp) > 1 or v in edges[v]:
                out.append(sorted(comp))

    for v in edges:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    edges, _ = _graph_and_problems()
    assert sum(map(len, edges.values())) > 50          # the resolver sees the package's imports
    assert _cycles(edges) == []


def test_private_names_roughpaths_and_paper_boundaries():
    _, problems = _graph_and_problems()
    assert problems == []


def test_module_size_and_no_deprecation_warnings():
    doctest_import = re.compile(r">>> (?:from|import) roughpaths\.(?!(?:validation|io)\b)")
    for path in PKG.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        assert not doctest_import.search(text), f"{path.relative_to(ROOT)}: a doctest imports a roughpaths submodule"
        assert text.count("\n") <= 500, f"{path.relative_to(ROOT)} has {text.count(chr(10))} lines"
        assert "DeprecationWarning" not in text, path.relative_to(ROOT)
