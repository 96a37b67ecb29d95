r"""Families of vector fields :math:`(V_0, V_1, \dots, V_d)` on :math:`\mathbb{R}^e` for RDEs.

The rough differential equation is

.. math:: dY = V_0(Y)\,dt + \sum_{i=1}^d V_i(Y)\,d\mathbf{X}^i, \qquad V_i : \mathbb{R}^e \to \mathbb{R}^e .

A family is one object; every method is vectorised over leading batch axes of ``y`` (shape
``(..., e)``). Naming, said once: the maths' :math:`V_0` is the drift (``drift=`` here and in
:func:`roughpaths.solve`), and the driving fields :math:`V_1..V_d` are indexed from 0 in the API
(``fields(y)[..., :, i]`` and ``bracket(i, j)`` refer to :math:`V_{i+1}`). Fields may depend on time,
:math:`V_i(t, y)` (``time_dependent=True``); autonomous fields are the default. Conventions (``docs/conventions.md``):

* ``fields(y)[..., a, i]`` is :math:`V_i^a(y)` (shape ``(..., e, d)``);
* ``jacobians(y)[..., i, a, b]`` is :math:`\partial_b V_i^a(y)` (shape ``(..., d, e, e)``);
* Jacobi–Lie bracket :math:`[V, W] = DW\cdot V - DV\cdot W` (so :math:`[V, W]f = V(Wf) - W(Vf)`);
  for linear fields :math:`V_i(y) = M_i y`: :math:`[V_i, V_j](y) = (M_j M_i - M_i M_j)\,y`;
* Friz–Oberhauser drift of an antisymmetric ``s``:
  :math:`\tfrac12\sum_{i,j} s^{ij}[V_i, V_j] = \sum_{i,j} s^{ij}\,DV_j\cdot V_i`. Driving the RDE by
  :math:`(X, \mathbb{X} + s\,(t - s))` is the same as adding this drift. (The paper's printed
  Theorem A.1, :math:`\tfrac12\sum_{i\le j}`, and its composition-order bracket are slips.)

Three ways to build a family:

* :class:`~roughpaths.LinearVectorFields` (:mod:`roughpaths.rde.linear_fields`) from matrices
  ``M`` (shape ``(d, e, e)``) and an optional drift matrix; Jacobians and brackets are exact, and
  :class:`~roughpaths.LogODE` uses an exact matrix exponential.
* :class:`VectorFields` from callables with a user Jacobian (exact).
* :class:`VectorFields` from callables without a Jacobian: it is computed by central differences
  with step :math:`h_b = \varepsilon^{1/3}\max(1, |y_b|)` (:math:`\varepsilon` = float64 machine
  epsilon, so :math:`h_b \approx 6\cdot10^{-6}`), costing ``2 e`` evaluations of the fields. The error
  is :math:`\approx h^2 |D^3 V|/6 + \varepsilon |V| / h`, i.e. about ``1e-10`` relative for fields
  with moderate third derivatives (measured in ``tests/roughpaths/rde/test_vector_fields.py``).
"""

from __future__ import annotations

import numbers

import numpy as np

from ._field_callables import (_Autonomous, _Bracket, _Frozen, _FrizOberhauserDrift, _signature_hint,
                              _Stack, _Sum)
from .._linalg import matvec
from ..validation import as_float_array, check_antisymmetric

__all__ = ["VectorFields", "LinearDrift", "FD_STEP", "central_jacobian"]

#: Relative central-difference step, :math:`\varepsilon^{1/3}` with :math:`\varepsilon` the float64 epsilon.
FD_STEP = float(np.finfo(np.float64).eps ** (1.0 / 3.0))


class LinearDrift:
    r"""The linear vector field :math:`y \mapsto A y` (callable, batched), with its matrix ``A`` (``(e, e)``).

    Returned by :meth:`VectorFields.friz_oberhauser_drift` for linear families, and accepted wherever
    a drift is (a linear family stays linear when a :class:`LinearDrift` is added).
    """

    __slots__ = ("matrix",)

    def __init__(self, matrix):
        m = as_float_array(matrix, "matrix", ndim=2)
        if m.shape[0] != m.shape[1]:
            raise ValueError(f"matrix must be square (e, e), got shape {m.shape}.")
        self.matrix = m

    def __call__(self, y):
        return matvec(self.matrix, np.asarray(y, dtype=np.float64))

    def jacobian(self, y):
        """``(..., e, e)``: the matrix, broadcast over the batch of ``y``."""
        y = np.asarray(y, dtype=np.float64)
        return np.broadcast_to(self.matrix, y.shape[:-1] + self.matrix.shape)

    def __repr__(self) -> str:
        return f"LinearDrift(e={self.matrix.shape[0]})"


def _as_callable(f, name):
    if f is None:
        return None
    if not callable(f):
        raise TypeError(f"{name} must be a callable y -> array (batched over leading axes of y), got "
                        f"{type(f).__name__}; wrap constants in a function or pass a matrix to "
                        f"LinearVectorFields.")
    return f


class VectorFields:
    r"""A family :math:`(V_0; V_1, \dots, V_d)` of vector fields on :math:`\mathbb{R}^e` given by callables.

    Naming: the maths writes :math:`V_0` for the drift and :math:`V_1..V_d` for the driving fields;
    the API indexes the **driving** fields from 0, so column / index ``i`` of :meth:`fields`,
    :meth:`jacobians` and :meth:`bracket` is :math:`V_{i+1}`, and :math:`V_0` is ``drift``.

    Parameters
    ----------
    fields : callable or sequence of d callables
        Either one callable ``y (..., e) -> (..., e, d)`` (column ``i`` is the driving field
        :math:`V_{i+1}`), or a list of ``d`` callables ``y (..., e) -> (..., e)``. Callables must accept
        leading batch axes (checked at construction on a batch of distinct random points against
        one-point evaluations).
    jacobians : callable or sequence of d callables, optional
        ``y -> (..., d, e, e)`` with ``[..., i, a, b] = ∂_b V_{i+1}^a``, or ``d`` callables
        ``y -> (..., e, e)``. If omitted, computed by central differences (step ``FD_STEP·max(1,|y_b|)``,
        about ``1e-10`` relative accuracy; see the module docstring).
    drift : callable, LinearDrift, array_like (e, e) or None
        :math:`V_0`: ``y (..., e) -> (..., e)``; a matrix ``A`` means ``y -> A y``. None: no drift.
    drift_jacobian : callable, optional
        ``y -> (..., e, e)``; computed by central differences if omitted and ever needed.
    dim_state, dim_noise : int
        ``e`` and ``d``. Required for callables (no shapes can be inferred without evaluating them).
    time_dependent : bool
        If True, every callable takes ``(t, y)`` (``t`` a float) instead of ``y``; the solvers pass
        the time (see each solver for where in the step the fields are evaluated). Default False:
        autonomous fields.
    batched_time : bool
        With ``time_dependent=True``: the callables also accept ``t`` as an array of shape ``(..., 1)`` (the
        batch axes of ``y`` and one axis), each point at its own time, and broadcast it themselves (e.g.
        ``sigma(t)[..., None] * ...`` for an ``(..., e, d)`` output); checked at construction against
        one-point evaluations. Then adaptive steps per member (:func:`~roughpaths.solve`) step every member
        on its own times in one call instead of one call per member. Default False.

    Notes
    -----
    A family built from module-level functions (or other picklable callables) pickles, so it can be
    sent to a process pool; lambdas and local functions cannot be pickled by Python.

    Examples
    --------
    A rotation field and a radial field on the plane (they commute, so the bracket vanishes):

    >>> import numpy as np
    >>> from roughpaths import VectorFields
    >>> rot = lambda y: np.stack([-y[..., 1], y[..., 0]], axis=-1)
    >>> rad = lambda y: y
    >>> V = VectorFields([rot, rad], dim_state=2, dim_noise=2)
    >>> V.fields(np.array([1.0, 2.0]))      # columns: driving fields V_1(y), V_2(y) (API indices 0, 1)
    array([[-2.,  1.],
           [ 1.,  2.]])
    >>> np.allclose(V.bracket(0, 1)(np.array([0.3, -0.2])), 0.0)
    True

    A time-dependent field :math:`V_1(t, y) = \cos(t)\, y`:

    >>> W = VectorFields(lambda t, y: (np.cos(t) * y)[..., None], dim_state=1, dim_noise=1,
    ...                  time_dependent=True)
    >>> W.fields(np.array([2.0]), t=0.0)
    array([[2.]])
    """

    is_linear = False
    time_dependent = False
    batched_time = False

    def __init__(self, fields, jacobians=None, *, drift=None, drift_jacobian=None,
                 dim_state=None, dim_noise=None, time_dependent=False, batched_time=False):
        from ..validation import check_positive_int
        if dim_state is None or dim_noise is None:
            raise TypeError("dim_state (e) and dim_noise (d) are required for callable vector fields, "
                            "e.g. VectorFields(f, dim_state=3, dim_noise=2).")
        if not isinstance(time_dependent, (bool, np.bool_)):
            raise TypeError(f"time_dependent must be True or False, got {time_dependent!r}.")
        if batched_time not in (True, False) or (batched_time and not time_dependent):
            raise ValueError(f"batched_time must be True or False and needs time_dependent=True, got "
                             f"batched_time={batched_time!r}, time_dependent={time_dependent!r}.")
        self.batched_time = bool(batched_time)
        self.dim_state = check_positive_int(dim_state, "dim_state")
        self.dim_noise = check_positive_int(dim_noise, "dim_noise")
        from ..validation import check_memory
        check_memory(8.0 * 64 * self.dim_state * self.dim_state * self.dim_noise,
                     f"probing fields with dim_state={self.dim_state} and dim_noise={self.dim_noise} (Jacobians "
                     f"of shape (dim_noise, dim_state, dim_state) on a small batch)", "check dim_state and dim_noise")
        self.time_dependent = bool(time_dependent)
        wrap = (lambda f: f) if self.time_dependent else _Autonomous
        d = self.dim_noise
        if isinstance(fields, (list, tuple)):
            if len(fields) != d:
                raise ValueError(f"fields is a list of {len(fields)} callables but dim_noise={d}; "
                                 f"give one callable per driving component.")
            self._fields = _Stack([wrap(_as_callable(f, f"fields[{i}]")) for i, f in enumerate(fields)], -1)
        else:
            f = _as_callable(fields, "fields")
            if f is None:
                raise TypeError("fields must be a callable or a list of callables, got None.")
            self._fields = wrap(f)
        if isinstance(jacobians, (list, tuple)):
            if len(jacobians) != d:
                raise ValueError(f"jacobians is a list of {len(jacobians)} callables but dim_noise={d}.")
            self._jac = _Stack([wrap(_as_callable(f, f"jacobians[{i}]")) for i, f in enumerate(jacobians)], -3)
        else:
            j = _as_callable(jacobians, "jacobians")
            self._jac = None if j is None else wrap(j)
        self._drift, self._drift_jac = _parse_drift(drift, drift_jacobian, self.dim_state, self.time_dependent)
        self._raw = (fields, jacobians, drift)
        self._check_shapes()

    # ------------------------------------------------------------------ helpers
    def _probe(self, f, y, name, raw):
        t = 0.25
        try:
            return np.asarray(f(t, y))
        except TypeError as exc:
            hint = (_signature_hint(raw, name) if not self.time_dependent else
                    f" With time_dependent=True, {name} is called as {name}(t, y): define it with two "
                    f"arguments (t, y), or pass time_dependent=False for {name}(y).")
            raise TypeError(f"calling {name} on y of shape {y.shape} failed: {exc}.{hint}") from None
        except Exception as exc:             # the user's callable failed on a valid probe point
            raise ValueError(f"calling {name} on the probe point y of shape {y.shape} raised "
                             f"{type(exc).__name__}: {exc}; {name} must be defined on (..., e) arrays.") from exc

    def _check_shapes(self):
        e, d = self.dim_state, self.dim_noise
        raw_f, raw_j, raw_d = getattr(self, "_raw", (None, None, None))
        y = np.linspace(0.1, 0.3, e)
        checks = [("fields", self._fields, (e, d), raw_f, "(e, d)")]
        if self._jac is not None:
            checks.append(("jacobians", self._jac, (d, e, e), raw_j, "(d, e, e)"))
        if self._drift is not None:
            checks.append(("drift", self._drift, (e,), raw_d, "(e,)"))
        for name, fn, tail, raw, label in checks:
            one = self._probe(fn, y, name, raw)
            if one.shape != tail:
                raise ValueError(f"{name}(y) for y of shape ({e},) must return shape {label} = {tail}, got "
                                 f"{one.shape}; check dim_state/dim_noise or the callable.")
        # Batching probe: distinct random points in a (2, 3) batch, each row compared with its own
        # one-point evaluation (identical rows, or a batch as long as e, could hide a callable that
        # indexes y[k] instead of y[..., k]).
        yb = np.random.default_rng(12345).uniform(0.1, 0.9, size=(2, 3, e))
        for name, fn, tail, raw, _ in checks:
            fb = self._probe(fn, yb, name, raw)
            if fb.shape != (2, 3) + tail:
                raise ValueError(f"{name} must be batched: for y of shape (2, 3, {e}) it must return "
                                 f"{(2, 3) + tail}, got {fb.shape}; use y[..., k] rather than y[k] inside "
                                 f"the callable.")
            # tolerance: an indexing bug gives O(1) differences, while a field derived by finite
            # differences (e.g. a Friz–Oberhauser drift of fields without Jacobians) amplifies the
            # last-bit differences of a batched BLAS product in the user's callable to ~1e-10
            scale = max(1.0, float(np.nanmax(np.abs(fb), initial=0.0)))
            tb = np.array([[[0.1], [0.4], [0.7]], [[0.2], [0.5], [0.9]]]) if self.batched_time else None
            if tb is not None:
                try:
                    fb = np.broadcast_to(np.asarray(fn(tb, yb)), fb.shape)
                except Exception as exc:
                    raise ValueError(f"{name} was declared batched_time=True but failed on t of shape (2, 3, 1): "
                                     f"{type(exc).__name__}: {exc}; broadcast t against the output (e.g. "
                                     f"sigma(t)[..., None] * ...) or drop batched_time.") from None
            for k in ((0, 0), (1, 2)):
                one = np.asarray(fn(0.25 if tb is None else float(tb[k][0]), yb[k]))
                if not np.allclose(fb[k], one, rtol=1e-8, atol=1e-8 * scale, equal_nan=True):
                    raise ValueError(f"{name} is not batched correctly: for a batch y of shape (2, 3, {e}) "
                                     f"its row {k} differs from {name} evaluated at that point alone; the "
                                     f"callable must act on the last axis only (use y[..., k] rather than "
                                     f"y[k], and axis=-1 in reductions).")

    @property
    def has_drift(self) -> bool:
        """Whether :math:`V_0` is non-zero (given)."""
        return self._drift is not None

    def _time(self, t):
        if t is None:
            if self.time_dependent:
                raise ValueError("t is required: this family is time-dependent (time_dependent=True); "
                                 "pass the time, e.g. V.fields(y, t).")
            return 0.0
        return t

    # ------------------------------------------------------------------ evaluation
    def drift(self, y, t=None) -> np.ndarray:
        """:math:`V_0(t, y)`, shape ``(..., e)`` (zeros if the family has no drift); ``t`` only if time-dependent."""
        y = np.asarray(y, dtype=np.float64)
        if self._drift is None:
            return np.zeros_like(y)
        return np.asarray(self._drift(self._time(t), y), dtype=np.float64)

    def fields(self, y, t=None) -> np.ndarray:
        """The driving fields as ``[..., a, i]`` (column ``i`` is :math:`V_{i+1}`), shape ``(..., e, d)``."""
        return np.asarray(self._fields(self._time(t), np.asarray(y, dtype=np.float64)), dtype=np.float64)

    def jacobians(self, y, t=None) -> np.ndarray:
        r""":math:`\partial_b V_{i+1}^a(t, y)` as ``[..., i, a, b]``, shape ``(..., d, e, e)``."""
        y = np.asarray(y, dtype=np.float64)
        t = self._time(t)
        if self._jac is not None:
            return np.asarray(self._jac(t, y), dtype=np.float64)
        # central differences; J[..., a, i, b] then moved to [..., i, a, b]
        return np.moveaxis(central_jacobian(_Frozen(self._fields, t), y), -2, -3)

    def drift_jacobian(self, y, t=None) -> np.ndarray:
        r""":math:`\partial_b V_0^a(t, y)`, shape ``(..., e, e)``."""
        y = np.asarray(y, dtype=np.float64)
        if self._drift is None:
            return np.zeros(y.shape + (y.shape[-1],))
        t = self._time(t)
        if self._drift_jac is not None:
            return np.asarray(self._drift_jac(t, y), dtype=np.float64)
        return central_jacobian(_Frozen(self._drift, t), y)

    # ------------------------------------------------------------------ brackets
    def _check_index(self, i, name):
        if isinstance(i, bool) or not isinstance(i, numbers.Integral) or not 0 <= i < self.dim_noise:
            raise ValueError(f"{name} must be an integer field index in 0..{self.dim_noise - 1} "
                             f"(driving fields V_1..V_d, 0-based; the drift V_0 is not indexed), got {i!r}.")
        return int(i)

    def bracket(self, i, j):
        r"""The Jacobi–Lie bracket of the driving fields ``i`` and ``j`` (0-based: :math:`[V_{i+1}, V_{j+1}]`).

        :math:`[V, W] = DW\cdot V - DV\cdot W`. Returns a callable ``y -> (..., e)`` (``(t, y)`` for a
        time-dependent family, the bracket at frozen time ``t``).
        """
        return _Bracket(self, self._check_index(i, "i"), self._check_index(j, "j"))

    def brackets(self, y, t=None) -> np.ndarray:
        r"""All brackets of the driving fields as ``[..., i, j, a]``, shape ``(..., d, d, e)`` (0-based indices)."""
        y = np.asarray(y, dtype=np.float64)
        V, J = self.fields(y, t), self.jacobians(y, t)
        d = self.dim_noise
        # [i, j] = DV_j · V_i, one stacked mat-vec per pair (a fixed order for every batch member)
        DVjVi = np.stack([np.stack([(J[..., j, :, :] @ V[..., :, i, None])[..., 0] for j in range(d)], axis=-2)
                          for i in range(d)], axis=-3)
        return DVjVi - np.swapaxes(DVjVi, -2, -3)

    def friz_oberhauser_drift(self, s):
        r"""The drift :math:`\tfrac12\sum_{i,j} s^{ij}[V_i, V_j]` equivalent to perturbing the area by ``s (t-s)``.

        Parameters
        ----------
        s : array_like, shape ``(d, d)``
            Antisymmetric (a non-antisymmetric ``s`` is rejected: it breaks geometricity). Indices are
            those of the driving fields (0-based in the API).

        Returns
        -------
        callable ``y (..., e) -> (..., e)`` (``(t, y)`` for a time-dependent family)
            A :class:`LinearDrift` for linear families. Equal to :math:`\sum_{i,j} s^{ij} DV_j\cdot V_i`
            and to :math:`\sum_{i<j} s^{ij}[V_i, V_j]`.
        """
        s = check_antisymmetric(s, "s", dim=self.dim_noise)
        if s.ndim != 2:
            raise ValueError(f"s must have shape (d, d) = ({self.dim_noise}, {self.dim_noise}), got {s.shape}.")
        return _FrizOberhauserDrift(self, s)

    # ------------------------------------------------------------------ composition
    def with_drift(self, extra, jacobian=None) -> "VectorFields":
        r"""A new family with drift :math:`V_0 + \text{extra}` (same driving fields).

        ``extra`` is a callable (``y -> (..., e)``, or ``(t, y) -> (..., e)`` for a time-dependent
        family), a :class:`LinearDrift`, or a matrix ``(e, e)``.
        """
        f, fj = _parse_drift(extra, jacobian, self.dim_state, self.time_dependent)
        if f is None:
            return self
        new = object.__new__(VectorFields)
        new.dim_state, new.dim_noise = self.dim_state, self.dim_noise
        new.time_dependent, new.batched_time = self.time_dependent, self.batched_time
        new._fields, new._jac = self._fields, self._jac
        new._raw = (self._raw[0], self._raw[1], extra) if hasattr(self, "_raw") else (None, None, extra)
        return self._add_drift_to(new, f, fj)

    def _add_drift_to(self, new, f, fj):
        """Give ``new`` the drift of this family plus ``f`` (Jacobian ``fj``), check it and return it."""
        old, oldj = self._drift, self._drift_jac
        if old is None:
            new._drift, new._drift_jac = f, fj
        else:
            new._drift = _Sum(old, f)
            new._drift_jac = None if (oldj is None or fj is None) else _Sum(oldj, fj)
        new._check_shapes()
        return new

    def __repr__(self) -> str:
        jac = "user Jacobian" if self._jac is not None else "central-difference Jacobian"
        td = ", time-dependent" if self.time_dependent else ""
        return (f"{type(self).__name__}(e={self.dim_state}, d={self.dim_noise}, {jac}, "
                f"drift={'yes' if self.has_drift else 'no'}{td})")


def _parse_drift(drift, drift_jacobian, e, time_dependent=False):
    """Return ``(callable (t, y) or None, its Jacobian callable (t, y) or None)`` for a drift argument."""
    if drift is None:
        return None, None
    if isinstance(drift, LinearDrift):
        m = drift
    elif callable(drift):
        j = _as_callable(drift_jacobian, "drift_jacobian")
        if time_dependent:
            return drift, j
        return _Autonomous(drift), None if j is None else _Autonomous(j)
    else:
        m = LinearDrift(as_float_array(drift, "drift", ndim=2))
    if m.matrix.shape != (e, e):
        raise ValueError(f"drift matrix must have shape (e, e) = ({e}, {e}), got {m.matrix.shape}.")
    return _Autonomous(m), _Autonomous(m.jacobian)


def _linear_part(drift):
    """The :class:`LinearDrift` behind a stored drift callable, or None."""
    if isinstance(drift, _Autonomous) and isinstance(drift.f, LinearDrift):
        return drift.f
    return None


def central_jacobian(f, y):
    """Central differences of ``f: (..., e) -> (..., *out)``; returns ``(..., *out, e)``.

    Step ``FD_STEP·max(1, |y_b|)`` per coordinate (the Jacobian that :class:`VectorFields` and
    ``mechanics.LiePoissonSystem``'s forces use when none is given).
    """
    e = y.shape[-1]
    h = FD_STEP * np.maximum(1.0, np.abs(y))                          # (..., e)
    cols = []
    for b in range(e):
        dy = np.zeros_like(y)
        dy[..., b] = h[..., b]
        fp, fm = np.asarray(f(y + dy)), np.asarray(f(y - dy))
        hb = h[..., b].reshape(h.shape[:-1] + (1,) * (fp.ndim - y.ndim + 1))
        cols.append((fp - fm) / (2.0 * hb))
    return np.stack(cols, axis=-1)

