"""Which checks and figures of the main job are beyond the paper, and how their report section is introduced.

The paper's own results (its theorems, propositions and figures) and the library's extensions are reported
apart: a check or figure whose name starts with :data:`BEYOND_THE_PAPER_PREFIX` goes to the section
:data:`BEYOND_TITLE` of ``report.md`` and ``report.html`` (:mod:`mechanics.paper.report`), after the paper's.
"""

from __future__ import annotations

__all__ = ["BEYOND_THE_PAPER_PREFIX", "BEYOND_TITLE", "BEYOND_NOTE", "beyond_the_paper"]

#: checks and figures named with this prefix are beyond the paper (their own section of the report)
BEYOND_THE_PAPER_PREFIX = "sphere_"
#: the heading of their section
BEYOND_TITLE = "Beyond the paper: Euler on the sphere"
#: the paragraph that opens it
BEYOND_NOTE = (
    "Not in the paper. The paper's theory (SALT noise, the Lévy-area correction ℓ = ½ sᶦʲ[ξᵢ, ξⱼ], "
    "Friz–Oberhauser, the isospectral schemes of strong order 1) run on Zeitlin's model of the incompressible "
    "Euler equations on the unit sphere (two-dimensional), a Lie–Poisson system on su(N) whose Casimirs "
    "tr((iW)ᵏ) are the discrete enstrophies and which converges to the Euler equations as N grows "
    "(mechanics.sphere; tutorial docs/tutorials/euler-sphere.md)."
)


def beyond_the_paper(name: str) -> bool:
    """Whether the check or figure ``name`` belongs to the section "Beyond the paper" (not the paper's own results).

    Examples
    --------
    >>> beyond_the_paper("sphere_casimirs"), beyond_the_paper("chen")
    (True, False)
    """
    return str(name).startswith(BEYOND_THE_PAPER_PREFIX)
