"""Rough differential equations: one entry point (solve), the Solver contract, the schemes, and vector fields."""
