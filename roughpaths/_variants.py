"""Compile-time variants of numba kernels, each compiled on its first use (private).

A kernel specialised on a size (an alphabet size, a depth, a state dimension) is written once as a
factory whose closure holds the size as an integer constant: numba folds the constant, prunes the
branches it decides before typing, and unrolls the loops it bounds. Each key gets its own dispatcher,
compiled when first called and cached on disk (numba keys a closure's cache entry by its constants), so
a call compiles only the variant it runs instead of every variant of a dispatching kernel. This is the
compile-time budget of the issue "First contact": a dispatching kernel that inlined seven unrolled
variants cost about 20 s of CPU to compile on its first call, one variant costs a few seconds.

Only integer (or other picklable, stable) constants may be closed over: a closure over a compiled
function would be keyed by the function's pickle, which changes from process to process, and would be
compiled again by every process.
"""

from __future__ import annotations

import threading
from functools import wraps


def _named(kernel, key: tuple):
    """``kernel`` with its key in its qualified name (``block_units_variant[0, 0, 0]``), before it compiles.

    numba names a compiled function's symbols after its qualified name and a counter of the compiling
    process, and the variants of one factory share a qualified name: two variants compiled in two
    processes and loaded from the cache into one can define the same symbol, and a lookup of the symbol by
    name (``library.get_pointer_to_function``, which :mod:`roughpaths.signatures.xla_handlers` uses to call a kernel
    by its address) may then find the other variant. With the key in the name, the symbols of different
    variants differ. (numba's cache files keep the name the dispatcher was made with.)
    """
    py_func = getattr(kernel, "py_func", None)
    if py_func is not None:
        py_func.__qualname__ = f"{py_func.__qualname__}[{', '.join(map(repr, key))}]"
    return kernel


def variants(factory):
    """Decorate ``factory(*key) -> kernel`` so that each key's kernel is made once (thread-safe).

    Threads that ask for the same key get the same dispatcher, so numba compiles it once even when
    the first call comes from several threads of :func:`roughpaths._threads.run` at the same time.
    """
    cache: dict = {}
    lock = threading.Lock()

    @wraps(factory)
    def get(*key):
        kernel = cache.get(key)
        if kernel is None:
            with lock:
                kernel = cache.get(key)
                if kernel is None:
                    kernel = cache[key] = _named(factory(*key), key)
        return kernel

    return get
