r"""One formula of the report's claims, written as KaTeX source and as plain HTML.

The checks and figures state their claims as plain text in which formulas are written the way one
types them: Unicode symbols (``σ²``, ``A⁻¹D``, ``h̃ = ½Π·𝕀⁻¹Π``, ``E[ΠΠᵀ] → I/3``) mixed with
TeX-style scripts (``XX_{s,t}``, ``s^{ij}``, ``X^i_s``, ``Ad*_{exp σ_n}``, ``h^1.5``). Such a text is
read into tokens, each carrying its KaTeX source and its HTML, and a formula is written twice: by
:func:`formula_tex` (KaTeX source) and by :func:`formula_html` (HTML with ``<i>``, ``<sub>``, ``<sup>``:
what a reader sees where KaTeX is not available or JavaScript does not run). A braced script
(``X_{s,u}``) is a formula of its own, written by the same two functions. Where the formulas stand in
a claim is decided from the same tokens, in module ``_html_markup``.

How a text is read (the rules, so that a claim can be written to be read right):

* tokens: prose words (Latin letter runs that look like words: two lowercase letters in a row, as in
  ``rough``, ``Chen's``, ``LevyArea``, ``Lie–Heun``, or capitals only, as in ``SE``; also file names,
  dotted or underscored identifiers such as ``levy_area``, calls such as ``so(3)`` and
  ``--options``), math atoms (a single Latin or Greek letter, ``𝕀``, ``𝐗``, ``ℓ``, ``h̃``, ``XX``, a
  letter run that is not a word such as ``kI``, a differential ``dt``, anything carrying a script
  ``_``/``^``/``*``/Unicode super- or subscript; digits right after a single letter are its index:
  ``s13`` is s₁₃), numbers, operators, brackets, bars.
* a lone ``x`` between spaces, after a number, word or bracket and before a number or symbol, is a
  multiplication sign (``32 paths x 100 steps``) and is shown as ``×``.

Examples
--------
>>> formula_tex("XX_{s,t} = XX_{s,u} + X_{s,u} ⊗ X_{u,t}")
'XX_{s,t} = XX_{s,u} + X_{s,u} \\otimes X_{u,t}'
>>> formula_tex("h̃ = ½Π·𝕀⁻¹Π + c·Π")
'\\tilde{h} = \\tfrac{1}{2}\\Pi\\cdot\\mathbb{I}^{-1}\\Pi + c\\cdot\\Pi'
>>> formula_html("s^{ij}")
'<i>s</i><sup><i>ij</i></sup>'
"""

from __future__ import annotations

import html
import re
import unicodedata
from dataclasses import dataclass, field

__all__ = ["formula_tex", "formula_html"]

# ------------------------------------------------------------------------------------------ symbols
_GREEK = {
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "ε": "varepsilon", "ϵ": "epsilon", "ζ": "zeta",
    "η": "eta", "θ": "theta", "ϑ": "vartheta", "ι": "iota", "κ": "kappa", "λ": "lambda", "μ": "mu", "ν": "nu",
    "ξ": "xi", "π": "pi", "ρ": "rho", "σ": "sigma", "τ": "tau", "υ": "upsilon", "φ": "varphi", "ϕ": "phi",
    "χ": "chi", "ψ": "psi", "ω": "omega", "Γ": "Gamma", "Δ": "Delta", "Θ": "Theta", "Λ": "Lambda", "Ξ": "Xi",
    "Π": "Pi", "Σ": "Sigma", "Υ": "Upsilon", "Φ": "Phi", "Ψ": "Psi", "Ω": "Omega",
}
#: letter-like symbols outside the Mathematical Alphanumeric Symbols block
_LETTERLIKE = {"ℓ": (r"\ell", "ℓ"), "ℝ": (r"\mathbb{R}", "ℝ"), "ℕ": (r"\mathbb{N}", "ℕ"),
               "ℤ": (r"\mathbb{Z}", "ℤ"), "ℂ": (r"\mathbb{C}", "ℂ"), "ℚ": (r"\mathbb{Q}", "ℚ")}
#: styles of the Mathematical Alphanumeric Symbols (U+1D400..U+1D7FF), by their Unicode names
_MATH_STYLES = (("DOUBLE-STRUCK", "mathbb"), ("BOLD SCRIPT", "mathcal"), ("SCRIPT", "mathcal"),
                ("BOLD FRAKTUR", "mathfrak"), ("FRAKTUR", "mathfrak"), ("SANS-SERIF", "mathsf"),
                ("MONOSPACE", "mathtt"), ("BOLD ITALIC", "boldsymbol"), ("BOLD", "mathbf"), ("ITALIC", ""))
_SUPERSCRIPTS = dict(zip("⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻⁼⁽⁾ⁱⁿᵀ", "0123456789+-=()inT"))
_SUBSCRIPTS = dict(zip("₀₁₂₃₄₅₆₇₈₉₊₋₌₍₎ₐₑₒₓᵢⱼₖₙₜ", "0123456789+-=()aeoxijknt"))
_COMBINING = {"\u0303": "tilde", "\u0302": "hat", "\u0304": "bar", "\u0307": "dot", "\u20d7": "vec"}
#: operators: text form -> (TeX, HTML)
_OPS = {
    "<=": (r"\le", "≤"), ">=": (r"\ge", "≥"), "->": (r"\to", "→"), "!=": (r"\neq", "≠"), "..": ("..", ".."),
    "=": ("=", "="), "+": ("+", "+"), "−": ("-", "−"), "-": ("-", "−"), "×": (r"\times", "×"),
    "⊗": (r"\otimes", "⊗"), "·": (r"\cdot", "·"), "∝": (r"\propto", "∝"), "≤": (r"\le", "≤"), "≥": (r"\ge", "≥"),
    "<": ("<", "&lt;"), ">": (">", "&gt;"), "→": (r"\to", "→"), "≈": (r"\approx", "≈"), "≠": (r"\neq", "≠"),
    "±": (r"\pm", "±"), "/": ("/", "/"), "∫": (r"\int", "∫"), "∑": (r"\sum", "∑"), "½": (r"\tfrac{1}{2}", "½"),
    "∈": (r"\in", "∈"), "∞": (r"\infty", "∞"), "∂": (r"\partial", "∂"), "∇": (r"\nabla", "∇"), "√": (r"\surd", "√"),
    "~": (r"\sim", "~"), "≡": (r"\equiv", "≡"), "∘": (r"\circ", "∘"), "…": (r"\dots", "…"), "⋯": (r"\cdots", "⋯"),
}
_BARS = {"|": ("|", "|"), "‖": (r"\|", "‖")}
_FUNCS = {"exp": r"\exp", "log": r"\log", "det": r"\det", "sin": r"\sin", "cos": r"\cos", "max": r"\max",
          "min": r"\min", "diag": r"\operatorname{diag}", "Alt": r"\operatorname{Alt}",
          "skew": r"\operatorname{skew}", "tr": r"\operatorname{tr}", "Sym": r"\operatorname{Sym}"}
#: operator names written with a star and a subscript (the coadjoint actions Ad*_g, ad*_ξ)
_STARRED = {"Ad": r"\operatorname{Ad}", "ad": r"\operatorname{ad}"}
_DIFFERENTIALS = {"dt", "ds", "dx", "dy", "dB", "dW", "dX", "dY", "dZ"}
_BRACKETS = {"(": ")", "[": "]", "{": "}"}
_CLOSERS = set(_BRACKETS.values())
_DIGITS = "0123456789"

_LATIN = "A-Za-zÀ-ÖØ-öø-ɏ"
_WORD_RE = re.compile(rf"[{_LATIN}][{_LATIN}\u0300-\u036f\u20d7]*")
_CODE_RE = re.compile(rf"[{_LATIN}][{_LATIN}0-9]*(?:[._/][{_LATIN}][{_LATIN}0-9]*)+")
_OPTION_RE = re.compile(r"--[a-z][a-z0-9-]*")
_NUMBER_RE = re.compile(r"\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_WORD_TAIL_RE = re.compile(rf"(?:['’]s\b|[-–][{_LATIN}0-9]+)*")
_SCRIPT_WORD_RE = re.compile(rf"[-−+]?\d+(?:\.\d+)?|[{_LATIN}\u0391-\u03c90-9]+")


def _join_tex(pieces) -> str:
    """Concatenate TeX pieces, with a space where a command would run into a letter (``\\otimes X``)."""
    out = ""
    for piece in pieces:
        if out and piece and re.search(r"\\[A-Za-z]+$", out) and re.match(r"[A-Za-z]", piece):
            out += " "
        out += piece
    return out


def _word_like(run: str) -> bool:
    """A run of Latin letters read as a prose word (``rough``, ``Chen``, ``LevyArea``, ``SE``), not as
    symbols (``kI``, ``dX``, ``XX``, the differentials ``dt``, ``dB``)."""
    if len(run) < 2 or run in _DIFFERENTIALS:
        return False
    if len(set(run)) == 1 and run[0].isupper():
        return False  # XX: the area of a rough path
    return bool(re.search(r"[a-zß-öø-ɏ]{2}", run) or re.fullmatch(r"[A-Z]{2,}", run))


# ------------------------------------------------------------------------------------------- tokens
@dataclass
class _Atom:
    """A symbol with its scripts: ``tex``/``html`` of the base; ``sub``/``sup`` lists of (TeX, HTML)."""

    tex: str
    html: str
    sub: list = field(default_factory=list)
    sup: list = field(default_factory=list)

    def render(self, which: int) -> str:
        out = (self.tex, self.html)[which]
        for scripts, tag, mark in ((self.sub, "sub", "_"), (self.sup, "sup", "^")):
            if scripts:
                inner = _join_tex(s[0] for s in scripts) if which == 0 else "".join(s[1] for s in scripts)
                out += f"{mark}{{{inner}}}" if which == 0 else f"<{tag}>{inner}</{tag}>"
        return out


@dataclass
class _Token:
    kind: str      # space, word, atom, num, op, bar, open, close, punct, func, other
    text: str      # the original text
    value: object = None   # _Atom for atoms; (TeX, HTML) for the others that can stand in a formula


def _symbol(ch: str) -> tuple[str, str] | None:
    """(TeX, HTML) of a one-character letter symbol, or None."""
    if ch in _GREEK:
        return "\\" + _GREEK[ch], ch if ch.isupper() else f"<i>{ch}</i>"
    if ch in _LETTERLIKE:
        return _LETTERLIKE[ch]
    if "\U0001d400" <= ch <= "\U0001d7ff":
        name = unicodedata.name(ch, "")
        m = re.search(r"(CAPITAL|SMALL) ([A-Z])$", name)
        if m:
            letter = m.group(2) if m.group(1) == "CAPITAL" else m.group(2).lower()
            for style, command in _MATH_STYLES:
                if style in name:
                    return (rf"\{command}{{{letter}}}" if command else letter), ch
        return None
    if re.fullmatch(rf"[{_LATIN}]", ch):
        return ch, f"<i>{ch}</i>"
    return None


def _letter_atom(ch: str, combining: str = "") -> _Atom:
    tex, shown = _symbol(ch)
    for mark in combining:
        if mark in _COMBINING:
            tex, shown = rf"\{_COMBINING[mark]}{{{tex}}}", shown.replace(ch, ch + mark)
    return _Atom(tex, shown)


def _script_text(s: str) -> tuple[str, str]:
    """A script written without braces: a number, an index (``i``, ``ij``) or a word (``col``, ``Itô``)."""
    if re.fullmatch(r"[-−+]?\d+(?:\.\d+)?", s):
        return s.replace("−", "-"), s.replace("-", "−")
    if len(s) >= 3 and re.fullmatch(rf"[{_LATIN}]+", s) and _word_like(s):
        return rf"\text{{{s}}}", html.escape(s)
    parts = [_Atom(ch, ch) if ch in _DIGITS else _letter_atom(ch) if _symbol(ch)
             else _Atom(rf"\text{{{_tex_text(ch)}}}", html.escape(ch)) for ch in s]
    return _join_tex(p.tex for p in parts), "".join(p.html for p in parts).replace("</i><i>", "")


def _group_end(text: str, i: int) -> int:
    """Index of the bracket closing the one at ``i`` (same kind), or -1."""
    opener, closer = text[i], _BRACKETS[text[i]]
    depth = 0
    for j in range(i, len(text)):
        depth += 1 if text[j] == opener else -1 if text[j] == closer else 0
        if depth == 0:
            return j
    return -1


def _read_scripts(text: str, i: int, atom: _Atom) -> int:
    """Attach the scripts that follow position ``i`` to ``atom``; returns the position after them."""
    n = len(text)
    while i < n:
        ch = text[i]
        if ch == "*" and i + 1 < n and (text[i + 1] in "_^" or _symbol(text[i + 1])):
            atom.sup.append((r"\ast", "*"))       # Ad*_g, T*R^N
            i += 1
        elif ch in _SUPERSCRIPTS or ch in _SUBSCRIPTS:
            table, target = (_SUPERSCRIPTS, atom.sup) if ch in _SUPERSCRIPTS else (_SUBSCRIPTS, atom.sub)
            j = i
            while j < n and text[j] in table:
                j += 1
            raw = "".join(table[c] for c in text[i:j])
            if re.fullmatch(r"-?T", raw):
                target.append(("-" * (raw[0] == "-") + r"\mathsf{T}", "−" * (raw[0] == "-") + "T"))
            else:
                target.append(_script_text(raw))
            i = j
        elif ch in "_^" and i + 1 < n:
            target = atom.sub if ch == "_" else atom.sup
            if text[i + 1] in _BRACKETS:
                j = _group_end(text, i + 1)
                if j < 0:
                    return i      # unbalanced: left to the caller
                inner = text[i + 2:j] if text[i + 1] == "{" else text[i + 1:j + 1]
                target.append((formula_tex(inner), formula_html(inner)))
                i = j + 1
            else:
                m = _SCRIPT_WORD_RE.match(text, i + 1)
                if not m:
                    return i
                target.append(_script_text(m.group()))
                i = m.end()
        else:
            break
    return i


def _index_digits(text: str, i: int, atom: _Atom) -> int:
    """``s13``, ``e3``, ``Λ13``: digits right after a single letter are its index (but not in ``e3x``)."""
    m = re.match(r"\d+", text[i:])
    if not m or re.match(rf"[.\d]*[{_LATIN}\u0370-\u03ff]", text[i + m.end():i + m.end() + 2]):
        return i
    atom.sub.append((m.group(), m.group()))
    return _read_scripts(text, i + m.end(), atom)


def _scripted(text: str, i: int) -> bool:
    return i < len(text) and (text[i] in "_^" or text[i] in _SUPERSCRIPTS or text[i] in _SUBSCRIPTS
                              or (text[i] == "*" and i + 1 < len(text) and text[i + 1] in "_^"))


def _is_math_identifier(ident: str) -> bool:
    """``XX_ii``, ``e_k``, ``V_i`` are symbols with a subscript; ``levy_area``, ``X.perturb`` are code."""
    if "." in ident or "/" in ident:
        return False
    head, _, tail = ident.partition("_")
    return "_" not in tail and (len(head) == 1 or (len(set(head)) == 1 and head[0].isupper())) and len(tail) <= 2


def _tokens(text: str) -> list[_Token]:
    """Cut ``text`` into tokens (kinds: see :class:`_Token`)."""
    out: list[_Token] = []
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        prev = text[i - 1] if i else " "
        if ch.isspace():
            j = i
            while j < n and text[j].isspace():
                j += 1
            out.append(_Token("space", text[i:j]))
            i = j
        elif ch == "-" and prev.isspace() and (m := _OPTION_RE.match(text, i)):
            out.append(_Token("word", m.group()))
            i = m.end()
        elif (m := _CODE_RE.match(text, i)) and not _is_math_identifier(m.group()):
            i = _prose_word(text, i, m.end(), out)
        elif m := _WORD_RE.match(text, i):
            i = _letter_run(text, i, m.end(), out)
        elif _symbol(ch):
            j = i + 1
            while j < n and text[j] in _COMBINING:
                j += 1
            atom = _letter_atom(ch, text[i + 1:j])
            k = _read_scripts(text, j, atom)
            if k == j:
                k = _index_digits(text, j, atom)
            out.append(_Token("atom", text[i:k], atom))
            i = k
        elif ch in _DIGITS:
            m = _NUMBER_RE.match(text, i)
            plain = re.match(r"\d+(?:\.\d+)?", m.group()).group()
            atom = _Atom(plain, plain)
            j = _read_scripts(text, i + len(plain), atom) if _scripted(text, i + len(plain)) else i
            if atom.sub or atom.sup:      # 2^-9, 10²
                out.append(_Token("atom", text[i:j], atom))
                i = j
            else:
                out.append(_Token("num", m.group(), _number(m.group())))
                i = m.end()
        elif text[i:i + 2] in _OPS:
            out.append(_Token("op", text[i:i + 2], _OPS[text[i:i + 2]]))
            i += 2
        elif ch in _OPS or ch in _BARS:
            out.append(_Token("op" if ch in _OPS else "bar", ch, _OPS.get(ch) or _BARS[ch]))
            i += 1
        else:
            if ch in _BRACKETS:
                out.append(_Token("open", ch, ((r"\{" if ch == "{" else ch), ch)))
            elif ch in _CLOSERS:
                out.append(_Token("close", ch, ((r"\}" if ch == "}" else ch), ch)))
                atom = _Atom("", "")       # ½(XX − XXᵀ)₁₂: scripts on a bracket
                if _scripted(text, i + 1) and (j := _read_scripts(text, i + 1, atom)) > i + 1:
                    out.append(_Token("atom", text[i + 1:j], atom))
                    i = j - 1
            elif ch in ",;:.!?":
                out.append(_Token("punct", ch, (ch, ch)))
            elif _scripted(text, i) and (j := _read_scripts(text, i, atom := _Atom("{}", ""))) > i:
                out.append(_Token("atom", text[i:j], atom))      # a script on nothing: {}^{x}
                i = j
                continue
            else:
                out.append(_Token("other", ch))
            i += 1
    return _times_signs(out)


def _prose_word(text: str, i: int, end: int, out: list[_Token]) -> int:
    """A prose word from ``i`` to ``end``, with its hyphenated parts and a call's brackets (``so(3)``)."""
    end = _WORD_TAIL_RE.match(text, end).end()
    if end < len(text) and text[end] == "(" and (close := _group_end(text, end)) > 0 and close - end < 40:
        end = close + 1
    out.append(_Token("word", text[i:end]))
    return end


def _letter_run(text: str, i: int, end: int, out: list[_Token]) -> int:
    """A run of Latin letters (with combining marks) from ``i`` to ``end``: a word, a function or symbols."""
    run = text[i:end]
    letters = "".join(c for c in run if c not in _COMBINING)
    prev = text[i - 1] if i else " "
    scripted = _scripted(text, end)
    if letters in _STARRED and scripted:
        atom = _Atom(_STARRED[letters], html.escape(letters))
        j = _read_scripts(text, end, atom)
        out.append(_Token("atom", text[i:j], atom))
        return j
    if run == letters and letters in _FUNCS and not scripted and end < len(text) and (
            text[end] == "(" or (text[end] == " " and end + 1 < len(text) and _symbol(text[end + 1])
                                 and not _WORD_RE.match(text[end + 1]))):       # exp(...), exp σ_n
        out.append(_Token("func", letters, (_FUNCS[letters], letters)))
        return end
    caps_glued = letters.isupper() and ((end < len(text) and text[end] in "·×⊗[(") or prev in "·×⊗")
    glued = bool(out) and out[-1].kind == "atom" and bool(out[-1].value.sub or out[-1].value.sup)  # ε⁻²Ay
    if run == letters and not scripted and _word_like(run) and not caps_glued and not glued:
        return _prose_word(text, i, end, out)
    # symbols: one atom per letter (XX and a differential stay one atom); the scripts go on the last
    if letters in _DIFFERENTIALS or (len(set(letters)) == 1 and letters[0].isupper()):
        pieces = [run]
    else:
        pieces = re.findall(rf"[^{''.join(_COMBINING)}][{''.join(_COMBINING)}]*", run)
    start = i
    for k, piece in enumerate(pieces):
        base = "".join(c for c in piece if c not in _COMBINING)
        atom = _letter_atom(base, piece[len(base):]) if len(base) == 1 else _Atom(base, f"<i>{base}</i>")
        j = start + len(piece)
        if k == len(pieces) - 1:
            j = _read_scripts(text, end, atom)
            if j == end and len(pieces) == 1 and len(base) == 1:
                j = _index_digits(text, end, atom)
        out.append(_Token("atom", text[start:j], atom))
        start = j
    return start


def _number(num: str) -> tuple[str, str]:
    """(TeX, HTML) of a number; ``1e-10`` is written 10⁻¹⁰, ``2.5e-3`` 2.5·10⁻³."""
    m = re.fullmatch(r"(\d+(?:\.\d+)?)[eE]([-+]?)(\d+)", num)
    if not m:
        return num, num
    mant, sign, exp = m.groups()
    exp = exp.lstrip("0") or "0"
    tex_exp, html_exp = ("-" if sign == "-" else "") + exp, ("−" if sign == "-" else "") + exp
    if float(mant) == 1.0:
        return rf"10^{{{tex_exp}}}", f"10<sup>{html_exp}</sup>"
    return rf"{mant}\cdot 10^{{{tex_exp}}}", f"{mant}·10<sup>{html_exp}</sup>"


def _times_signs(tokens: list[_Token]) -> list[_Token]:
    """``32 paths x 100 steps``, ``(8 each) x T = 40``: a lone ``x`` between spaces is a multiplication sign."""
    for k in range(2, len(tokens) - 2):
        before, after = tokens[k - 2], tokens[k + 2]
        if tokens[k].kind == "atom" and tokens[k].text == "x" and tokens[k - 1].kind == tokens[k + 1].kind == "space" \
                and before.kind in ("num", "word", "close") and after.kind in ("num", "atom", "open"):
            tokens[k] = _Token("other", "×")
    return tokens


# ------------------------------------------------------------------------------------------ writing
def _render(formula: str, which: int) -> str:
    """The tokens of a formula as KaTeX source (``which = 0``) or as HTML (``which = 1``)."""
    tokens = _tokens(unicodedata.normalize("NFC", formula))
    out: list[str] = []
    k = 0
    while k < len(tokens):
        t, piece = tokens[k], None
        if t.kind == "atom":
            piece = t.value.render(which)
        elif t.kind == "space":
            # a space between two numbers is kept (TeX would drop it); elsewhere TeX spaces the formula
            nums = k and k + 1 < len(tokens) and tokens[k - 1].kind == "num" and tokens[k + 1].kind == "num"
            piece = (r"\ " if nums else " ") if which == 0 else " "
        elif t.kind == "word":   # inside a formula: an index (ij) or a word (Strat)
            if len(t.text) <= 2 and t.text.isalpha():
                piece = _script_text(t.text)[which]
            else:
                piece = rf"\text{{{_tex_text(t.text)}}}" if which == 0 else html.escape(t.text)
        elif t.kind == "op" and t.text == "√" and k + 1 < len(tokens) and tokens[k + 1].kind in ("atom", "num"):
            k += 1
            arg = tokens[k].value.render(which) if tokens[k].kind == "atom" else tokens[k].value[which]
            piece = rf"\sqrt{{{arg}}}" if which == 0 else "√" + arg
        elif t.value is not None:
            piece = t.value[which]
        else:
            piece = rf"\text{{{_tex_text(t.text)}}}" if which == 0 else html.escape(t.text)
        out.append(piece)
        k += 1
    s = _join_tex(out) if which == 0 else "".join(out)
    if which == 0:
        return re.sub(r"(?<!\\) +", " ", s).strip()
    return s.replace("</i><i>", "")


def _tex_text(s: str) -> str:
    """Text for ``\\text{...}`` or a formula: TeX's special characters escaped."""
    special = {"#": r"\#", "$": r"\$", "%": r"\%", "&": r"\&", "_": r"\_", "{": r"\{", "}": r"\}",
               "~": r"\textasciitilde{}", "^": r"\textasciicircum{}", "\\": r"\textbackslash{}"}
    return "".join(special.get(c, c) for c in s if not unicodedata.combining(c))


def formula_tex(formula: str) -> str:
    r"""KaTeX source of a formula found by :func:`split_formulas`.

    Examples
    --------
    >>> formula_tex("E[ΠΠᵀ] → I/3")
    'E[\\Pi\\Pi^{\\mathsf{T}}] \\to I/3'
    >>> formula_tex("||Π| − 1| ≤ 1e-10")
    '||\\Pi| - 1| \\le 10^{-10}'
    """
    return _render(formula, 0)


def formula_html(formula: str) -> str:
    """The same formula as HTML text (``<i>``, ``<sub>``, ``<sup>``), for readers without KaTeX.

    Examples
    --------
    >>> formula_html("μ_{n+1} = Ad*_{exp σ_n} μ_n")
    '<i>μ</i><sub><i>n</i>+1</sub> = Ad<sub>exp <i>σ</i><sub><i>n</i></sub></sub><sup>*</sup> <i>μ</i><sub><i>n</i></sub>'
    """
    return _render(formula, 1)
