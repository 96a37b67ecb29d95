"""A claim of the report cut into prose and formulas, and marked up as HTML.

The checks and figures state their claims as plain text with formulas written the way one types
them (the notation, and how a text is read into tokens: module ``_html_formula``). The report shows
those formulas typeset, never as raw ``_{``/``^{``: :func:`split_formulas` cuts a text into prose and
formulas, and :func:`markup` gives its HTML, each formula written by ``_html_formula.formula_html``
(plain HTML) and ``_html_formula.formula_tex`` (KaTeX source).

How a formula is found (the rules, so that a claim can be written to be read right):

* a formula is a maximal run of atoms, numbers, operators and brackets, with the spaces between
  them, that holds at least one atom and does not cross a line break; a bracket belongs to it only if
  nothing inside it is prose (nor a row of numbers such as a printed array); after a space, a
  bracket that states a relation (``(σ = 0.5, t = 30)``) starts a formula of its own; a comma belongs
  to a formula only inside such a bracket; operators at its ends (but a leading sign) and unpaired
  bars go back to the prose; a lone ``a``, ``A`` or ``I`` is prose (an article or a pronoun).

Examples
--------
>>> [kind for kind, _ in split_formulas("Chen's identity XX_{s,t} = XX_{s,u} + XX_{u,t} on paths")]
['text', 'math', 'text']
>>> split_formulas("Chen's identity XX_{s,t} = XX_{s,u} + XX_{u,t} on paths")[1][1]
'XX_{s,t} = XX_{s,u} + XX_{u,t}'
"""

from __future__ import annotations

import html
import re
import unicodedata

from ._html_formula import _BRACKETS, _OPS, _Token, _tokens, formula_html, formula_tex

__all__ = ["split_formulas", "markup"]

_RELATIONS = {"=", "≤", "≥", "<", ">", "→", "≈", "≠", "∝", "≡", "∈", "~", "<=", ">=", "->", "!="}
#: operators that may open a formula (signs, prefix operators, symbols); the others go back to the prose
_PREFIX_OPS = {"−", "-", "+", "±", "∫", "∑", "½", "√", "∂", "∇", "∞", "…", "⋯"}
#: operators that may close a formula
_SUFFIX_OPS = {"½", "∞", "…", "⋯"}
_WEAK_LETTERS = {"a", "A", "I"}
_MATH_KINDS = {"atom", "num", "op", "bar", "func"}


def _numbers_in_a_row(tokens: list[_Token], k: int) -> bool:
    """Token ``k`` is a number followed, after a space, by another: a printed array, not a formula."""
    return (tokens[k].kind == "num" and k + 2 < len(tokens) and tokens[k + 1].kind == "space"
            and (tokens[k + 2].kind == "num" or (tokens[k + 2].text in "−-" and k + 3 < len(tokens)
                                                  and tokens[k + 3].kind == "num")))


def _bracket_is_math(tokens: list[_Token], k: int) -> int:
    """If the bracket opened at ``k`` holds only formula tokens, the index of its closer; else -1."""
    depth = 0
    for j in range(k, len(tokens)):
        t = tokens[j]
        if t.kind == "open":
            depth += 1
        elif t.kind == "close":
            depth -= 1
            if depth == 0:
                return j if _BRACKETS[tokens[k].text] == t.text else -1
        elif t.kind in ("word", "other") or (t.kind == "punct" and t.text != ",") or "\n" in t.text \
                or _numbers_in_a_row(tokens, j):
            return -1
    return -1


def _holds_relation(tokens: list[_Token]) -> bool:
    """A bracket that states relations (``(σ = 0.5, t = 30)``) at its top level."""
    depth = 0
    for t in tokens:
        depth += {"open": 1, "close": -1}.get(t.kind, 0)
        if depth == 0 and t.kind == "op" and t.text in _RELATIONS:
            return True
    return False


def _span_end(tokens: list[_Token], i: int) -> int:
    """The end (exclusive) of the longest formula candidate starting at token ``i``."""
    j, n = i, len(tokens)
    while j < n:
        t = tokens[j]
        if t.kind in _MATH_KINDS:
            if _numbers_in_a_row(tokens, j):
                return j + 1
            j += 1
        elif t.kind == "open":
            close = _bracket_is_math(tokens, j)
            if close < 0:
                break
            j = close + 1
        elif t.kind == "space" and "\n" not in t.text and j + 1 < n:
            nxt = tokens[j + 1]
            if nxt.kind in _MATH_KINDS or (nxt.kind == "open" and (close := _bracket_is_math(tokens, j + 1)) >= 0
                                           and not _holds_relation(tokens[j + 2:close])):
                j += 1
            else:
                break
        else:
            break
    return j


def _trim(tokens: list[_Token], i: int, j: int) -> tuple[int, int]:
    """Give the operators at the ends (but a leading sign) and the unpaired bars back to the prose."""
    while True:
        before = (i, j)
        while j > i and (tokens[j - 1].kind == "space" or (tokens[j - 1].kind == "op" and
                                                           tokens[j - 1].text not in _SUFFIX_OPS)):
            j -= 1
        while i < j and (tokens[i].kind == "space" or (tokens[i].kind == "op" and (
                tokens[i].text not in _PREFIX_OPS or i + 1 >= j or tokens[i + 1].kind == "space"))):
            i += 1
        bars = [k for k in range(i, j) if tokens[k].kind == "bar"]
        if len(bars) % 2:
            if bars[0] == i:
                i += 1
            else:
                j = bars[-1]
        if (i, j) == before:
            return i, j


def _is_formula(tokens: list[_Token]) -> bool:
    if not any(t.kind in ("atom", "func") for t in tokens):
        return False
    return not (len(tokens) == 1 and tokens[0].text in _WEAK_LETTERS)


def split_formulas(text: str) -> list[tuple[str, str]]:
    """Cut a plain-text claim into prose and formulas (rules: see the module docstring).

    Parameters
    ----------
    text : str
        A claim, caption or note as the checks and figures write it.

    Returns
    -------
    list of ``(kind, piece)``
        ``kind`` is ``"text"`` or ``"math"``; joined, the pieces give ``text`` back (in Unicode NFC
        form), except that a lone ``x`` used as a multiplication sign comes back as ``×``.

    Examples
    --------
    >>> split_formulas("with θ = 0 (no dissipation) the law of Π_t tends to uniform")
    [('text', 'with '), ('math', 'θ = 0'), ('text', ' (no dissipation) the law of '), ('math', 'Π_t'), ('text', ' tends to uniform')]
    """
    if not isinstance(text, str):
        raise TypeError(f"text must be a str, got {type(text).__name__}: pass the claim as text.")
    tokens = _tokens(unicodedata.normalize("NFC", text))
    pieces: list[tuple[str, str]] = []

    def emit(kind, s):
        if s and pieces and pieces[-1][0] == kind:
            pieces[-1] = (kind, pieces[-1][1] + s)
        elif s:
            pieces.append((kind, s))

    i = 0
    while i < len(tokens):
        t = tokens[i]
        if t.kind in _MATH_KINDS or (t.kind == "open" and _bracket_is_math(tokens, i) >= 0):
            a, b = _trim(tokens, i, _span_end(tokens, i))
            if a < b and _is_formula(tokens[a:b]):
                emit("text", "".join(x.text for x in tokens[i:a]))
                emit("math", "".join(x.text for x in tokens[a:b]))
                i = b
                continue
        emit("text", t.text)
        i += 1
    return pieces


def markup(text: str, *, typeset: bool = True) -> str:
    """HTML of a claim: prose escaped, each formula a ``<span class="arithmatex">``.

    The span holds the formula as plain HTML (:func:`formula_html`); with ``typeset`` its
    ``data-tex`` attribute carries the KaTeX source, which the report's script typesets on load
    (the class is the one the documentation site gives its formulas). ASCII ``<=``, ``>=``, ``->``
    and ``!=`` in the prose are shown as ``≤``, ``≥``, ``→``, ``≠``.

    Examples
    --------
    >>> markup("mean 0, variance t²/4")
    'mean 0, variance <span class="arithmatex" data-tex="t^{2}/4"><i>t</i><sup>2</sup>/4</span>'
    >>> markup("defect <= 1e-10", typeset=False)
    'defect ≤ 1e-10'
    """
    parts = []
    for kind, piece in split_formulas(text):
        if kind == "text":
            parts.append(html.escape(re.sub(r"<=|>=|->|!=", lambda m: _OPS[m.group()][1], piece), quote=False))
        else:
            tex = f' data-tex="{html.escape(formula_tex(piece))}"' if typeset else ""
            parts.append(f'<span class="arithmatex"{tex}>{formula_html(piece)}</span>')
    return "".join(parts)
