r"""Ensembles of Brownian-driven Lie–Poisson paths, reduced to statistics on the fly.

:func:`run_ensemble` (:mod:`.run`) simulates many independent paths of a system on top of
:func:`roughpaths.solve` and returns an :class:`EnsembleResult` (:mod:`.result`, which
``roughpaths.save`` / ``roughpaths.load`` write and read); the streaming, chunking-independent
statistics (:class:`RunningMoments`, the fixed-leaf reduction) are in :mod:`.statistics` and the
resumable, fingerprinted checkpoint file in :mod:`.checkpoint`.
"""

from .result import EnsembleResult
from .run import run_ensemble
from .statistics import RunningMoments, moment_observable, split_moment_features

__all__ = ["run_ensemble", "EnsembleResult", "RunningMoments", "moment_observable", "split_moment_features"]
