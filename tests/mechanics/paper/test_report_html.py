"""report.html: the formulas of the claims are found and typeset (KaTeX source, or plain HTML without KaTeX),
KaTeX is embedded whole or refused with a reason, and no raw TeX reaches the reader.

Oracles: TeX and HTML written by hand for the claims' notations (not produced by the modules' helpers);
the embedded fonts are compared with the bytes written into a fake KaTeX folder; the visible text of a
page is collected by the standard library's HTML parser.
"""

from __future__ import annotations

import base64
import html.parser
import os
import re
import unicodedata

import pytest
from hypothesis import given
from hypothesis import strategies as st

from mechanics.paper._html_katex import KATEX_DIR, KatexUnavailable, load_katex
from mechanics.paper._html_formula import formula_html, formula_tex
from mechanics.paper._html_markup import markup, split_formulas
from mechanics.paper.checks import CHECKS
from mechanics.paper.figures import FIGURES
from mechanics.paper.report import CheckResult, FigureResult, RunMetadata, render_html


# ------------------------------------------------------------------------------------ finding formulas
@pytest.mark.parametrize("text, formulas", [
    ("Chen's identity XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t} on Brownian rough paths",
     ["XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t}"]),
    ("The coadjoint update μ_{n+1} = Ad*_{exp σ_n} μ_n preserves the Casimir |Π| of the rigid body.",
     ["μ_{n+1} = Ad*_{exp σ_n} μ_n", "|Π|"]),
    # a call, a file name, an identifier and an option are prose; so is an equation label
    ("the path X driven by X.perturb(s) with levy_area='auto' (docs/conventions.md, --convention paper, "
     "eq. (LevyArea))", ["X"]),
    # a printed array is data, not a formula; the symbol before it is one
    ("measured E[Π] = [-0.0073  0.3661  0.9257] ± [0.0065 0.0212 0.0086]", ["E[Π]"]),
    # a bracket stating relations after a space stands on its own; commas split top-level formulas
    ("E[ΠΠᵀ] → I/3 (σ = 0.5, s ≠ 0, t = 30)", ["E[ΠΠᵀ] → I/3", "(σ = 0.5, s ≠ 0, t = 30)"]),
    ("with θ = 1, σ = 0.05, 𝕀 = diag(1, 2, 3), Π(0) = (0, 0, 1) (red dot)",
     ["θ = 1", "σ = 0.05", "𝕀 = diag(1, 2, 3)", "Π(0) = (0, 0, 1)"]),
    # bars: paired ones belong to the formula, unpaired ones go back to the prose
    ("|measured − predicted| ≤ 4 SE; max ||Π| − 1| ≤ 1e-12 after 10 steps", ["||Π| − 1| ≤ 1e-12"]),
    # an article, a lone number and a trailing relation stay prose; an index and a differential do not
    ("a long run from e3 of 2 steps: s(t−s) = drift, 2 dt", ["e3", "s(t−s)", "2 dt"]),
    # formulas do not cross a line break
    ("burn-in 30\ns13=25: measured", ["s13=25"]),
])
def test_split_formulas_finds_the_formulas(text, formulas):
    pieces = split_formulas(text)
    assert [p for kind, p in pieces if kind == "math"] == formulas
    assert "".join(p for _, p in pieces) == unicodedata.normalize("NFC", text)


def test_multiplication_x_is_shown_as_times():
    assert split_formulas("32 paths x 100 steps, (8 each) x T = 40") == [
        ("text", "32 paths × 100 steps, (8 each) × "), ("math", "T = 40")]


@pytest.mark.parametrize("formula, tex, shown", [
    ("XX_{s,t} = XX_{s,u} + X_{s,u} ⊗ X_{u,t}", r"XX_{s,t} = XX_{s,u} + X_{s,u} \otimes X_{u,t}",
     "<i>XX</i><sub><i>s</i>,<i>t</i></sub> = <i>XX</i><sub><i>s</i>,<i>u</i></sub> + <i>X</i><sub><i>s</i>,<i>u</i>"
     "</sub> ⊗ <i>X</i><sub><i>u</i>,<i>t</i></sub>"),
    ("μ_{n+1} = Ad*_{exp σ_n} μ_n", r"\mu_{n+1} = \operatorname{Ad}_{\exp \sigma_{n}}^{\ast} \mu_{n}",
     "<i>μ</i><sub><i>n</i>+1</sub> = Ad<sub>exp <i>σ</i><sub><i>n</i></sub></sub><sup>*</sup> <i>μ</i><sub><i>n</i>"
     "</sub>"),
    ("h̃ = ½Π·𝕀⁻¹Π + c·Π", r"\tilde{h} = \tfrac{1}{2}\Pi\cdot\mathbb{I}^{-1}\Pi + c\cdot\Pi",
     "<i>h\u0303</i> = ½Π·𝕀<sup>−1</sup>Π + <i>c</i>·Π"),
    ("XX[i,j] = ∫(X^i-X^i_s)dX^j", r"XX[i,j] = \int(X^{i}-X_{s}^{i})dX^{j}",
     "<i>XX</i>[<i>i</i>,<i>j</i>] = ∫(<i>X</i><sup><i>i</i></sup>−<i>X</i><sub><i>s</i></sub><sup><i>i</i></sup>)"
     "<i>dX</i><sup><i>j</i></sup>"),
    ("c = σ²(s23, −s13, s12)", r"c = \sigma^{2}(s_{23}, -s_{13}, s_{12})",
     "<i>c</i> = <i>σ</i><sup>2</sup>(<i>s</i><sub>23</sub>, −<i>s</i><sub>13</sub>, <i>s</i><sub>12</sub>)"),
    ("N = Alt(ΣA⁻ᵀ)", r"N = \operatorname{Alt}(\Sigma A^{-\mathsf{T}})", "<i>N</i> = Alt(Σ<i>A</i><sup>−T</sup>)"),
    ("½(XX − XXᵀ)₁₂", r"\tfrac{1}{2}(XX - XX^{\mathsf{T}})_{12}",
     "½(<i>XX</i> − <i>XX</i><sup>T</sup>)<sub>12</sub>"),
    ("E[XX_ii] = +0.0135 ± 0.0230", r"E[XX_{ii}] = +0.0135 \pm 0.0230",
     "<i>E</i>[<i>XX</i><sub><i>ii</i></sub>] = +0.0135 ± 0.0230"),
    ("XX^Itô = XX^Strat", r"XX^{\text{Itô}} = XX^{\text{Strat}}",
     "<i>XX</i><sup>Itô</sup> = <i>XX</i><sup>Strat</sup>"),
    ("D = √δ I", r"D = \sqrt{\delta} I", "<i>D</i> = √<i>δ</i> <i>I</i>"),
    ("||Π| − 1| ≤ 1e-12", r"||\Pi| - 1| \le 10^{-12}", "||Π| − 1| ≤ 10<sup>−12</sup>"),
    ("h = 2^-4..2^-8", r"h = 2^{-4}..2^{-8}", "<i>h</i> = 2<sup>−4</sup>..2<sup>−8</sup>"),
    ("dμ = F⁰ dt + Fⁱ d𝐗ⁱ, ℓ", r"d\mu = F^{0} dt + F^{i} d\mathbf{X}^{i}, \ell",
     "<i>dμ</i> = <i>F</i><sup>0</sup> <i>dt</i> + <i>F</i><sup><i>i</i></sup> <i>d</i>𝐗<sup><i>i</i></sup>, ℓ"),
])
def test_formula_tex_and_html_by_hand(formula, tex, shown):
    assert formula_tex(formula) == tex
    assert formula_html(formula) == shown


def test_markup_spans_and_escaping():
    out = markup("Chen's & <tag> t²/4; defect <= 1e-10")
    assert out == ("Chen's &amp; &lt;tag&gt; "
                   '<span class="arithmatex" data-tex="t^{2}/4"><i>t</i><sup>2</sup>/4</span>; defect ≤ 1e-10')
    assert markup("t²/4", typeset=False) == '<span class="arithmatex"><i>t</i><sup>2</sup>/4</span>'
    with pytest.raises(TypeError, match="text must be a str"):
        split_formulas(b"bytes")


class _Text(html.parser.HTMLParser):
    """The text a reader sees (outside <script>, <style> and attributes) and whether the tags balance."""

    VOID = {"meta", "img", "br", "hr", "input", "link"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.text, self.stack, self.balanced = [], [], True

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack.pop() != tag:
            self.balanced = False

    def handle_data(self, data):
        if not (self.stack and self.stack[-1] in ("script", "style")):
            self.text.append(data)


def _visible(page: str) -> tuple[str, bool]:
    p = _Text()
    p.feed(page)
    p.close()
    return "".join(p.text), p.balanced and not p.stack


_ALPHABET = st.sampled_from(list("XYabcdehstuxAIST ΠΣσξμεθ𝕀ℓ_^{}()[]|‖,.;:=+−-/·⊗×½²³⁻¹ᵀ₁₂0123456789*'\n") +
                            ["XX", "dt", "exp", "diag", "ad*", "levy_area", "--tiny", "1e-10", "h̃", "so(3)"])


@given(st.lists(_ALPHABET, max_size=40).map("".join))
def test_markup_never_breaks_on_any_text(text):
    """Whatever the text, the pieces join back to it, the HTML is well formed, and every piece whose braces
    balance leaves no raw ``_{``/``^{`` for the reader (an unbalanced brace is left as written)."""
    pieces = split_formulas(text)
    assert "".join(p for _, p in pieces).replace("×", "x") == unicodedata.normalize("NFC", text).replace("×", "x")
    page = markup(text)
    visible, balanced = _visible(page)
    assert balanced, page
    for kind, piece in pieces:
        if kind == "math":
            assert "_{" not in _visible(formula_html(piece))[0] and "^{" not in _visible(formula_html(piece))[0]
            assert formula_tex(piece).count("{") == formula_tex(piece).count("}")


def test_the_registered_titles_and_captions_show_no_raw_tex():
    texts = [t.title for t in CHECKS.values()] + [t.title for t in FIGURES.values()] + \
            [t.caption for t in FIGURES.values()]
    assert len(texts) >= 20
    found = 0
    for text in texts:
        visible, balanced = _visible(markup(text, typeset=False))
        assert balanced
        assert "_{" not in visible and "^{" not in visible, (text, visible)
        found += sum(kind == "math" for kind, _ in split_formulas(text))
    assert found >= 60, found


# ------------------------------------------------------------------------------------ the page
def _report(katex_dir):
    meta = RunMetadata(command="levy-area-paper --tiny", seed=3, convention="rp", scale="tiny",
                       versions={"python": "3"}, levy_area="auto")
    checks = [CheckResult("chen", "Chen: XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t}", predicted=0.0,
                          measured=1e-16, tolerance="max abs defect <= 1e-10", passed=True,
                          details="4 paths x 200 steps, d = 3; " + "long note " * 60),
              CheckResult("boom", "u^k = ½ Σ s^{ij} c^k_{ij}", passed=None,
                          details="Traceback (most recent call last):\n  x = XX_{s,t}\nValueError: no")]
    figures = [FigureResult("fig1", "Figure 1 (s = 0)", "Π(0) = e₃, B^ε = ∫y/ε dt", png="fig1.png")]
    return render_html(meta, checks, figures, lambda name: b"\x89PNG fake", katex_dir=katex_dir)


def test_report_without_katex_shows_plain_formulas():
    page = _report(None)
    visible, balanced = _visible(page)
    assert balanced
    assert "<script" not in page and "data-tex" not in page
    assert "Formulas are shown as plain text with sub- and superscripts: the report was written without KaTeX" \
        in visible
    # formulas as HTML scripts; only the traceback (shown as it is) keeps its raw TeX
    traceback = "x = XX_{s,t}"
    assert visible.count("_{") == visible.count(traceback) == 1
    assert "^{" not in visible
    assert 'XX</i><sub><i>s</i>,<i>t</i></sub>' in page
    assert "<div class='details'>4 paths × 200 steps, " in page   # notes wrap (pre-wrap), no <pre>
    assert "<pre>Traceback" in page


def test_report_says_why_a_refused_katex_is_not_used(tmp_path):
    page = _report(tmp_path / "nowhere")
    assert "<script" not in page
    assert "KaTeX is not vendored in nowhere/ (tools/vendor_katex.sh installs it)" in _visible(page)[0]


def _fake_katex(folder, script="var katex = {render: function () {}};", css=None, fonts=None):
    fonts = {"KaTeX_Main-Regular": b"\x00woff2-main\x01", "KaTeX_Math-Italic": b"woff2-math\xff"} \
        if fonts is None else fonts
    (folder / "fonts").mkdir(parents=True)
    for name, data in fonts.items():
        (folder / "fonts" / f"{name}.woff2").write_bytes(data)
        (folder / "fonts" / f"{name}.woff").write_bytes(b"old")
    if css is None:
        css = "".join(f"@font-face{{font-family:{n};src:url(fonts/{n}.woff2) format(\"woff2\"),url(fonts/{n}.woff) "
                      f"format(\"woff\"),url(fonts/{n}.ttf) format(\"truetype\")}}" for n in fonts) + \
            ".katex{font:normal 1.21em KaTeX_Main}"
    (folder / "katex.min.css").write_text(css)
    (folder / "katex.min.js").write_text(script)
    (folder / "VERSION").write_text("0.16.22\n")
    (folder / "LICENSE").write_text("The MIT License (MIT)\nCopyright (c) KaTeX authors")
    return folder, fonts


def test_load_katex_inlines_the_woff2_fonts(tmp_path):
    folder, fonts = _fake_katex(tmp_path / "katex", script='var katex={ns:"http://www.w3.org/2000/svg"};')
    k = load_katex(folder)
    assert k.version == "0.16.22" and "MIT" in k.licence
    uris = re.findall(r"url\(data:font/woff2;base64,([A-Za-z0-9+/=]+)\) format\(\"woff2\"\)", k.css)
    assert [base64.b64decode(u) for u in uris] == list(fonts.values())
    assert "fonts/" not in k.css and ".woff)" not in k.css and ".ttf" not in k.css
    # the namespace string is kept, written so that the page holds no address
    assert 'ns:"http:\\/\\/www.w3.org/2000/svg"' in k.script and "http://" not in k.script
    page = _report(folder)
    assert page.count("<script>") == 2 and "KaTeX 0.16.22 (embedded" in page
    assert 'data-tex="XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} \\otimes X_{u,t}"' in page
    assert _visible(page)[1]


@pytest.mark.parametrize("breakage, message", [
    (lambda f: (f / "VERSION").write_text("latest"), "not a version number"),
    (lambda f: (f / "katex.min.js").write_text("var katex; '</script><script>alert(1)'"), "could not be embedded"),
    (lambda f: (f / "katex.min.js").write_text("var katex; fetch('https://example.org/x')"), "other than the SVG"),
    (lambda f: (f / "katex.min.css").write_text("@font-face{src:url(https://example.org/f.woff2) format('woff2')}"),
     "refers to files other than its WOFF2 fonts"),
    (lambda f: (f / "fonts" / "KaTeX_Main-Regular.woff2").unlink(), "KaTeX_Main-Regular.woff2 is missing"),
    (lambda f: os.truncate(f / "fonts" / "KaTeX_Main-Regular.woff2", 600_000), "more than the 500,000 expected"),
    (lambda f: (f / "katex.min.css").write_text(".katex{}"), "refers to files other than its WOFF2 fonts"),
])
def test_load_katex_refuses_what_it_cannot_embed(tmp_path, breakage, message):
    folder, _ = _fake_katex(tmp_path / "katex")
    breakage(folder)
    with pytest.raises(KatexUnavailable, match=re.escape(message)):
        load_katex(folder)
    page = _report(folder)      # the report falls back and says why
    assert "<script" not in page and message in _visible(page)[0]


def test_load_katex_rejects_a_non_path():
    with pytest.raises(TypeError, match="folder must be a path"):
        load_katex(3)


def test_the_vendored_katex_embeds_without_any_address():
    """The real KaTeX (tools/vendor_katex.sh): fonts inlined, no address left in the page."""
    try:
        k = load_katex(KATEX_DIR)
    except KatexUnavailable as exc:
        if os.environ.get("CI"):
            pytest.fail(f"KaTeX must be vendored in CI (./test.sh runs tools/vendor_katex.sh): {exc}")
        pytest.skip(f"KaTeX is not vendored here: {exc}")
    page = _report(KATEX_DIR)
    assert "http://" not in page and "https://" not in page
    assert k.css.count("data:font/woff2;base64,") >= 15 and "url(fonts/" not in k.css
    assert "katex.render" in page and k.script in page
