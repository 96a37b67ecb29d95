"""The paper's application: its figures, theorem checks and verification report.

``python -m mechanics`` / ``levy-area-paper`` (:mod:`mechanics.paper.cli`) reproduces the figures
and checks of *Variational Principles on Geometric Rough Paths and the Lévy Area Correction* with
the public API of :mod:`mechanics` and :mod:`roughpaths`; the library never imports this package.

Modules
-------
cli
    The command line: the run, its cost check, exit codes.
options
    The command-line options: the parser and the validation of every value.
figures, checks
    The registries of the paper's figures and of its theorem / proposition checks.
report
    The results and the Markdown / HTML / JSON report.
plotting
    Public plotting helpers behind the figures (sphere trajectories, densities with the Gibbs
    overlay, phase portraits), usable on any simulation.
model
    The paper's Section 4 set-up shared by figures and checks.
sizes, cost
    The sizes each figure and check runs at (presets, ``--set``, factors), and the estimated CPU
    time and peak memory of a run at those sizes.
tasks, output
    What a figure or check receives (seeded streams, sizes, progress), and the output folder
    (atomic writes, lock, manifest, ``--resume``).
"""

from .cli import main

__all__ = ["main"]
