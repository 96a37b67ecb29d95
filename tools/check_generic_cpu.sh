#!/usr/bin/env bash
# Run pytest as on an older x86-64 CPU, to find tests that depend on floating-point bits the CPU's vector
# units can change (the library promises bitwise results across threads and batch splits on one machine,
# not across CPUs): numpy without its AVX2 / AVX-512 kernels (only its x86-64-v2 baseline), OpenBLAS on its
# Nehalem (SSE4.2) kernels, and numba compiling for a generic x86-64 CPU. Numba's cache keys entries by the
# CPU name, so the generic kernels are compiled once and kept beside the native ones.
# Usage: tools/check_generic_cpu.sh [pytest arguments]   (default: the whole default suite)
# CI runs it on the tests of the shipped tables and of the samplers' laws (.ci/run); the whole suite this
# way takes about twice the normal suite (every kernel is compiled again for the generic CPU).
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PY:-.venv/bin/python}"
export NPY_DISABLE_CPU_FEATURES="X86_V3 X86_V4 AVX512_ICL AVX512_SPR"
export OPENBLAS_CORETYPE=Nehalem
export NUMBA_CPU_NAME=generic
"$PY" - <<'PYEOF'
from numpy._core._multiarray_umath import __cpu_features__ as f
import numba
assert not f["X86_V3"] and not f["X86_V4"], "numpy still dispatches to AVX2/AVX-512 kernels"
assert numba.config.CPU_NAME == "generic", numba.config.CPU_NAME
PYEOF
exec "$PY" -m pytest "$@"
