"""Drivers: the Driver contract, seeded Brownian motion with Lévy areas (and its refinement), coloured noise and fractional Brownian motion."""
