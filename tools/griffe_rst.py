"""Griffe extension: render the library's reStructuredText docstring markup as Markdown at build time.

The library's docstrings are numpydoc with Sphinx-style reStructuredText inside (``:math:`…```,
``:class:`~a.B```, ``.. math::`` blocks …), which Python-Markdown shows verbatim. mkdocstrings loads
this extension (``extensions:`` in ``mkdocs.yml``); once a package is loaded it rewrites every
docstring's text, before mkdocstrings parses the numpydoc sections:

* ``:math:`x``` becomes ``$x$`` and a ``.. math::`` directive becomes a ``$$ … $$`` block (one per
  blank-line-separated equation; an equation with ``\\`` line breaks and no environment of its own is
  wrapped in ``aligned``, as Sphinx wraps it in ``split``). ``pymdownx.arithmatex`` (generic mode)
  turns both into ``\\( … \\)`` / ``\\[ … \\]`` spans that KaTeX typesets in the browser
  (``docs/javascripts/katex.js``).
* A bullet-list item's further blocks and nested lists are re-indented from RST's 2 columns to
  Markdown's 4.
* On the entry lines of typed numpydoc sections (``name : type`` in Parameters, Returns, Raises …),
  which mkdocstrings shows verbatim in the type column, a role becomes its plain text and a
  double-backtick literal loses its backticks.
* ``:class:``, ``:func:``, ``:meth:``, ``:attr:``, ``:mod:``, ``:data:``, ``:exc:``, ``:obj:`` and
  ``:const:`` become mkdocs-autorefs links: the target is resolved in the docstring's scope (as Sphinx
  does), then to its canonical path (where it is defined, which is where mkdocstrings renders it).
  ``~`` shows the last component only; functions and methods get ``()``. A target outside the two
  packages (``numpy.random.Generator``) or one that cannot be resolved is shown as code, not linked.

The library's docstrings stay the single source; nothing here is needed to read them in a terminal.
"""

from __future__ import annotations

import html
import importlib
import inspect
import re
from typing import Any

import griffe

__all__ = ["RstToMarkdown", "convert", "math_directives_to_markdown", "rst_lists_to_markdown"]

_PACKAGES = ("roughpaths", "mechanics")
_XREF_ROLES = ("class", "func", "meth", "attr", "mod", "data", "exc", "obj", "const")
_ROLE_RE = re.compile(r":(?:py:)?(?P<role>math|" + "|".join(_XREF_ROLES) + r"):`(?P<body>[^`]+)`", re.S)
_DIRECTIVE_RE = re.compile(r"^(?P<indent>[ \t]*)\.\. math::[ \t]*(?P<rest>.*)$")
_ENV_RE = re.compile(r"\\begin\{")


def math_directives_to_markdown(text: str) -> str:
    """Replace every ``.. math::`` directive in ``text`` by ``$$`` blocks at the directive's indentation."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        m = _DIRECTIVE_RE.match(lines[i])
        if not m:
            out.append(lines[i])
            i += 1
            continue
        indent = m["indent"]
        body = [m["rest"]] if m["rest"].strip() else []
        i += 1
        # The directive's argument and content: every following line indented deeper, or blank.
        while i < len(lines) and (not lines[i].strip() or _indent(lines[i]) > len(indent)):
            body.append(lines[i])
            i += 1
        # Trailing blank lines belong to the text after the directive.
        trailing = 0
        while body and not body[-1].strip():
            body.pop()
            trailing += 1
        equations: list[list[str]] = [[]]
        for line in body:
            if line.strip().startswith(":") and line.strip().split(":")[1] in ("label", "nowrap"):
                continue  # directive options: no meaning here
            if line.strip():
                equations[-1].append(line.strip())
            elif equations[-1]:
                equations.append([])
        for eq in (e for e in equations if e):
            tex = "\n".join(eq)
            if "\\\\" in tex and not _ENV_RE.search(tex):
                tex = "\\begin{aligned}\n" + tex + "\n\\end{aligned}"
            if out and out[-1].strip():
                out.append("")
            out += [indent + "$$", *(indent + t for t in tex.split("\n")), indent + "$$", ""]
        if out and not out[-1].strip():
            out.pop()
        out += [""] * max(trailing, 1) if i < len(lines) else []
    return "\n".join(out)


_BULLET_RE = re.compile(r"^(?P<indent>[ \t]*)[*+-] \S")


def rst_lists_to_markdown(text: str) -> str:
    """Re-indent RST bullet lists for Markdown: an item's further blocks and nested lists by 4 columns.

    In RST, an item's further paragraphs, ``$$`` blocks and nested lists are indented to the item's
    text, two columns past the bullet; Python-Markdown keeps a block in the item only when it is
    indented four columns, and otherwise ends the list and shows the block as a paragraph (or, past
    four columns, as code).
    """
    out: list[str] = []
    stack: list[tuple[int, int]] = []  # (RST indentation of an open item's bullet, shift of its content)
    for line in text.split("\n"):
        if not line.strip():
            out.append(line)
            continue
        ind = _indent(line)
        bullet = _BULLET_RE.match(line) is not None
        while stack and ind <= stack[-1][0] and not (bullet and ind == stack[-1][0]):
            stack.pop()
        if bullet and stack and ind == stack[-1][0]:
            stack.pop()  # a sibling item closes the previous one
        shift = stack[-1][1] if stack else 0
        out.append(" " * shift + line)
        if bullet:
            stack.append((ind, shift + 2))
    return "\n".join(out)


_SECTION_RE = re.compile(r"^(?P<indent>[ \t]*)(?P<title>\S[^\n]*?)[ \t]*\n(?P=indent)-{3,}[ \t]*$", re.M)
# numpydoc sections whose lines at the section's own indentation are "name : type" entries, which
# mkdocstrings shows verbatim (not as Markdown) in the type column.
_TYPED_SECTIONS = {"parameters", "other parameters", "returns", "yields", "receives", "raises", "warns",
                   "attributes"}


def _type_line_spans(text: str) -> list[tuple[int, int]]:
    """Character ranges of the entry lines ("name : type") of the typed numpydoc sections."""
    spans = []
    headers = list(_SECTION_RE.finditer(text))
    for k, h in enumerate(headers):
        if h["title"].strip().lower() not in _TYPED_SECTIONS:
            continue
        body_start = text.index("\n", h.end() - 1) + 1 if "\n" in text[h.end() - 1:] else len(text)
        body_end = headers[k + 1].start() if k + 1 < len(headers) else len(text)
        pos = body_start
        for line in text[body_start:body_end].split("\n"):
            if line.strip() and _indent(line) == len(h["indent"]):
                spans.append((pos, pos + len(line)))
            pos += len(line) + 1
    return spans


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" \t"))


def _canonical(path: str, module: bool = False) -> str | None:
    """The canonical dotted path of the object ``path`` names (where it is defined), or ``None``.

    Names are looked up as Python does, attribute by attribute from the top-level package, so
    ``roughpaths.solve`` is the function the package exports, not the submodule of the same name;
    with ``module=True`` (the ``:mod:`` role) a module of that name is preferred.
    """
    if module:
        try:
            return importlib.import_module(path).__name__
        except Exception:  # noqa: BLE001 - not a module: fall back to attribute lookup
            pass
    parts = path.split(".")
    # Attribute by attribute from the top-level package first, then from the longest importable
    # module prefix (``roughpaths.logsignature``: the package exports a function
    # ``signature`` that hides the submodule).
    for k in (1, *range(len(parts), 1, -1)):
        try:
            start: Any = importlib.import_module(".".join(parts[:k]))
        except Exception:  # noqa: BLE001 - a module that fails to import cannot be linked
            continue
        canon = _walk(start, parts[k:])
        if canon is not None:
            return canon
    return None


def _walk(obj: Any, names: list[str]) -> str | None:
    canon = obj.__name__
    for name in names:
        try:
            obj = inspect.getattr_static(obj, name)
        except AttributeError:
            if inspect.isclass(obj) and any(name in getattr(c, "__annotations__", {}) for c in obj.__mro__):
                canon = f"{canon}.{name}"  # a dataclass field or annotated instance attribute
                obj = None
                continue
            if not inspect.ismodule(obj):
                return None
            try:
                obj = importlib.import_module(f"{obj.__name__}.{name}")
            except Exception:  # noqa: BLE001
                return None
        target = getattr(obj, "__func__", obj)  # classmethod / staticmethod
        target = getattr(target, "fget", target)  # property
        mod, qual = getattr(target, "__module__", None), getattr(target, "__qualname__", None)
        if inspect.ismodule(obj):
            canon = obj.__name__
        elif (isinstance(mod, str) and isinstance(qual, str) and "<" not in qual
              and (inspect.isclass(target) or inspect.isfunction(target))):
            canon = f"{mod}.{qual}"
        else:
            canon = f"{canon}.{name}"
    return canon


def _resolve(obj: griffe.Object, target: str, module: bool = False) -> str | None:
    """Resolve ``target`` as written in ``obj``'s docstring to a canonical path, or ``None``."""
    target = target.lstrip(".")
    head, _, rest = target.partition(".")
    candidates = []
    scope: griffe.Object | None = obj
    while scope is not None:  # the docstring's scope, then its parents (Sphinx's lookup order)
        try:
            candidates.append(scope.resolve(head) + (f".{rest}" if rest else ""))
            break
        except (griffe.NameResolutionError, AttributeError, KeyError):
            scope = scope.parent
    if head in _PACKAGES or head in ("numpy", "scipy", "matplotlib", "numba"):
        candidates.append(target)
    if obj.is_class or obj.is_module:
        candidates.append(f"{obj.path}.{target}")
    if obj.parent is not None:
        candidates.append(f"{obj.parent.path}.{target}")
    for cand in candidates:
        canon = _canonical(cand, module)
        if canon is not None:
            return canon
    return None


def convert(text: str, obj: griffe.Object | None = None) -> str:
    """Convert the RST roles and ``.. math::`` directives in ``text`` (the docstring of ``obj``)."""
    text = rst_lists_to_markdown(math_directives_to_markdown(text))
    type_lines = _type_line_spans(text)

    def role(m: re.Match) -> str:
        kind, body = m["role"], " ".join(m["body"].split())
        in_type = any(a <= m.start() < b for a, b in type_lines)
        if kind == "math":
            return body if in_type else f"${body}$"
        explicit = re.fullmatch(r"(?P<title>.+?)\s*<(?P<target>[^<>]+)>", body)
        if explicit:
            title, target = explicit["title"], explicit["target"]
        else:
            target = body.lstrip("!")
            short = target.startswith("~")
            target = target.lstrip("~")
            title = target.rsplit(".", 1)[-1] if short else target
            if kind in ("func", "meth") and not title.endswith(")"):
                title += "()"
        target = target.removesuffix("()")
        path = _resolve(obj, target, kind == "mod") if obj is not None else None
        if in_type:  # shown verbatim: plain words, no markup
            return title
        code = f"<code>{html.escape(title)}</code>"
        if path is None or path.split(".")[0] not in _PACKAGES:
            return code
        return f'<autoref identifier="{html.escape(path)}" optional>{code}</autoref>'

    text = _ROLE_RE.sub(role, text)
    # The type column is verbatim too: drop the double backticks of RST literals there.
    parts, last = [], 0
    for a, b in _type_line_spans(text):
        parts += [text[last:a], text[a:b].replace("``", "")]
        last = b
    return "".join(parts) + text[last:]


class RstToMarkdown(griffe.Extension):
    """Rewrite the docstrings of a loaded package from reStructuredText markup to Markdown."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        seen: set[int] = set()
        stack: list[griffe.Object] = [pkg]
        while stack:
            obj = stack.pop()
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            if obj.docstring is not None:
                obj.docstring.value = convert(obj.docstring.value, obj)
            stack.extend(m for m in obj.members.values() if not m.is_alias)
