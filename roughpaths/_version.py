"""The package version (one place; :mod:`roughpaths.io` writes it into saved files)."""

__version__ = "0.1.0"
