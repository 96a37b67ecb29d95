"""Verification report of the paper's reproduction: Markdown and a self-contained HTML page.

The main job (``python -m mechanics``) collects, for every theorem / proposition check, a
:class:`CheckResult` (claim, predicted and measured numbers, tolerance, pass/fail) and, for every
figure, a :class:`FigureResult` (PNG and the ``.npz`` of the data behind it). :func:`write_report`
turns them into ``report.md`` (figures linked), ``report.html`` (figures embedded as base64, no
external resources) and ``results.json`` (the same results, machine-readable), with the run's
metadata (the command that reproduces it, seed, convention, Lévy-area sampler, sizes, versions).

In ``report.html`` the formulas written in the claims, notes and captions (``XX_{s,t}``, ``σ²``,
``Ad*_{exp σ_n}``) are found (modules ``_html_markup`` and ``_html_formula``) and typeset by KaTeX,
embedded whole from the copy ``tools/vendor_katex.sh`` puts in the source tree (module ``_html_katex``),
so the page still opens offline as one file. Where that copy is missing (``./run.sh`` installs the
Python dependencies only) the formulas are plain HTML with sub- and superscripts and the page says so;
raw TeX is never shown.
``report.md`` keeps the claims as the checks write them.

The three files depend only on the results and the options, never on the clock or the output
folder's name: the same run gives the same bytes (wall times and dates are in ``manifest.json``).
"""

from __future__ import annotations

import base64
import html
import json
import os
import platform
import sys
from dataclasses import asdict, dataclass, field
from importlib import metadata
from typing import Any

import numpy as np

import mechanics
import roughpaths

from ._html_katex import KATEX_DIR, KatexUnavailable, load_katex
from ._html_markup import markup

__all__ = [
    "CheckResult", "FigureResult", "RunMetadata", "format_value", "write_report", "versions",
    "result_to_json", "result_from_json", "levy_area_text", "PASS", "FAIL", "ERROR",
]

#: status strings of a check or figure
PASS, FAIL, ERROR = "pass", "FAIL", "error"


@dataclass
class CheckResult:
    """Outcome of one theorem / proposition check.

    Attributes
    ----------
    name : str
        Short identifier (used by ``--only``).
    statement : str
        The claim checked, in words, with the paper's reference and the convention used.
    predicted, measured : Any
        Numbers (scalars or small arrays) or short texts compared by the check.
    tolerance : str
        The acceptance rule, in words (e.g. ``"|measured - predicted| <= 4 standard errors"``).
    passed : bool or None
        ``None`` when the check raised (then ``status == "error"``).
    status : str
        ``"pass"``, ``"FAIL"`` or ``"error"`` (an exception; traceback in ``details``).
    details : str
        Free-form notes (sizes, standard errors, the rejected variants' numbers, ...).
    """

    name: str
    statement: str
    predicted: Any = None
    measured: Any = None
    tolerance: str = ""
    passed: bool | None = None
    status: str = ""
    details: str = ""

    def __post_init__(self):
        if not self.status:
            self.status = ERROR if self.passed is None else (PASS if self.passed else FAIL)
        if self.passed is not None:
            self.passed = bool(self.passed)


@dataclass
class FigureResult:
    """One rendered figure: the names of its PNG and data files in the output folder, its caption."""

    name: str
    title: str
    caption: str
    png: str | None = None
    npz: str | None = None
    status: str = PASS
    details: str = ""


@dataclass
class RunMetadata:
    """What a reader needs to reproduce the run (nothing that changes from one run to the next)."""

    command: str
    seed: int
    convention: str
    scale: str
    sizes: dict = field(default_factory=dict)
    versions: dict = field(default_factory=dict)
    levy_area: str = "auto"


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return {"array": value.tolist(), "dtype": value.dtype.str}
    if isinstance(value, np.generic):
        return value.item()
    return value


def _from_jsonable(value):
    if isinstance(value, dict) and set(value) == {"array", "dtype"}:
        return np.asarray(value["array"], dtype=np.dtype(value["dtype"]))
    return value


def result_to_json(result: CheckResult | FigureResult) -> dict:
    """A JSON-serialisable dict of a result (arrays with their dtype, floats exactly)."""
    kind = "check" if isinstance(result, CheckResult) else "figure"
    return {"kind": kind, **{k: _jsonable(v) for k, v in asdict(result).items()}}


def result_from_json(data: dict) -> CheckResult | FigureResult:
    """Inverse of :func:`result_to_json`."""
    data = dict(data)
    cls = CheckResult if data.pop("kind") == "check" else FigureResult
    return cls(**{k: _from_jsonable(v) for k, v in data.items()})


def versions() -> dict:
    """Versions of Python, the platform and the packages the run depends on."""
    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for dist in ("numpy", "scipy", "matplotlib", "numba"):   # without importing matplotlib (start-up time)
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:  # pragma: no cover - a core dependency
            out[dist] = "not installed"
    out["roughpaths"], out["mechanics"] = roughpaths.__version__, mechanics.__version__
    return out


def format_value(value: Any, digits: int = 4) -> str:
    """Compact text of a scalar, a small array or a string, for report tables."""
    if value is None:
        return "—"
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    arr = np.asarray(value)
    if arr.dtype.kind in "fc" or arr.dtype.kind in "iu":
        if arr.ndim == 0:
            return _fmt_scalar(arr.item(), digits)
        if arr.size <= 12:
            if arr.ndim == 1:
                return "(" + ", ".join(_fmt_scalar(v, digits) for v in arr.tolist()) + ")"
            return "[" + "; ".join("(" + ", ".join(_fmt_scalar(v, digits) for v in row) + ")"
                               for row in arr.reshape(arr.shape[0], -1).tolist()) + "]"
        return f"array{arr.shape}"
    return str(value)


def _fmt_scalar(v, digits):
    if isinstance(v, complex):
        return f"{v:.{digits}g}"
    if isinstance(v, (int, np.integer)):
        return str(v)
    if v == 0:
        return "0"
    return f"{v:.{digits}g}"


def _md_escape(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _summary(checks: list[CheckResult]) -> dict:
    counts = {PASS: 0, FAIL: 0, ERROR: 0}
    for c in checks:
        counts[c.status] = counts.get(c.status, 0) + 1
    return counts


_CONVENTION_NOTE = (
    "The checks test the library's rough-path-correct mathematics whatever the convention; where a check "
    "says so, the paper's printed variant is shown to fail. The convention option changes the figures only "
    "(the Lévy torque's sign in Figures 2 and surf2..surf5)."
)
_CONVENTION_TEXT = {
    "rp": "rough-path-correct signs and factors, see the project's docs/conventions.md",
    "paper": "the paper's printed equations, slips included",
}
_LEVY_AREA_TEXT = {
    "auto": "exact conditional law for d = 2; Mrongowius–Rößler, per-step L² error h^1.5 for d = 3",
    "exact": "exact conditional law for d = 2; d = 3 has no exact sampler and uses auto's: Mrongowius–Rößler, "
             "per-step L² error h^1.5",
    "mrongowius-rossler": "Mrongowius–Rößler Fourier series with Gaussian tail, per-step L² error h^1.5",
    "wiktorsson": "Wiktorsson's Fourier series with Gaussian tail, per-step L² error h^1.5",
    "fourier": "truncated Fourier series (Milstein), per-step L² error h^1.5, variance short by h² s_n/(2π²) per step",
    "davie": "Davie: exact second moments, strong order ½ against Brownian motion",
    "foster": "Foster: conditional mean given the space-time area, variance short by h²/12 per step, strong order ½",
}
_LEVY_AREA_NOTE = (
    "The Lévy-area option applies to the Brownian drivers of the checks and figures that use areas; the Gibbs "
    "check's ensembles (mechanics.run_ensemble) use increments only, and the coloured-noise figures and checks "
    "lift their own paths."
)


def levy_area_text(method: str) -> str:
    """The Lévy-area sampler of a run in words: ``method`` and what it samples (``"auto"`` resolved)."""
    return f"{method} ({_LEVY_AREA_TEXT[method]})" if method in _LEVY_AREA_TEXT else str(method)


_TIMING_NOTE = "Wall times and dates are in manifest.json (the report depends only on the results)."


def render_markdown(meta: RunMetadata, checks: list[CheckResult], figures: list[FigureResult]) -> str:
    """The Markdown report (figures referenced by file name, relative to the output folder)."""
    counts = _summary(checks)
    lines = [
        "# Verification report: *Variational Principles on Geometric Rough Paths and the Lévy Area Correction*",
        "",
        f"Convention: **{meta.convention}** ({_CONVENTION_TEXT.get(meta.convention, meta.convention)})"
        f" · seed **{meta.seed}** · sizes **{meta.scale}**",
        "",
        f"Lévy areas: **{meta.levy_area}** ({_LEVY_AREA_TEXT.get(meta.levy_area, meta.levy_area)}). "
        + _LEVY_AREA_NOTE,
        "",
        f"Checks: **{counts[PASS]} passed**, {counts[FAIL]} failed, {counts[ERROR]} errors.",
        "",
        _CONVENTION_NOTE,
        "",
        "## Theorem and proposition checks",
        "",
        "| check | claim | predicted | measured | tolerance | result |",
        "|---|---|---|---|---|---|",
    ]
    for c in checks:
        lines.append(
            f"| `{c.name}` | {_md_escape(c.statement)} | {_md_escape(format_value(c.predicted))} | "
            f"{_md_escape(format_value(c.measured))} | {_md_escape(c.tolerance)} | **{c.status}** |"
        )
    notes = [c for c in checks if c.details]
    if notes:
        lines += ["", "### Details", ""]
        for c in notes:
            detail = c.details.strip()
            if "\n" in detail:
                lines += [f"- `{c.name}`:", "", "```text", detail, "```", ""]
            else:
                lines.append(f"- `{c.name}`: {detail}")
    lines += ["", "## Figures", ""]
    for f in figures:
        lines += [f"### {f.title} (`{f.name}`)", ""]
        if f.png is not None and f.status == PASS:
            lines += [f"![{f.title}]({f.png})", ""]
            if f.npz is not None:
                lines += [f"Data: `{f.npz}`", ""]
        else:
            lines += [f"*{f.status}*: {_md_escape(f.details.strip().splitlines()[-1] if f.details else '')}", ""]
        lines += [f.caption, ""]
    lines += ["## Run metadata", "", f"- command: `{meta.command}`", f"- seed: {meta.seed}",
              f"- convention: {meta.convention}", f"- Lévy areas: {levy_area_text(meta.levy_area)}",
              f"- sizes: {meta.scale}", f"- {_TIMING_NOTE}", ""]
    if meta.sizes:
        lines += ["| size parameter | value |", "|---|---|"]
        lines += [f"| {k} | {format_value(v)} |" for k, v in meta.sizes.items()]
        lines.append("")
    lines += ["| package | version |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in meta.versions.items()]
    lines.append("")
    return "\n".join(lines) + "\n"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1150px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45;overflow-wrap:break-word}
table{border-collapse:collapse;margin:1em 0;font-size:0.92em}th,td{border:1px solid #ccc;padding:4px 8px;
vertical-align:top}th{background:#f2f2f2}td.name,td.pass,td.FAIL,td.error{white-space:nowrap}
td.pass{background:#e3f6e3;font-weight:bold}
td.FAIL{background:#fbe0e0;font-weight:bold}td.error{background:#fbe0e0}
figure{margin:1.5em 0}figure img{max-width:100%;box-sizing:border-box;border:1px solid #ddd}
figcaption{font-size:0.92em;color:#444}
code,pre{background:#f6f6f6;padding:1px 3px}pre{padding:6px;font-size:0.85em}
pre,.details{white-space:pre-wrap;overflow-wrap:anywhere}.details{font-size:0.92em;margin:0.2em 0 0.8em}
.katex{font-size:1.08em}.summary{font-size:1.1em}.note{color:#555;font-size:0.92em}
"""

#: typesets every formula span (class ``arithmatex``, KaTeX source in ``data-tex``) once KaTeX is loaded; a
#: formula KaTeX cannot parse keeps its plain-HTML form, is marked ``katex-failed`` and reported on the console
_TYPESET_SCRIPT = """(function () {
  "use strict";
  document.querySelectorAll(".arithmatex[data-tex]").forEach(function (el) {
    var tex = el.getAttribute("data-tex");
    try {
      katex.render(tex, el, { throwOnError: true, strict: "ignore" });
    } catch (err) {
      console.error("KaTeX could not typeset " + JSON.stringify(tex) + ": " + err.message);
      el.classList.add("katex-failed");
    }
  });
})();"""


def _formula_note(katex, reason: str | None) -> str:
    if katex is not None:
        return (f"Formulas are typeset by KaTeX {katex.version} (embedded: the page needs no network); where "
                f"JavaScript is off they are shown as plain text with sub- and superscripts.")
    return (f"Formulas are shown as plain text with sub- and superscripts: {reason}. Run tools/vendor_katex.sh "
            f"(or ./test.sh) in the source tree before the main job to have them typeset.")


def render_html(meta: RunMetadata, checks: list[CheckResult], figures: list[FigureResult], read_file,
                katex_dir: str | os.PathLike | None = KATEX_DIR) -> str:
    """A self-contained HTML page (figures embedded as base64 PNG; ``read_file(name) -> bytes``).

    The formulas in the claims, notes and captions are found (``_html_markup.markup``) and
    typeset by KaTeX, embedded whole (script, style sheet, fonts as ``data:`` URIs) from ``katex_dir``
    (default: where ``tools/vendor_katex.sh`` vendors it in the source tree). Without KaTeX
    (``katex_dir=None``, or a folder ``_html_katex.load_katex`` refuses) they are plain HTML with
    ``<sub>``/``<sup>``, and the page says why. Either way no raw TeX (``_{``, ``^{``) is shown.

    Parameters
    ----------
    meta : RunMetadata
    checks : list of CheckResult
    figures : list of FigureResult
    read_file : callable
        ``read_file(name) -> bytes``: a figure's PNG from the output folder.
    katex_dir : path-like or None
        The vendored KaTeX to embed, or None for plain-HTML formulas.

    Returns
    -------
    str
        The page; the same inputs (and the same KaTeX) give the same text.
    """
    e = html.escape
    katex, reason = None, "the report was written without KaTeX"
    if katex_dir is not None:
        try:
            katex = load_katex(katex_dir)
        except KatexUnavailable as exc:
            reason = str(exc)

    def m(text) -> str:
        return markup(str(text), typeset=katex is not None)

    counts = _summary(checks)
    head = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
            "<meta name='viewport' content='width=device-width, initial-scale=1'>",
            # an empty icon: without one the browser fetches /favicon.ico beside the file (one file, nothing else)
            "<link rel='icon' href='data:,'>",
            "<title>Verification report: Lévy area correction</title>"]
    if katex is not None:
        head.append(f"<style>/* KaTeX {katex.version}\n{katex.licence}\n*/\n{katex.css}</style>")
    parts = head + [
        f"<style>{_CSS}</style></head><body>",
        "<h1>Verification report: <i>Variational Principles on Geometric Rough Paths and the Lévy Area "
        "Correction</i></h1>",
        f"<p>Convention: <b>{e(meta.convention)}</b> ({e(_CONVENTION_TEXT.get(meta.convention, ''))}) · seed "
        f"<b>{meta.seed}</b> · sizes <b>{e(meta.scale)}</b></p>",
        f"<p>Lévy areas: <b>{e(meta.levy_area)}</b> ({m(_LEVY_AREA_TEXT.get(meta.levy_area, meta.levy_area))}). "
        f"{m(_LEVY_AREA_NOTE)}</p>",
        f"<p class='summary'>Checks: <b>{counts[PASS]} passed</b>, {counts[FAIL]} failed, "
        f"{counts[ERROR]} errors.</p>",
        f"<p>{m(_CONVENTION_NOTE)}</p>",
        f"<p class='note'>{e(_formula_note(katex, reason))}</p>",
        "<h2>Theorem and proposition checks</h2>",
        "<table><tr><th>check</th><th>claim</th><th>predicted</th><th>measured</th><th>tolerance</th>"
        "<th>result</th></tr>",
    ]
    for c in checks:
        parts.append(
            f"<tr><td class='name'><code>{e(c.name)}</code></td><td>{m(c.statement)}</td>"
            f"<td>{m(format_value(c.predicted))}</td><td>{m(format_value(c.measured))}</td>"
            f"<td>{m(c.tolerance)}</td><td class='{e(c.status)}'>{e(c.status)}</td></tr>"
        )
    parts.append("</table>")
    notes = [c for c in checks if c.details]
    if notes:
        parts.append("<h3>Details</h3><ul>")
        for c in notes:
            # a traceback is shown as it is; notes are prose with formulas, wrapped (no horizontal scrolling)
            body = (f"<pre>{e(c.details.strip())}</pre>" if c.status == ERROR
                    else f"<div class='details'>{m(c.details.strip())}</div>")
            parts.append(f"<li><code>{e(c.name)}</code>: {body}</li>")
        parts.append("</ul>")
    parts.append("<h2>Figures</h2>")
    for f in figures:
        parts.append(f"<figure id='{e(f.name)}'><h3>{m(f.title)} (<code>{e(f.name)}</code>)</h3>")
        if f.png is not None and f.status == PASS:
            data = base64.b64encode(read_file(f.png)).decode("ascii")
            parts.append(f"<img alt='{e(f.title)}' src='data:image/png;base64,{data}'>")
        else:
            parts.append(f"<p><b>{e(f.status)}</b></p><pre>{e(f.details.strip())}</pre>")
        parts.append(f"<figcaption>{m(f.caption)}</figcaption></figure>")
    parts += ["<h2>Run metadata</h2><table>",
              f"<tr><th>command</th><td><code>{e(meta.command)}</code></td></tr>",
              f"<tr><th>seed</th><td>{meta.seed}</td></tr>",
              f"<tr><th>convention</th><td>{e(meta.convention)}</td></tr>",
              f"<tr><th>Lévy areas</th><td>{m(levy_area_text(meta.levy_area))}</td></tr>",
              f"<tr><th>sizes</th><td>{e(meta.scale)}</td></tr></table>",
              f"<p>{e(_TIMING_NOTE)}</p>"]
    if meta.sizes:
        parts.append("<table><tr><th>size parameter</th><th>value</th></tr>")
        parts += [f"<tr><td>{e(k)}</td><td>{e(format_value(v))}</td></tr>" for k, v in meta.sizes.items()]
        parts.append("</table>")
    parts.append("<table><tr><th>package</th><th>version</th></tr>")
    parts += [f"<tr><td>{e(k)}</td><td>{e(str(v))}</td></tr>" for k, v in meta.versions.items()]
    parts.append("</table>")
    if katex is not None:
        parts.append(f"<script>/*! KaTeX {katex.version}\n{katex.licence}\n*/\n{katex.script}</script>")
        parts.append(f"<script>{_TYPESET_SCRIPT}</script>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def write_report(folder, meta: RunMetadata, checks: list[CheckResult],
                 figures: list[FigureResult]) -> list[str]:
    """Write ``results.json``, ``report.md`` and ``report.html`` through ``folder`` (a ``RunFolder``).

    Returns the names of the files written.
    """
    results = {"metadata": asdict(meta), "checks": [result_to_json(c) for c in checks],
               "figures": [result_to_json(f) for f in figures]}
    pages = {
        "results.json": json.dumps(results, indent=1, ensure_ascii=False, allow_nan=True).encode(),
        "report.md": render_markdown(meta, checks, figures).encode(),
        "report.html": render_html(meta, checks, figures, lambda name: (folder.staging / name).read_bytes()).encode(),
    }
    for name, data in pages.items():
        folder.write_bytes(name, data)
    return list(pages)
