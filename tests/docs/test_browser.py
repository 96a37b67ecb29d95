"""The documentation site and the main job's ``report.html`` display correctly in a real browser.

Claims, checked in headless Chromium (Debian's ``chromium``; ``tools/setup_browser.sh`` installs it)
on pages served from 127.0.0.1:

* on every page of the built site (``mkdocs build --strict``): every formula was typeset by KaTeX
  (each ``.arithmatex`` element holds a ``.katex`` rendering, none failed to parse), no raw TeX
  delimiter (``$$``, ``\\(``, ``\\[``) or reStructuredText role is left in the visible text, the
  KaTeX fonts loaded, every image loaded (``naturalWidth > 0``), and no console error, uncaught
  exception or failed network load occurred (the site needs nothing outside it);
* on ``report.html`` from a ``--tiny`` run of the main job: every embedded figure decodes
  (``naturalWidth > 0``), one per figure that ran, no raw TeX or RST is in the text, no console
  error occurred, and the page asked for nothing but itself (no network, no file beside it);
  every formula of the claims, notes and captions was typeset by the embedded KaTeX (each
  ``.arithmatex`` holds a ``.katex``, the KaTeX fonts loaded, no ``_{``/``^{`` left in the visible
  text: where KaTeX is not vendored, outside CI, the formulas are checked in their plain-HTML form
  instead), and nothing needs horizontal scrolling (the page, the Details notes, the tables).
  Screenshots of the page and of Figures 1, 4 and 5 as the reader sees them are kept, and of the section
  "Beyond the paper: Euler on the sphere" (present, after the paper's results) and its figure
  ``sphere_euler`` (the vorticity in two projections, the enstrophy spectrum, the Casimir drift).

Screenshots are kept in ``test-artifacts/browser/`` (gitignored): of the report, of the site's home page and of
every site page that fails a check (of every page with ``BROWSER_SHOTS=all``). Skipped when Chromium is missing,
except under ``CI=true``, where that is a failure.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from _browser import Chromium, StaticServer, find_chromium

ROOT = Path(__file__).resolve().parents[2]
ARTIFACTS = ROOT / "test-artifacts" / "browser"

PAGE_STATE = r"""
(async () => {
  // KaTeX typesets on page load (katex.js); give it up to 5 s before counting.
  const pending = () => Array.from(document.querySelectorAll('.arithmatex')).some(el => !el.querySelector('.katex'));
  for (let i = 0; i < 50 && pending(); i++) { await new Promise(r => setTimeout(r, 100)); }
  await document.fonts.ready;
  const imgs = Array.from(document.images);
  await Promise.all(imgs.map(img => img.complete ? null : new Promise(r => { img.onload = img.onerror = r; })));
  const text = document.body.innerText;
  const raw = [];
  for (const rx of [/\$\$/g, /\\\(/g, /\\\[/g, /:(?:math|class|func|meth|attr|mod|data|exc|obj):`/g, /\.\. math::/g]) {
    for (const m of text.matchAll(rx)) { raw.push(text.slice(Math.max(0, m.index - 40), m.index + 40)); }
  }
  const math = Array.from(document.querySelectorAll('.arithmatex'));
  return {
    title: document.title,
    formulas: math.length,
    typeset: math.filter(el => el.querySelector('.katex')).length,
    failed: document.querySelectorAll('.katex-failed, .katex-error').length,
    katexFont: math.length ? document.fonts.check('16px KaTeX_Main') : true,
    images: imgs.map(img => ({src: img.src.slice(0, 80), width: img.naturalWidth})),
    raw: raw.slice(0, 10),
  };
})()
"""


@pytest.fixture(scope="module")
def chromium():
    exe = find_chromium()
    if exe is None:
        msg = "Chromium not found: tools/setup_browser.sh installs Debian's chromium (run by ./test.sh)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    with Chromium(exe) as browser:
        yield browser


def _check_page(browser, url: str, shot: str) -> dict:
    """The page's state (PAGE_STATE) and errors; its tab is closed after (the tabs left open slowed every
    later page: 46 s for the site against 37 s closing each). Screenshots (of the top and of the first
    display formula) are taken of the home page and of any page that fails a check, or of every page with
    ``BROWSER_SHOTS=all``: for all 40 pages they cost 9 s of the test's 31."""
    page = browser.open(url)
    state = page.evaluate(PAGE_STATE)
    state["errors"] = page.errors()
    state["url"] = url
    broken = (state["errors"] or state["typeset"] != state["formulas"] or state["failed"] or not state["katexFont"]
              or state["raw"] or any(i["width"] == 0 for i in state["images"]))
    if broken or shot == "home" or os.environ.get("BROWSER_SHOTS") == "all":
        page.screenshot(ARTIFACTS / f"{shot}.png")
        if page.evaluate("(() => { const el = document.querySelector('div.arithmatex');"
                         " if (el) { el.scrollIntoView({block: 'center'}); } return !!el; })()"):
            page.screenshot(ARTIFACTS / f"{shot}-display-math.png")
    page.close()
    return state


def test_docs_site_in_browser(docs_site, chromium):
    assert docs_site.returncode == 0, docs_site.stderr[-4000:]
    if docs_site.katex_missing:
        pytest.skip(f"KaTeX could not be vendored, so the site cannot typeset: {docs_site.katex_missing}")
    site = docs_site.site
    pages = sorted(p.relative_to(site) for p in site.rglob("index.html"))
    assert len(pages) >= 8, pages
    # one API page per subpackage (docs/api/<package>/<subpackage>.md): every one of them is opened
    api_pages = {rel.parent.as_posix() for rel in pages if rel.parts[0] == "api"}
    for sub in ("algebra", "paths", "signatures", "norms", "drivers", "rde", "io"):
        assert f"api/roughpaths/{sub}" in api_pages, sorted(api_pages)
    total = api_total = 0
    with StaticServer(site) as server:
        for rel in pages:
            url = server.url + rel.parent.as_posix().removeprefix(".") + ("/" if rel.parent != Path(".") else "")
            shot = re.sub(r"\W+", "-", rel.parent.as_posix()).strip("-") or "home"
            s = _check_page(chromium, url, shot)
            where = f"{rel.parent} (screenshot test-artifacts/browser/{shot}.png)"
            assert not s["errors"], f"{where}: console/network errors: {s['errors']}"
            assert s["typeset"] == s["formulas"], f"{where}: {s['formulas'] - s['typeset']} formulas not typeset"
            assert s["failed"] == 0, f"{where}: {s['failed']} formulas KaTeX could not parse"
            assert s["katexFont"], f"{where}: KaTeX fonts did not load"
            assert not s["raw"], f"{where}: raw TeX/RST in the text: {s['raw']}"
            bad = [i for i in s["images"] if i["width"] == 0]
            assert not bad, f"{where}: images that did not load: {bad}"
            if rel.parts[0] == "api":
                api_total += s["formulas"]
            total += s["formulas"]
    assert api_total >= 400, f"only {api_total} formulas on the API pages"
    assert total >= 400


REPORT_STATE = r"""
(() => {
  const text = document.body.innerText;
  const raw = [];
  for (const rx of [/_\{/g, /\^\{/g]) {
    for (const m of text.matchAll(rx)) { raw.push(text.slice(Math.max(0, m.index - 40), m.index + 40)); }
  }
  const wide = Array.from(document.querySelectorAll('pre, .details, table, figure, p'))
    .filter(el => el.scrollWidth > el.clientWidth + 1)
    .map(el => el.tagName + '.' + el.className + ': ' + el.textContent.slice(0, 60));
  return {
    rawTex: raw.slice(0, 10),
    katex: document.querySelectorAll('.arithmatex > .katex').length,
    withTex: document.querySelectorAll('.arithmatex[data-tex]').length,
    details: document.querySelectorAll('.details').length,
    pageScrolls: document.documentElement.scrollWidth > document.documentElement.clientWidth,
    wide: wide.slice(0, 10),
    requests: performance.getEntriesByType('resource').map(r => r.name.slice(0, 100)),
  };
})()
"""


def test_report_html_in_browser(tiny_paper_run, chromium):
    out = tiny_paper_run.out
    assert tiny_paper_run.returncode in (0, 1), tiny_paper_run.stderr[-4000:]
    report = out / "report.html"
    assert report.exists()
    page_text = report.read_text(encoding="utf-8")
    figures_run = len(re.findall(r"<img alt=", page_text))
    # the report says whether it embeds KaTeX (it does wherever tools/vendor_katex.sh has run, as in CI)
    katex_embedded = "Formulas are typeset by KaTeX" in page_text
    with StaticServer(out) as server:
        page = chromium.open(server.url + "report.html")
        s = page.evaluate(PAGE_STATE)
        r = page.evaluate(REPORT_STATE)
        page.screenshot(ARTIFACTS / "report.png")
        page.screenshot(ARTIFACTS / "report-full.png", full_page=True)
        # the figures as the reader sees them (look at them: the legends, markers and colour bars)
        for name in ("fig1", "fig4", "fig5", "beyond-the-paper", "sphere_euler"):
            if page.evaluate(f"(() => {{ const f = document.getElementById('{name}'); if (!f) return false;"
                             f" f.scrollIntoView({{block: 'start'}}); return true; }})()"):
                page.screenshot(ARTIFACTS / f"report-{name}.png")
        errors = page.errors()
        page.close()
    # none filtered out: the report declares an empty icon, so the browser does not ask for /favicon.ico either
    assert not errors, f"report.html: console/network errors: {errors}"
    assert figures_run >= 1 and len(s["images"]) == figures_run
    # the section beyond the paper comes after the paper's figures, and holds its own figure
    assert page_text.index("<h2>Figures</h2>") < page_text.index("id='beyond-the-paper'") < \
        page_text.index("id='sphere_euler'")
    bad = [i for i in s["images"] if i["width"] == 0]
    assert not bad, f"report.html: figures that did not decode: {bad}"
    assert not s["raw"], f"report.html: raw TeX/RST in the text: {s['raw']}"
    assert s["failed"] == 0
    # self-contained: the page loaded nothing but itself (images are data: URIs, KaTeX is inline)
    assert not [u for u in r["requests"] if not u.startswith("data:")], r["requests"]
    # formulas: every claim has some; all typeset by KaTeX, or all plain HTML when KaTeX is missing here
    assert s["formulas"] >= 100, f"only {s['formulas']} formulas found in report.html"
    assert not r["rawTex"], f"report.html: raw TeX in the text: {r['rawTex']}"
    if katex_embedded:
        assert r["withTex"] == s["formulas"] == s["typeset"] == r["katex"], (r, s)
        assert s["katexFont"], "report.html: the embedded KaTeX fonts did not load"
    elif os.environ.get("CI"):
        pytest.fail("report.html does not embed KaTeX in CI (./test.sh runs tools/vendor_katex.sh before the tests)")
    else:
        assert r["withTex"] == r["katex"] == 0 and "Formulas are shown as plain text" in page_text
    # text wraps: no horizontal scrolling of the page or of a note, table or figure
    assert r["details"] >= 5
    assert not r["pageScrolls"] and not r["wide"], f"report.html needs horizontal scrolling: {r['wide']}"
