"""Rough paths on a time grid: level 2 (:class:`RoughPath`), any level (:class:`RoughPathN`), and the rough integral."""

from .integral import rough_integral
from .rough_path import RoughPath, chen_defect
from .rough_path_n import RoughPathN

__all__ = [
    "rough_integral", "RoughPath", "chen_defect", "RoughPathN",
]
