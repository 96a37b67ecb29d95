r"""Wong–Zakai limits: mechanics driven by smooth coloured noise and its white-noise rough-path limit.

:mod:`.wong_zakai` holds the coloured-noise rigid body, its exact limit (Friz–Oberhauser: the Lévy
torque enters the conservative part only) and a coupled simulation of both on the same Brownian
draws; :mod:`.planar` is the paper's planar linear example, whose limit moments are known in
closed form.
"""

from .planar import PlanarExample, planar_example, planar_limit_moments
from .wong_zakai import RigidBodyWongZakai, rigid_body_wong_zakai_limit, simulate_wong_zakai_rigid_body

__all__ = ["RigidBodyWongZakai", "rigid_body_wong_zakai_limit", "simulate_wong_zakai_rigid_body",
           "PlanarExample", "planar_example", "planar_limit_moments"]
