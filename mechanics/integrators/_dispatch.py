r"""Which representation runs a coadjoint system: structure constants or matrices, chosen by a cost model.

One :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` serves both representations of an algebra (users do
not choose code paths). Where both are available (a quadratic Hamiltonian, no forces) the solver runs the one a
cost model predicts cheaper:

* a system on a :class:`~mechanics.MatrixLieAlgebra` of small dimension runs the compiled kernel of
  :mod:`._generic_kernels` on its structure constants (formed once, ``n³`` floats) when that is predicted
  cheaper than the isospectral steps of :mod:`._isospectral`;
* a system on a structure-constant :class:`~mechanics.LieAlgebra` that has a matrix basis
  (:meth:`LieAlgebra.from_matrix_basis`) runs the isospectral steps on
  ``MatrixLieAlgebra(basis)`` when those are predicted cheaper (a basis whose trace form is degenerate, e.g.
  se(3)'s, has no matrix path and stays on the constants).

The two are the same equations in the same coordinates and agree to round-off. The choice depends on the
system and the block's step sizes only, never on the batch or the thread count, so a member's bits do not
depend on its neighbours.

The cost model (per path-step, nanoseconds; constants measured by ``benchmarks/bench_lie_algebras.py``):

* compiled kernel: :math:`\kappa_c\,\mathrm{nnz}(c)\,(d + 6)` with ``d`` the Taylor degree the kernel's vector
  path takes at the typical size :math:`\hat\theta = \sum_i \mathrm{cnorm}_i\,\hat\sigma_i` of a step
  (:math:`\hat\sigma_i = (\Delta t\sum_j\xi_{ji}^2)^{1/2}`, the noise part of :math:`\sigma`), plus, on the
  share of the steps whose size exceeds the vector path's limit :math:`\theta_v` (modelled as a Gaussian of mean
  :math:`0.8\hat\theta` and deviation :math:`0.5\hat\theta`, fitted to the measured costs), the dense
  ``n × n`` scaling and squaring the kernel falls back to, :math:`\kappa_f n^3(6 + \log_2(3\hat\theta/\theta_v))`;
* isospectral steps: :math:`\kappa_0 + \kappa_m P N^3` with ``P`` about 16 products per step (doubled
  for complex matrices: a complex product is four real ones, at twice the speed per flop).
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from ..systems.hamiltonian import QuadraticHamiltonian
from ..systems.lie_algebra import LieAlgebra
from ..systems.lie_poisson import LiePoissonSystem
from ..systems.matrix_algebra import MatrixLieAlgebra
from ._generic_member import DEGREE_THETA, THETA_VECTOR

__all__ = ["choose", "member_system", "KAPPA"]

#: Cost constants (ns): per non-zero structure constant and Taylor term, per member-step of Python overhead on
#: the matrix path, per real multiply-add of a product on the matrix path.
KAPPA = {"constants": 0.35, "fallback": 0.7, "matrix_overhead": 3000.0, "matrix": 0.55}
#: Products per isospectral Lie–Heun step (drift twice, predictor, exponential, conjugation), a typical count.
MATRIX_PRODUCTS = 16

_TWINS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _twin(system, algebra):
    h = system.hamiltonian
    if isinstance(h, QuadraticHamiltonian) and h.q_diagonal is None and not np.any(h.q - np.diag(np.diagonal(h.q))):
        h = QuadraticHamiltonian(np.array(np.diagonal(h.q)), h.linear)    # a diagonal Q as its vector: O(n) gradient
    new = LiePoissonSystem(algebra, h, system.xi, system.s, system.theta, system.convention,
                           levy_in_dissipation=system.levy_in_dissipation)
    new._metric_inv = system._metric_inv
    return new


def _constants_twin(system):
    alg = system.algebra
    c = alg.structure_constants
    return _twin(system, LieAlgebra(c, name=alg.name, casimirs=alg.casimirs, casimir_names=alg.casimir_names,
                                    check=False))


def _matrix_twin(system):
    try:
        alg = MatrixLieAlgebra(system.algebra.basis, name=system.algebra.name)
    except ValueError:                       # degenerate trace form (se(3), solvable algebras): no matrix path
        return None
    return _twin(system, alg)


def _cost_constants(system, dt, twins):
    if "stats" not in twins:
        c = system.algebra.structure_constants
        twins["stats"] = (c.shape[0], np.count_nonzero(c), np.max(np.sum(np.abs(c), axis=2), axis=1))
    n, nnz, cnorm = twins["stats"]
    sigma = np.sqrt(dt * np.sum(np.asarray(system.xi) ** 2, axis=0))
    theta = float(np.sum(cnorm * sigma))
    k = KAPPA["constants"]
    vector = k * nnz * (int(np.searchsorted(DEGREE_THETA, min(theta, THETA_VECTOR))) + 6)
    if theta == 0.0:
        return vector
    fallback = KAPPA["fallback"] * float(n) ** 3 * (6.0 + max(0.0, np.log2(3.0 * theta / THETA_VECTOR)))
    share = 0.5 * math.erfc((THETA_VECTOR - 0.8 * theta) / (0.5 * theta * np.sqrt(2.0)))
    return vector + share * fallback


def _cost_matrix(N, complex_):
    return KAPPA["matrix_overhead"] + KAPPA["matrix"] * MATRIX_PRODUCTS * float(N) ** 3 * (2.0 if complex_ else 1.0)


#: The reference step of :func:`member_system`'s choice (typical of adaptive steps at rtol 1e-3 on unit-scale noise).
MEMBER_DT = 1e-2


def member_system(system):
    """The system the steps per member run on (contract item 10; adaptive steps per member): for a quadratic
    Hamiltonian without forces, the representation the cost model predicts cheaper (:func:`choose`) at the reference
    step :data:`MEMBER_DT`: structure constants (compiled, :mod:`._generic_member_steps`) or the matrix twin (the
    numpy path's conjugation of ``N × N`` matrices); otherwise ``system``. Chosen once per system: it depends on the
    system only, never on the steps or the batch. Measured per member-step (``benchmarks/bench_member_steps.py``:
    LieHeun, 1000 members, dt in [0.005, 0.02], one thread; su(N) from its matrix basis, constants against
    matrices): su(2) 0.43 against 2.2 µs, su(3) 1.8 against 3.3 µs, su(4) 14 against 5.7 µs, su(6) 413 against
    26 µs; the model picks the cheaper in each."""
    if not system.hamiltonian.is_quadratic or system.has_forces:
        return system
    twins = _TWINS.setdefault(system, {})
    if "member" not in twins:
        twins["member"] = choose(system, np.array([MEMBER_DT]))[0]
    return twins["member"]


def choose(system, dts):
    """The system to integrate (``system`` itself or its twin on the other representation, cached) and whether it
    is on a matrix algebra, for a quadratic Hamiltonian without forces and the block's steps ``dts``."""
    alg = system.algebra
    dt = float(np.max(dts)) if np.size(dts) else 0.0
    if isinstance(alg, MatrixLieAlgebra):
        if alg.dim > 120:                            # n³ constants: never cheaper at this size
            return system, True
        cm = _cost_matrix(alg.matrix_size, alg.dtype.kind == "c")
        twins = _TWINS.setdefault(system, {})
        if "constants" not in twins:
            twins["constants"] = _constants_twin(system)
        if _cost_constants(twins["constants"], dt, twins) < cm:
            return twins["constants"], False
        return system, True
    if getattr(alg, "basis", None) is None or type(alg) is not LieAlgebra:
        return system, False
    twins = _TWINS.setdefault(system, {})
    if "matrix" not in twins:
        twins["matrix"] = _matrix_twin(system)
    twin = twins["matrix"]
    if twin is None:
        return system, False
    N = twin.algebra.matrix_size
    if _cost_matrix(N, twin.algebra.dtype.kind == "c") < _cost_constants(system, dt, twins):
        return twin, True
    return system, False
