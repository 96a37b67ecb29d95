"""The vendored KaTeX, read and checked, to be embedded in the self-contained ``report.html``.

KaTeX (the npm package ``katex``) is vendored into ``docs/assets/vendor/katex/`` of the source tree
by ``tools/vendor_katex.sh`` (``./test.sh`` runs it; the folder is gitignored, and ``./run.sh``,
which installs the Python dependencies only, does not). :func:`load_katex` reads that folder and
returns its script and its style sheet with the fonts inlined as ``data:`` URIs (WOFF2 only, which
every current browser reads), so that the report still opens offline as one file. The files are
untrusted input: sizes are bounded, the font references must be plain KaTeX font names in the
folder, and a script that could end its ``<script>`` element early is refused. Where anything is
missing or wrong, :func:`load_katex` says why in a :class:`KatexUnavailable` and the report shows
its formulas as plain HTML instead (module ``_html_formula``).
"""

from __future__ import annotations

import base64
import os
import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["KATEX_DIR", "Katex", "KatexUnavailable", "load_katex"]

#: where tools/vendor_katex.sh puts KaTeX in the source tree
KATEX_DIR = Path(__file__).resolve().parents[2] / "docs" / "assets" / "vendor" / "katex"
#: bounds on the files read (KaTeX 0.16: script 0.28 MB, style sheet 23 kB, fonts 4-28 kB, 0.27 MB in all)
_MAX_SCRIPT, _MAX_CSS, _MAX_FONT, _MAX_FONTS = 2_000_000, 200_000, 500_000, 3_000_000
_FONT_FACE_SRC = re.compile(r"src:\s*url\((?P<q>['\"]?)fonts/(?P<name>KaTeX_[A-Za-z0-9_-]+)\.woff2(?P=q)\)"
                            r"\s*format\([\"']woff2[\"']\)(?:,\s*url\([^)]*\)\s*format\([^)]*\))*")


class KatexUnavailable(Exception):
    """KaTeX cannot be embedded; the message says why and how to get it."""


@dataclass(frozen=True)
class Katex:
    """KaTeX ready to embed: ``version``, ``licence`` text, ``script`` and ``css`` (fonts as data URIs)."""

    version: str
    licence: str
    script: str
    css: str


def _read(path: Path, limit: int) -> bytes:
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise KatexUnavailable(f"{path.name} is missing from the vendored KaTeX ({exc.strerror})") from None
    if size > limit:
        raise KatexUnavailable(f"{path.name} of the vendored KaTeX is {size:,} bytes, more than the {limit:,} "
                               f"expected: re-vendor it with tools/vendor_katex.sh")
    return path.read_bytes()


def load_katex(folder: str | os.PathLike = KATEX_DIR) -> Katex:
    """Read the vendored KaTeX in ``folder`` and prepare it for embedding.

    Parameters
    ----------
    folder : path-like
        A folder as ``tools/vendor_katex.sh`` makes it: ``VERSION``, ``LICENSE``, ``katex.min.js``,
        ``katex.min.css`` and ``fonts/*.woff2``.

    Returns
    -------
    Katex

    Raises
    ------
    KatexUnavailable
        The folder or a file is missing, too large, or not what KaTeX ships (the message says which).
    TypeError
        ``folder`` is not a path.

    Examples
    --------
    >>> try:
    ...     k = load_katex()
    ... except KatexUnavailable:
    ...     k = None           # not vendored here: the report falls back to plain HTML formulas
    >>> k is None or ("katex" in k.script and "data:font/woff2;base64," in k.css)
    True
    """
    if not isinstance(folder, (str, os.PathLike)):
        raise TypeError(f"folder must be a path to the vendored KaTeX, got {type(folder).__name__}: pass e.g. "
                        f"docs/assets/vendor/katex.")
    folder = Path(folder)
    if not folder.is_dir():
        raise KatexUnavailable(f"KaTeX is not vendored in {folder.name}/ (tools/vendor_katex.sh installs it)")
    version = _read(folder / "VERSION", 100).decode("ascii", "replace").strip()
    if not re.fullmatch(r"\d+\.\d+\.\d+", version):
        raise KatexUnavailable(f"VERSION of the vendored KaTeX reads {version[:20]!r}, not a version number: "
                               f"re-vendor it with tools/vendor_katex.sh")
    licence = _read(folder / "LICENSE", 10_000).decode("utf-8", "replace").strip()
    script = _read(folder / "katex.min.js", _MAX_SCRIPT).decode("utf-8", "replace")
    css = _read(folder / "katex.min.css", _MAX_CSS).decode("utf-8", "replace")
    lowered = script.lower()
    if "</script" in lowered or "<!--" in lowered or "katex" not in lowered:
        raise KatexUnavailable("katex.min.js of the vendored KaTeX is not KaTeX's script or could not be embedded "
                               "in an HTML page: re-vendor it with tools/vendor_katex.sh")
    # KaTeX names the SVG and MathML namespaces in string literals ("http://www.w3.org/..."); nothing is
    # fetched from them. Written "http:\/\/..." (the same string in JavaScript), the page holds no URL.
    if len(re.findall(r"https?://", script)) != len(re.findall(r"[\"']https?://www\.w3\.org/", script)):
        raise KatexUnavailable("katex.min.js of the vendored KaTeX refers to addresses other than the SVG and "
                               "MathML namespaces: re-vendor it with tools/vendor_katex.sh")
    script = re.sub(r"(https?):/{2}", r"\1:\\/\\/", script)
    total = 0

    def inline(m: re.Match) -> str:
        nonlocal total
        data = _read(folder / "fonts" / f"{m.group('name')}.woff2", _MAX_FONT)
        total += len(data)
        if total > _MAX_FONTS:
            raise KatexUnavailable(f"the fonts of the vendored KaTeX exceed {_MAX_FONTS:,} bytes: re-vendor it with "
                                   f"tools/vendor_katex.sh")
        return f"src:url(data:font/woff2;base64,{base64.b64encode(data).decode('ascii')}) format(\"woff2\")"

    css, fonts = _FONT_FACE_SRC.subn(inline, css)
    leftover = re.findall(r"url\((?!data:)[^)]*\)", css)
    if fonts == 0 or leftover or "</style" in css.lower():
        raise KatexUnavailable(f"katex.min.css of the vendored KaTeX refers to files other than its WOFF2 fonts "
                               f"({leftover[:2]}): re-vendor it with tools/vendor_katex.sh")
    return Katex(version, licence, script, css)
