"""Picklable callables behind :class:`roughpaths.VectorFields` (private).

Small classes instead of closures and lambdas, so that a family built from module-level functions
pickles (and so runs in a process pool or on a cluster). Every stored field callable takes
``(t, y)``; autonomous user callables are wrapped by :class:`_Autonomous`.
"""

from __future__ import annotations

import numpy as np


class _Autonomous:
    """``(t, y) -> f(y)`` for an autonomous callable ``f``."""

    __slots__ = ("f",)

    def __init__(self, f):
        self.f = f

    def __call__(self, t, y):
        return self.f(y)


class _Stack:
    """``(t, y) -> stack([f(t, y) for f in fs], axis)``: one callable per driving field."""

    __slots__ = ("fs", "axis")

    def __init__(self, fs, axis):
        self.fs, self.axis = tuple(fs), axis

    def __call__(self, t, y):
        return np.stack([np.asarray(f(t, y), dtype=np.float64) for f in self.fs], axis=self.axis)


class _Sum:
    """``(t, y) -> f(t, y) + g(t, y)``."""

    __slots__ = ("f", "g")

    def __init__(self, f, g):
        self.f, self.g = f, g

    def __call__(self, t, y):
        return np.asarray(self.f(t, y), dtype=np.float64) + np.asarray(self.g(t, y), dtype=np.float64)


class _Frozen:
    """``y -> f(t, y)`` at a fixed time (for central differences)."""

    __slots__ = ("f", "t")

    def __init__(self, f, t):
        self.f, self.t = f, t

    def __call__(self, y):
        return self.f(self.t, y)


class _PublicCallable:
    """A family-derived field with the family's calling convention: ``f(y)``, or ``f(t, y)`` if time-dependent."""

    def __init__(self, family):
        self.family = family

    def __call__(self, *args):
        if self.family.time_dependent:
            if len(args) != 2:
                raise TypeError("this field belongs to a time-dependent family: call it as f(t, y).")
            t, y = args
        else:
            if len(args) != 1:
                raise TypeError("this field belongs to an autonomous family: call it as f(y).")
            t, y = None, args[0]
        return self._eval(t, np.asarray(y, dtype=np.float64))


class _Bracket(_PublicCallable):
    r""":math:`[V_i, V_j] = DV_j\cdot V_i - DV_i\cdot V_j`."""

    def __init__(self, family, i, j):
        super().__init__(family)
        self.i, self.j = i, j

    def _eval(self, t, y):
        V, J = self.family.fields(y, t), self.family.jacobians(y, t)
        i, j = self.i, self.j
        return ((J[..., j, :, :] @ V[..., :, i, None])[..., 0] - (J[..., i, :, :] @ V[..., :, j, None])[..., 0])


class _FrizOberhauserDrift(_PublicCallable):
    r""":math:`\tfrac12\sum_{i,j} s^{ij}[V_i, V_j]`."""

    def __init__(self, family, s):
        super().__init__(family)
        self.s = s

    def _eval(self, t, y):
        B = self.family.brackets(y, t)                                 # (..., d, d, e)
        d = B.shape[-2]
        acc = np.zeros(B.shape[:-3] + B.shape[-1:])
        for i in range(d):
            for j in range(d):
                if self.s[i, j] != 0.0:
                    acc = acc + self.s[i, j] * B[..., i, j, :]
        return 0.5 * acc


def _signature_hint(f, name):
    """A sentence for a callable that failed on ``f(y)``: does it take ``(t, y)``?"""
    import inspect

    try:
        params = [q for q in inspect.signature(f).parameters.values()
                  if q.kind in (q.POSITIONAL_ONLY, q.POSITIONAL_OR_KEYWORD) and q.default is q.empty]
    except (TypeError, ValueError):
        return ""
    if len(params) == 2:
        return (f" {name} takes two arguments: if it is a time-dependent field V(t, y), pass "
                f"time_dependent=True (then every callable of the family takes (t, y)).")
    return ""
