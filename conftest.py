"""Collection settings for the doctests of the library modules (``--doctest-modules`` over ``roughpaths/``).

The framework front ends ``roughpaths/torch.py`` and ``roughpaths/jax.py`` import torch / jax, which are
optional extras: where one is not installed its module is not collected (instead of an import error).
``./test.sh`` installs both, so in CI they are collected and their doctests run.
"""

import importlib.util

collect_ignore = [f"roughpaths/{name}.py" for name in ("torch", "jax") if importlib.util.find_spec(name) is None]
