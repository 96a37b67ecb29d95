"""Verification report of the paper's reproduction: Markdown and a self-contained HTML page.

The main job (``python -m mechanics``) collects, for every theorem / proposition check, a
:class:`CheckResult` (claim, predicted and measured numbers, tolerance, pass/fail) and, for every
figure, a :class:`FigureResult` (PNG and the ``.npz`` of the data behind it). :func:`write_report`
turns them into ``report.md`` (figures linked) and ``report.html`` (figures embedded as base64, no
external resources), with the run's metadata (seed, convention, sizes, versions, timings).
"""

from __future__ import annotations

import base64
import html
import platform
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "CheckResult", "FigureResult", "RunMetadata", "Task", "format_value", "write_report", "versions",
]

#: status strings of a check
PASS, FAIL, ERROR, SKIPPED = "pass", "FAIL", "error", "skipped"


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
        Numbers (scalars or small arrays) compared by the check.
    tolerance : str
        The acceptance rule, in words (e.g. ``"|measured - predicted| <= 4 standard errors"``).
    passed : bool or None
        ``None`` when the check could not run (see ``status``).
    status : str
        ``"pass"``, ``"FAIL"``, ``"error"`` (an exception; traceback in ``details``) or ``"skipped"``.
    details : str
        Free-form notes (sizes, standard errors, the failing variant's numbers, ...).
    seconds : float
        Wall time of the check.
    """

    name: str
    statement: str
    predicted: Any = None
    measured: Any = None
    tolerance: str = ""
    passed: bool | None = None
    status: str = ""
    details: str = ""
    seconds: float = 0.0

    def __post_init__(self):
        if not self.status:
            self.status = SKIPPED if self.passed is None else (PASS if self.passed else FAIL)


@dataclass
class FigureResult:
    """One rendered figure: PNG path, data path, caption."""

    name: str
    title: str
    caption: str
    png: Path | None = None
    npz: Path | None = None
    status: str = PASS
    details: str = ""
    seconds: float = 0.0


@dataclass
class RunMetadata:
    """What a reader needs to reproduce the run."""

    command: str
    seed: int
    convention: str
    scale: str
    sizes: dict = field(default_factory=dict)
    versions: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    started: str = ""
    total_seconds: float = 0.0


@dataclass
class Task:
    """A registry entry: a figure or a check, its title/caption, and the modules it needs.

    ``requires`` lists importable names, either ``"package.module"`` or ``"package.module:attribute"``;
    a task whose requirements are missing is reported as skipped (not an error) so that the main job
    runs while the library grows.
    """

    name: str
    title: str
    func: Any
    requires: tuple = ()
    caption: str = ""

    def missing_modules(self) -> list[str]:
        import importlib

        missing = []
        for req in self.requires:
            mod, _, attr = req.partition(":")
            try:
                m = importlib.import_module(mod)
            except ImportError:
                missing.append(mod)
                continue
            if attr and not hasattr(m, attr):
                missing.append(req)
        return missing

    def run(self, ctx):
        return self.func(ctx)


def versions() -> dict:
    """Versions of Python, the platform and the packages the run depends on."""
    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for mod in ("numpy", "scipy", "matplotlib", "numba", "roughpaths", "mechanics"):
        try:
            m = __import__(mod)
            out[mod] = getattr(m, "__version__", "?")
        except Exception:  # pragma: no cover - reported, not fatal
            out[mod] = "not importable"
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
    counts = {PASS: 0, FAIL: 0, ERROR: 0, SKIPPED: 0}
    for c in checks:
        counts[c.status] = counts.get(c.status, 0) + 1
    return counts


_CONVENTION_NOTE = (
    "The checks test the library's rough-path-correct mathematics whatever the convention; where a check "
    "says so, the paper's printed variant is shown to fail. The convention option changes the figures only "
    "(the Lévy torque's sign in Figures 2 and surf2..surf5)."
)


def render_markdown(meta: RunMetadata, checks: list[CheckResult], figures: list[FigureResult],
                    out_dir: Path) -> str:
    """The Markdown report (figures referenced by relative path)."""
    counts = _summary(checks)
    lines = [
        "# Verification report: *Variational Principles on Geometric Rough Paths and the Lévy Area Correction*",
        "",
        f"Convention: **{meta.convention}**"
        + (" (rough-path-correct, see CONVENTIONS.md)" if meta.convention == "rp"
           else " (the paper's printed equations, slips included)")
        + f" · seed **{meta.seed}** · sizes **{meta.scale}** · total time **{meta.total_seconds:.1f} s**",
        "",
        f"Checks: **{counts[PASS]} passed**, {counts[FAIL]} failed, {counts[ERROR]} errors, "
        f"{counts[SKIPPED]} skipped.",
        "",
        _CONVENTION_NOTE,
        "",
        "## Theorem and proposition checks",
        "",
        "| check | claim | predicted | measured | tolerance | result | time (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in checks:
        lines.append(
            f"| `{c.name}` | {_md_escape(c.statement)} | {_md_escape(format_value(c.predicted))} | "
            f"{_md_escape(format_value(c.measured))} | {_md_escape(c.tolerance)} | "
            f"**{c.status}** | {c.seconds:.1f} |"
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
            rel = Path(f.png).relative_to(out_dir) if Path(f.png).is_relative_to(out_dir) else f.png
            lines += [f"![{f.title}]({rel})", ""]
            if f.npz is not None:
                rel_npz = Path(f.npz).relative_to(out_dir) if Path(f.npz).is_relative_to(out_dir) else f.npz
                lines += [f"Data: `{rel_npz}`", ""]
        else:
            lines += [f"*{f.status}*: {_md_escape(f.details.strip().splitlines()[-1] if f.details else '')}", ""]
        lines += [f.caption, ""]
    lines += ["## Run metadata", "", f"- command: `{meta.command}`", f"- started: {meta.started}",
              f"- seed: {meta.seed}", f"- convention: {meta.convention}", f"- sizes: {meta.scale}", ""]
    if meta.sizes:
        lines += ["| size parameter | value |", "|---|---|"]
        lines += [f"| {k} | {format_value(v)} |" for k, v in meta.sizes.items()]
        lines.append("")
    lines += ["| package | version |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in meta.versions.items()]
    lines.append("")
    if meta.timings:
        lines += ["| task | wall time (s) |", "|---|---|"]
        lines += [f"| {k} | {v:.2f} |" for k, v in meta.timings.items()]
        lines.append("")
    return "\n".join(lines) + "\n"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1150px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;margin:1em 0;font-size:0.92em}th,td{border:1px solid #ccc;padding:4px 8px;
vertical-align:top}th{background:#f2f2f2}td.pass{background:#e3f6e3;font-weight:bold}
td.FAIL{background:#fbe0e0;font-weight:bold}td.error{background:#fbe0e0}td.skipped{background:#f4f4f4}
figure{margin:1.5em 0}figure img{max-width:100%;border:1px solid #ddd}figcaption{font-size:0.92em;color:#444}
code,pre{background:#f6f6f6;padding:1px 3px}pre{padding:6px;overflow-x:auto;font-size:0.85em}
.summary{font-size:1.1em}
"""


def render_html(meta: RunMetadata, checks: list[CheckResult], figures: list[FigureResult]) -> str:
    """A self-contained HTML page (figures embedded as base64 PNG)."""
    e = html.escape
    counts = _summary(checks)
    conv = ("rough-path-correct (see CONVENTIONS.md)" if meta.convention == "rp"
            else "the paper's printed equations, slips included")
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<title>Verification report: Lévy area correction</title>",
        f"<style>{_CSS}</style></head><body>",
        "<h1>Verification report: <i>Variational Principles on Geometric Rough Paths and the Lévy Area "
        "Correction</i></h1>",
        f"<p>Convention: <b>{e(meta.convention)}</b> ({e(conv)}) · seed <b>{meta.seed}</b> · sizes "
        f"<b>{e(meta.scale)}</b> · total time <b>{meta.total_seconds:.1f} s</b></p>",
        f"<p class='summary'>Checks: <b>{counts[PASS]} passed</b>, {counts[FAIL]} failed, "
        f"{counts[ERROR]} errors, {counts[SKIPPED]} skipped.</p>",
        f"<p>{e(_CONVENTION_NOTE)}</p>",
        "<h2>Theorem and proposition checks</h2>",
        "<table><tr><th>check</th><th>claim</th><th>predicted</th><th>measured</th><th>tolerance</th>"
        "<th>result</th><th>time (s)</th></tr>",
    ]
    for c in checks:
        parts.append(
            f"<tr><td><code>{e(c.name)}</code></td><td>{e(c.statement)}</td>"
            f"<td>{e(format_value(c.predicted))}</td><td>{e(format_value(c.measured))}</td>"
            f"<td>{e(c.tolerance)}</td><td class='{e(c.status)}'>{e(c.status)}</td>"
            f"<td>{c.seconds:.1f}</td></tr>"
        )
    parts.append("</table>")
    notes = [c for c in checks if c.details]
    if notes:
        parts.append("<h3>Details</h3><ul>")
        for c in notes:
            parts.append(f"<li><code>{e(c.name)}</code>: <pre>{e(c.details.strip())}</pre></li>")
        parts.append("</ul>")
    parts.append("<h2>Figures</h2>")
    for f in figures:
        parts.append(f"<figure id='{e(f.name)}'><h3>{e(f.title)} (<code>{e(f.name)}</code>)</h3>")
        if f.png is not None and f.status == PASS and Path(f.png).exists():
            data = base64.b64encode(Path(f.png).read_bytes()).decode("ascii")
            parts.append(f"<img alt='{e(f.title)}' src='data:image/png;base64,{data}'>")
        else:
            parts.append(f"<p><b>{e(f.status)}</b></p><pre>{e(f.details.strip())}</pre>")
        parts.append(f"<figcaption>{e(f.caption)}</figcaption></figure>")
    parts += ["<h2>Run metadata</h2><table>",
              f"<tr><th>command</th><td><code>{e(meta.command)}</code></td></tr>",
              f"<tr><th>started</th><td>{e(meta.started)}</td></tr>",
              f"<tr><th>seed</th><td>{meta.seed}</td></tr>",
              f"<tr><th>convention</th><td>{e(meta.convention)}</td></tr>",
              f"<tr><th>sizes</th><td>{e(meta.scale)}</td></tr></table>"]
    if meta.sizes:
        parts.append("<table><tr><th>size parameter</th><th>value</th></tr>")
        parts += [f"<tr><td>{e(k)}</td><td>{e(format_value(v))}</td></tr>" for k, v in meta.sizes.items()]
        parts.append("</table>")
    parts.append("<table><tr><th>package</th><th>version</th></tr>")
    parts += [f"<tr><td>{e(k)}</td><td>{e(str(v))}</td></tr>" for k, v in meta.versions.items()]
    parts.append("</table>")
    if meta.timings:
        parts.append("<table><tr><th>task</th><th>wall time (s)</th></tr>")
        parts += [f"<tr><td>{e(k)}</td><td>{v:.2f}</td></tr>" for k, v in meta.timings.items()]
        parts.append("</table>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def write_report(out_dir, meta: RunMetadata, checks: list[CheckResult],
                 figures: list[FigureResult]) -> tuple[Path, Path]:
    """Write ``report.md`` and ``report.html`` into ``out_dir``; return their paths."""
    out = Path(out_dir)
    md = out / "report.md"
    page = out / "report.html"
    md.write_text(render_markdown(meta, checks, figures, out), encoding="utf-8")
    page.write_text(render_html(meta, checks, figures), encoding="utf-8")
    return md, page
