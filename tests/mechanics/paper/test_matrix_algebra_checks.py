"""The main job's checks beyond the rigid body (``matrix_prop21``, ``matrix_uniform``, ``matrix_gibbs``).

Claims: they are registered after the rigid-body checks and labelled as beyond the rigid body; each reads exactly
the sizes declared for it and passes at the tiny sizes (the seeds are the run's: the numbers are reproducible) and reports predicted and measured numbers; and
(slow) each passes at the default sizes, where its power requirements (the wrong sign and the missing ½ at least 6
SE away, the dissipative law at least 10 SE away) are met with a wide margin. The mathematics of the three claims is
tested in ``tests/mechanics/systems/test_proposition_2_1_matrix_algebras.py`` and
``tests/mechanics/analysis/test_{proposition_3_1_uniform,theorem_3_1_gibbs}_matrix_algebras.py``.
"""

import numpy as np
import pytest

from mechanics.paper.checks import CHECKS
from mechanics.paper.sizes import SIZES
from mechanics.paper.tasks import Context

NAMES = ["matrix_prop21", "matrix_uniform", "matrix_gibbs"]


def test_registered_after_the_rigid_body_and_labelled():
    names = list(CHECKS)
    after = names[names.index("chaos") + 1:]                   # after the paper's own checks, before the sphere's
    assert after[:3] == NAMES and all(n.startswith("sphere_") for n in after[3:])
    assert all(CHECKS[n].title.startswith("Beyond the rigid body") for n in NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_passes_at_tiny_sizes_reading_exactly_its_sizes(name, monkeypatch):
    read = set()
    real = Context.size

    def spy(self, key, **presets):
        read.add(key)
        return real(self, key, **presets)

    monkeypatch.setattr(Context, "size", spy)
    r = CHECKS[name].run(Context(scale="tiny"))
    assert read == {f"{name}.{w}" for w in SIZES[name]}
    assert r.passed, r.details
    assert r.statement.startswith("Beyond the rigid body") and r.measured is not None and r.predicted is not None
    if name == "matrix_gibbs":
        assert np.asarray(r.predicted).shape == np.asarray(r.measured).shape == (18,)   # E[μ] on su(3), so(5)


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_passes_at_default_sizes(name):
    r = CHECKS[name].run(Context(scale="default"))
    print(r.details)
    assert r.passed, r.details
