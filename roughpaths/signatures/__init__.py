"""Signatures and log-signatures of paths and rough paths at any depth, and their gradients.

:mod:`~roughpaths.signatures.signature` (forward) and :mod:`~roughpaths.signatures.gradients`
(vector–Jacobian products) share one engine (``_engine``: checks, the split of the work); the compiled
kernels (``_level2``, ``_lanes``, ``_simd``, ``_vjp``, ``_kernels``) are private to this subpackage.
:mod:`~roughpaths.signatures.expected` holds the closed-form expected signature of Brownian motion.

Signature kernels (:mod:`~roughpaths.signatures.kernel`, the Goursat PDE in ``_goursat``), their static
kernels (:mod:`~roughpaths.signatures.static_kernels`) and the two-sample test on them
(:mod:`~roughpaths.signatures.mmd`) live here too.

Path transforms applied before a signature (lead–lag, time, basepoint, invisibility reset:
:mod:`~roughpaths.signatures.transforms`), signatures of any sub-interval and of sliding or expanding
windows (:mod:`~roughpaths.signatures.stream`) and the coefficients of chosen words
(:mod:`~roughpaths.signatures.words`) build on :func:`signature` and the tensor algebra.
"""

from .expected import brownian_expected_signature
from .gradients import logsignature_vjp, rough_path_signature_vjp, signature_vjp
from .kernel import signature_kernel, signature_kernel_gram, signature_kernel_gram_vjp, signature_kernel_vjp
from .mmd import MMDTestResult, sig_mmd_test
from .signature import logsignature, rough_path_signature, signature
from .static_kernels import LinearKernel, RBFKernel
from .stream import SignatureStream, windowed_signature
from .transforms import basepoint, invisibility_reset, lead_lag, time_augment
from .words import signature_coefficients

__all__ = [
    "logsignature_vjp", "rough_path_signature_vjp", "signature_vjp", "logsignature", "rough_path_signature",
    "signature", "brownian_expected_signature", "signature_kernel", "signature_kernel_gram", "signature_kernel_vjp", "signature_kernel_gram_vjp",
    "LinearKernel", "RBFKernel", "sig_mmd_test", "MMDTestResult",
    "lead_lag", "time_augment", "basepoint", "invisibility_reset", "SignatureStream", "windowed_signature",
    "signature_coefficients",
]
