"""Signatures and log-signatures of paths and rough paths at any depth, and their gradients.

:mod:`~roughpaths.signatures.signature` (forward) and :mod:`~roughpaths.signatures.gradients`
(vector–Jacobian products) share one engine (``_engine``: checks, the split of the work); the compiled
kernels (``_level2``, ``_lanes``, ``_simd``, ``_vjp``, ``_kernels``) are private to this subpackage.
:mod:`~roughpaths.signatures.expected` holds the closed-form expected signature of Brownian motion.
"""

from .expected import brownian_expected_signature
from .gradients import logsignature_vjp, rough_path_signature_vjp, signature_vjp
from .signature import logsignature, rough_path_signature, signature

__all__ = [
    "logsignature_vjp", "rough_path_signature_vjp", "signature_vjp", "logsignature", "rough_path_signature",
    "signature", "brownian_expected_signature",
]
