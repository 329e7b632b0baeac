"""A material graded in the student's process (rtpy.grading.remote_material) is, to
rtpy.testing's checks, the same material: its draws and values arrive bit for bit,
and answers of the wrong size are protocol errors."""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.grading.judge import probe_registry, probes_outside_pytest
from rtpy.grading.protocol import ProtocolError
from rtpy.grading.remote_material import RemoteMaterial
from rtpy.grading.sandbox import InProcess
from rtpy.testing import chi2_test
from rtpy.testing.subject import LocalMaterial

SPEC = {"type": "Phong", "albedo": [0.5, 0.4, 0.3], "kd": 0.5, "ks": 0.4, "exponent": 20.0}


@pytest.fixture
def probe():
    return probes_outside_pytest(InProcess({}), probe_registry([]))


def test_draws_and_values_arrive_bit_for_bit(probe):
    from rtpy.grading.probes import make_material

    remote, local = RemoteMaterial(probe, SPEC), LocalMaterial(make_material(SPEC))
    a, b = remote.draw(30.0, 200, seed=4), local.draw(30.0, 200, seed=4)
    for field in ("directions", "weights", "pdfs", "status"):
        assert np.array_equal(getattr(a, field), getattr(b, field), equal_nan=True), field
    wo = np.tile([0.5, 0.0, np.sqrt(0.75)], (50, 1))
    wi = np.random.default_rng(1).normal(size=(50, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    assert np.array_equal(remote.brdf(wo, wi), local.brdf(wo, wi))
    assert np.array_equal(remote.pdf(wo, wi), local.pdf(wo, wi))
    assert remote.is_specular is False
    result = chi2_test(remote, 30.0, n_samples=4000, theta_bins=6, phi_bins=8, seed=2)
    assert (
        result.p_value
        == chi2_test(local, 30.0, n_samples=4000, theta_bins=6, phi_bins=8, seed=2).p_value
    )


class Liar:
    """A probe whose answers have the wrong number of rows."""

    def material_brdf(self, **inputs):
        return np.zeros((1, 3))

    def material_draw(self, **inputs):
        return np.zeros((inputs["n"], 8)) + 7.0  # a status that does not exist


def test_answers_of_the_wrong_size_or_status_are_protocol_errors():
    liar = RemoteMaterial(Liar(), SPEC)
    with pytest.raises(ProtocolError, match="asked for 2 values"):
        liar.brdf(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ProtocolError, match="status"):
        liar.draw(30.0, 5)
