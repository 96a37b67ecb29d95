"""Rough paths on a time grid: level 2 (RoughPath), level N (RoughPathN), and the rough integral."""
