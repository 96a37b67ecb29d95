"""Masked arrays (``numpy.ma``) as paths are refused with the fix, wherever paths enter the numpy API.

``np.asarray`` drops a masked array's mask: the values under it (finite, often a fill value or a stale
reading) were used silently. Other ndarray subclasses are still read as their values.
"""

import numpy as np
import pytest

import roughpaths as rp
from roughpaths.signatures.stream import SignatureStream, windowed_signature


def _masked():
    x = np.ma.masked_array(np.random.default_rng(0).standard_normal((2, 6, 2)), mask=False)
    x[1, 3, 0] = np.ma.masked
    return x


CALLS = {
    "signature": lambda x: rp.signature(x, 2),
    "logsignature": lambda x: rp.logsignature(x, 3),
    "signature_vjp": lambda x: rp.signature_vjp(x, 2, np.ones((2, rp.sigdim(2, 2)))),
    "logsignature_vjp": lambda x: rp.logsignature_vjp(x, 3, np.ones((2, rp.logsigdim(2, 3)))),
    "lead_lag": rp.lead_lag,
    "time_augment": rp.time_augment,
    "basepoint": rp.basepoint,
    "invisibility_reset": rp.invisibility_reset,
    "SignatureStream": lambda x: SignatureStream(x, 2, block=2).signature(0, 5),
    "windowed_signature": lambda x: windowed_signature(x, 2, 3),
    "windowed_signature_stream": lambda x: windowed_signature(x, 2, 2, expanding=True),
    "signature_coefficients": lambda x: rp.signature_coefficients(x, [(0, 1), (1,)]),
    "signature_kernel": lambda x: rp.signature_kernel(x, x),
    "signature_kernel_gram": lambda x: rp.signature_kernel_gram(x, x),
    "signature_kernel_vjp": lambda x: rp.signature_kernel_vjp(x, x, np.ones(2)),
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_masked_paths_are_refused_with_the_fix(name):
    x = _masked()
    with pytest.raises(TypeError, match=r"paths|x|X") as err:
        CALLS[name](x)
    msg = str(err.value)
    assert "masked array with 1 masked value" in msg and ".filled(" in msg


@pytest.mark.parametrize("name", sorted(CALLS))
def test_filled_masked_paths_and_other_subclasses_are_taken(name):
    filled = _masked().filled(0.5)
    want, got = CALLS[name](filled), CALLS[name](filled.view(_Tagged))
    for a, b in zip(got if isinstance(got, tuple) else (got,), want if isinstance(want, tuple) else (want,)):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


class _Tagged(np.ndarray):
    """An ndarray subclass without a mask (as a units or metadata wrapper would be)."""


def test_grad_output_and_times_that_are_masked_are_refused():
    x = np.random.default_rng(1).standard_normal((6, 2))
    g = np.ma.masked_array(np.ones(rp.sigdim(2, 2)), mask=False)
    g[0] = np.ma.masked
    with pytest.raises(TypeError, match=r"grad_output is a numpy masked array"):
        rp.signature_vjp(x, 2, g)
    t = np.ma.masked_array(np.linspace(0.0, 1.0, 6), mask=False)
    t[2] = np.ma.masked
    with pytest.raises(TypeError, match=r"times is a numpy masked array"):
        rp.time_augment(x, t)
