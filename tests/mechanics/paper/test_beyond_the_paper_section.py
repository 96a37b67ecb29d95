"""The report keeps the paper's results and the library's extensions apart, and the sphere plotting helpers.

Claims:

* checks and figures named ``sphere_*`` (mechanics.paper.beyond) are reported in the section "Beyond the paper:
  Euler on the sphere", after the paper's checks and figures, in report.md and report.html; the paper's tables
  do not hold them; without any such result the section is absent;
* the main job registers its sphere checks and figure after the paper's own (report order);
* ``enstrophy_spectrum`` sums to the enstrophy 1/2 int omega^2 dA (Parseval, against the trace formula of
  mechanics.sphere.enstrophy); the field helpers refuse a grid whose shape does not match and an unknown view.
"""

import numpy as np
import pytest

from mechanics.paper.beyond import BEYOND_TITLE, beyond_the_paper
from mechanics.paper.checks import CHECKS
from mechanics.paper.figures import FIGURES
from mechanics.paper.plotting import enstrophy_spectrum, new_figure, plot_field_hemisphere, plot_field_latlon
from mechanics.paper.report import CheckResult, FigureResult, RunMetadata, render_html, render_markdown
from mechanics.sphere import coefficients_to_matrix, enstrophy


def _results():
    meta = RunMetadata(command="levy-area-paper --tiny", seed=3, convention="rp", scale="tiny")
    checks = [CheckResult("chen", "Chen", predicted=0.0, measured=0.0, passed=True, details="paper note"),
              CheckResult("sphere_casimirs", "Casimirs of Zeitlin's model", predicted=0.0, measured=1e-15,
                          passed=True, details="sphere note")]
    figures = [FigureResult("fig1", "Figure 1", "caption 1", png="fig1.png"),
               FigureResult("sphere_euler", "Sphere figure", "caption sphere", png="sphere_euler.png")]
    return meta, checks, figures


def test_markdown_puts_sphere_results_in_their_own_section_after_the_paper():
    md = render_markdown(*_results())
    paper, beyond = md.split(f"## {BEYOND_TITLE}")
    assert "`chen`" in paper and "Figure 1" in paper and "sphere_" not in paper
    assert "`sphere_casimirs`" in beyond and "Sphere figure" in beyond and "`chen`" not in beyond
    assert beyond.index("sphere note") < beyond.index("Sphere figure") < beyond.index("## Run metadata")
    assert "Checks: **2 passed**, 0 failed, 0 errors. (1 of them beyond the paper, in their own section.)" in paper


def test_html_puts_sphere_results_in_their_own_section_after_the_paper():
    page = render_html(*_results(), lambda name: b"\x89PNG fake", katex_dir=None)
    start, end = page.index("<section id='beyond-the-paper'>"), page.index("</section>")
    assert page.index("<h2>Figures</h2>") < page.index("id='fig1'") < start < page.index("id='sphere_euler'") < end
    assert "sphere_casimirs" in page[start:end] and "sphere_casimirs" not in page[:start]
    meta, checks, figures = _results()
    assert "beyond-the-paper" not in render_html(meta, checks[:1], figures[:1], lambda n: b"", katex_dir=None)
    assert BEYOND_TITLE not in render_markdown(meta, checks[:1], figures[:1])


def test_sphere_tasks_are_registered_after_the_papers():
    for registry in (CHECKS, FIGURES):
        names = list(registry)
        flags = [beyond_the_paper(n) for n in names]
        assert any(flags) and flags == sorted(flags), names      # all paper tasks first, then the sphere ones


def test_enstrophy_spectrum_sums_to_the_enstrophy():
    rng = np.random.default_rng(5)
    L, N = 6, 12
    omega = np.zeros(L * L, dtype=complex)
    for l in range(1, L):
        omega[l * (l + 1)] = rng.standard_normal()
        for m in range(1, l + 1):
            c = rng.standard_normal() + 1j * rng.standard_normal()
            omega[l * (l + 1) + m], omega[l * (l + 1) - m] = c, (-1) ** m * np.conj(c)
    Z = enstrophy_spectrum(omega)
    assert Z.shape == (L,) and Z[0] == 0.0
    assert np.isclose(Z.sum(), enstrophy(coefficients_to_matrix(omega, N)), rtol=1e-12)
    assert np.isclose(Z[2], 0.5 * np.sum(np.abs(omega[4:9]) ** 2))
    with pytest.raises(ValueError, match="L\\*\\*2"):
        enstrophy_spectrum(np.zeros(10))


def test_field_helpers_refuse_bad_grids_and_views():
    ax = new_figure().add_subplot()
    theta, phi = np.linspace(0.1, 3.0, 8), np.linspace(0.0, 6.0, 16)
    with pytest.raises(ValueError, match="view must be"):
        plot_field_hemisphere(ax, theta, phi, np.zeros((8, 16)), "east")
    with pytest.raises(ValueError, match="shape"):
        plot_field_latlon(ax, theta, phi, np.zeros((16, 8)))
    plot_field_hemisphere(ax, theta, phi, np.ones((8, 16)), "south")
