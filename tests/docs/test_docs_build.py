"""The documentation site builds with ``mkdocs build --strict`` and its API reference renders.

Claims:

* every page, cross-reference, included tutorial file and API reference (mkdocstrings from the
  numpydoc docstrings) resolves, with no warning;
* no reStructuredText is left in the HTML: no ``:math:``/``:class:``/``:func:``/… role and no
  ``.. math::`` (or other) directive, and none of the converted markup shows as text (an escaped
  ``<autoref>`` tag or a ``$\…`` formula inside a code block or a type column) (``tools/griffe_rst.py`` converts them when the docstrings
  are loaded; before it, the API pages showed about 590 raw roles and 23 directives);
* every formula on the site is valid input for KaTeX (each arithmatex span is typeset by the
  vendored KaTeX under Node.js with ``throwOnError``), and no dollar-delimited formula was left
  unconverted in the text;
* cross-references into the two packages became links.

Skipped, with the reason, when mkdocs or its plugins are not installed (they are in the ``docs``
extra: ``pip install -e ".[docs]"``); under ``CI=true`` a missing toolchain is a failure.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: One API page per subpackage (docs/api/<package>/<subpackage>.md), each a folder of the built site.
API_PAGES = ["roughpaths"] + [f"roughpaths/{p}" for p in ("algebra", "paths", "signatures", "norms", "drivers",
                                                            "rde", "io")]
KATEX = ROOT / "docs" / "assets" / "vendor" / "katex" / "katex.min.js"

RAW_ROLE = re.compile(r":(?:py:)?(?:math|class|func|meth|attr|mod|data|exc|obj|const|ref|eq|cite|term|doc)"
                      r":(?:`|&#96;|<code>)")
RAW_DIRECTIVE = re.compile(r"(?m)^\s*\.\. [a-z][a-z-]*::|\.\. (?:math|note|warning|seealso|code-block|"
                           r"versionadded|versionchanged|deprecated)::")
# Converted markup that ended up shown as text (e.g. in a code block or a verbatim type column):
# an escaped autoref tag, or a dollar-delimited formula (arithmatex writes \( \), never $).
LEFTOVER = re.compile(r"&lt;autoref|\$\\[A-Za-z]")
ARITHMATEX = re.compile(r'<(span|div) class="arithmatex">(.*?)</\1>', re.S)


class _Text(HTMLParser):
    """The page's visible text outside code, pre, script, style and arithmatex elements."""

    SKIP = {"code", "pre", "script", "style"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.parts: list[str] = []
        self._stack: list[bool] = []

    def handle_starttag(self, tag, attrs):
        if tag in ("br", "img", "hr", "input", "meta", "link"):
            return
        skip = tag in self.SKIP or "arithmatex" in (dict(attrs).get("class") or "")
        self._stack.append(skip or (bool(self._stack) and self._stack[-1]))

    def handle_endtag(self, tag):
        if tag in ("br", "img", "hr", "input", "meta", "link"):
            return
        if self._stack:
            self._stack.pop()

    def handle_data(self, data):
        if not (self._stack and self._stack[-1]):
            self.parts.append(data)


def _pages(site: Path) -> list[Path]:
    return sorted(p for p in site.rglob("*.html") if p.name != "404.html")


@pytest.fixture(scope="module")
def site(docs_site):
    assert docs_site.returncode == 0, docs_site.stderr[-4000:]
    return docs_site.site


def test_mkdocs_build_strict(site):
    assert (site / "index.html").exists()
    for page in API_PAGES:
        assert (site / "api" / page / "index.html").exists(), page

def test_katex_is_part_of_the_site(site, docs_site):
    if docs_site.katex_missing:
        pytest.skip(f"KaTeX could not be vendored: {docs_site.katex_missing}")
    assert (site / "assets" / "vendor" / "katex" / "katex.min.js").exists(), "KaTeX not copied into the site"
    assert (site / "assets" / "vendor" / "katex" / "fonts" / "KaTeX_Main-Regular.woff2").exists()


def test_no_raw_restructuredtext(site):
    found = []
    for page in _pages(site):
        text = page.read_text(encoding="utf-8")
        for rx in (RAW_ROLE, RAW_DIRECTIVE, LEFTOVER):
            for m in rx.finditer(text):
                found.append(f"{page.relative_to(site)}: ...{text[max(0, m.start() - 60):m.end() + 60]!r}...")
    assert not found, f"{len(found)} raw reStructuredText roles/directives in the HTML:\n" + "\n".join(found[:20])


def _formulas(site: Path) -> list[tuple[str, str, bool]]:
    out = []
    for page in _pages(site):
        for m in ARITHMATEX.finditer(page.read_text(encoding="utf-8")):
            tex = html.unescape(m[2]).strip()
            display = m[1] == "div"
            delims = ("\\[", "\\]") if display else ("\\(", "\\)")
            assert tex.startswith(delims[0]) and tex.endswith(delims[1]), (page, tex)
            out.append((str(page.relative_to(site)), tex[2:-2], display))
    return out


def test_api_reference_has_typeset_maths_and_links(site):
    formulas = _formulas(site)
    api = [f for f in formulas if f[0].startswith("api")]
    # The docstrings hold ~430 inline formulas and ~20 display blocks; all must reach the page.
    assert len(api) >= 400, len(api)
    assert sum(display for *_, display in api) >= 15
    links = []
    for page in API_PAGES:
        if page.startswith("roughpaths"):
            text = (site / "api" / page / "index.html").read_text(encoding="utf-8")
            links += re.findall(r'<a class="autorefs autorefs-[a-z]+"[^>]*href="[^"]*#(roughpaths\.[\w.]+)"', text)
    assert len(links) >= 50, len(links)
    assert "roughpaths.paths.rough_path.RoughPath" in links


def test_every_formula_is_valid_katex(site, docs_site):
    if docs_site.katex_missing:
        pytest.skip(f"KaTeX could not be vendored: {docs_site.katex_missing}")
    node = shutil.which("node")
    if node is None:
        if os.environ.get("CI"):
            pytest.fail("Node.js is needed in CI to check the formulas with KaTeX")
        pytest.skip("Node.js not installed: cannot check the formulas with KaTeX")
    formulas = _formulas(site)
    script = (
        "const katex = require(process.argv[1]);"
        "const items = JSON.parse(require('fs').readFileSync(0, 'utf8'));"
        "const bad = [];"
        "for (const [page, tex, display] of items) {"
        "  try { katex.renderToString(tex, {displayMode: display, throwOnError: true, strict: 'error'}); }"
        "  catch (e) { bad.push(page + ': ' + JSON.stringify(tex) + ': ' + e.message); } }"
        "process.stdout.write(JSON.stringify(bad));"
    )
    proc = subprocess.run([node, "-e", script, str(KATEX)], input=json.dumps(formulas), capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-3000:]
    bad = json.loads(proc.stdout)
    assert not bad, f"{len(bad)} of {len(formulas)} formulas are not valid KaTeX:\n" + "\n".join(bad[:20])


def test_no_unconverted_math_delimiters_in_text(site):
    found = []
    for page in _pages(site):
        parser = _Text()
        parser.feed(page.read_text(encoding="utf-8"))
        text = "".join(parser.parts)
        for m in re.finditer(r"\$\$|\$[^\s$][^$]*?\$|\\\(|\\\[", text):
            found.append(f"{page.relative_to(site)}: ...{text[max(0, m.start() - 40):m.end() + 40]!r}...")
    assert not found, "math delimiters left as text (formula not converted):\n" + "\n".join(found[:20])
