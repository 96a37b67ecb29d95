"""Rough differential equations: one entry point (:func:`solve`), the :class:`Solver` contract, the schemes, vector fields.

* :mod:`~roughpaths.rde.integrate`: :func:`solve` and its one time loop; :mod:`~roughpaths.rde.solution`: its
  :class:`Solution`; :mod:`~roughpaths.rde.step_control`: the step-controller contract (:class:`StepController`,
  :class:`FixedSteps`, :class:`PIController`); :mod:`~roughpaths.rde.adaptive`: the attempts on a tree.
* :mod:`~roughpaths.rde.base`: the numbered solver contract; one file per scheme family:
  :mod:`~roughpaths.rde.euler` (Euler, Heun), :mod:`~roughpaths.rde.davie` (Davie, Davie3),
  :mod:`~roughpaths.rde.logode` (LogODE, LogODE3).
* :mod:`~roughpaths.rde.vector_fields` and :mod:`~roughpaths.rde.linear_fields`: the fields.
"""

from .base import Solver
from .davie import Davie, Davie3
from .euler import Euler, Heun
from .integrate import SOLVERS, NonFiniteStateError, Solution, solve
from .linear_fields import LinearVectorFields
from .logode import LogODE, LogODE3
from .step_control import FixedSteps, PIController, StepController
from .vector_fields import LinearDrift, VectorFields, central_jacobian

__all__ = [
    "PIController", "FixedSteps", "StepController", "Solver", "Davie", "Davie3", "Euler", "Heun", "SOLVERS", "NonFiniteStateError", "Solution",
    "solve",
    "LinearVectorFields", "LogODE", "LogODE3", "LinearDrift", "VectorFields", "central_jacobian",
]
