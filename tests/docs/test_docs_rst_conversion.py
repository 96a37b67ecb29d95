"""``tools/griffe_rst.py`` turns the docstrings' reStructuredText into the Markdown the site renders.

Claims, on hand-written inputs with the expected output written out here: a ``:math:`` role becomes
``$…$``; a ``.. math::`` directive becomes one ``$$`` block per equation (``aligned`` added where
Sphinx would add ``split``); a cross-reference role resolves in the docstring's scope to the canonical
path of the object (where mkdocstrings renders it) and becomes an optional autorefs link, an external
one becomes code; RST list indentation becomes Markdown's; on the verbatim "name : type" lines of
numpydoc sections roles become plain text.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

griffe = pytest.importorskip("griffe", reason="griffe comes with the docs extra (mkdocstrings[python])")
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import griffe_rst  # noqa: E402


def test_math_role_and_directive():
    text = "A :math:`x_1\n  + y` here.\n\n.. math:: a = b\n          + c\n\n   d = e\n\nAfter."
    assert griffe_rst.convert(text) == "A $x_1 + y$ here.\n\n$$\na = b\n+ c\n$$\n\n$$\nd = e\n$$\n\nAfter."


def test_multiline_equation_gets_aligned():
    out = griffe_rst.convert(".. math::\n\n    a &= b,\\\\\n    c &= d\n")
    assert out.startswith("$$\n\\begin{aligned}\na &= b,\\\\\nc &= d\n\\end{aligned}\n$$")


def test_cross_references_resolve_to_canonical_paths():
    pkg = griffe.load("roughpaths", search_paths=[str(Path(__file__).resolve().parents[2])])
    solve = pkg["solve"]  # the re-exported function; its scope imports RoughPath from ..paths.rough_path
    out = griffe_rst.convert(":class:`RoughPath`, :func:`~roughpaths.solve`, :meth:`RoughPath.increment`, "
                             ":class:`numpy.random.Generator`, :class:`Nowhere`", solve)
    assert out == (
        '<autoref identifier="roughpaths.paths.rough_path.RoughPath" optional><code>RoughPath</code></autoref>, '
        '<autoref identifier="roughpaths.rde.integrate.solve" optional><code>solve()</code></autoref>, '
        '<autoref identifier="roughpaths.paths.rough_path.RoughPath.increment" optional>'
        '<code>RoughPath.increment()</code></autoref>, '
        '<code>numpy.random.Generator</code>, <code>Nowhere</code>')


def test_lists_reindented_for_markdown():
    text = "* one\n  more\n\n  para\n\n  - nested\n\n    nested para\n* two\n\nText."
    assert griffe_rst.rst_lists_to_markdown(text) == (
        "* one\n    more\n\n    para\n\n    - nested\n\n        nested para\n* two\n\nText.")


def test_typed_section_entry_lines_are_plain():
    text = ("Returns\n-------\nmean : ndarray ``(3,)``\n    The :math:`\\mu`, see :class:`~a.B`.\n"
            "See :class:`~a.B` for :math:`x`.\n\nNotes\n-----\nUses :math:`y`.")
    assert griffe_rst.convert(text) == (
        "Returns\n-------\nmean : ndarray (3,)\n    The $\\mu$, see <code>B</code>.\nSee B for x.\n\n"
        "Notes\n-----\nUses $y$.")
