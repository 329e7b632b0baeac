"""The Phong kernel: the checks of test_table.py catch a wrong lobe and a wrong sampler."""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.materials import Phong
from rtpy.numpy_backend.materials import KERNELS, MaterialTable
from rtpy.numpy_backend.materials.glossy import positive_power
from rtpy.numpy_backend.materials.phong import INV_TWO_PI, PhongKernel
from rtpy.testing import chi2_test
from rtpy.vec3 import Color

from .kernel_checks import (
    CHI2_ALPHA,
    batched_samples,
    check_brdf_and_pdf,
    compare_with_scalar_sampler,
    random_hits,
    random_wi,
)


class PhongWithWrongNormalisation(PhongKernel):
    """(n + 1) / (2 pi) in place of (n + 2) / (2 pi): off by a factor 1 + 1/(n+1)."""

    def specular(self, slots, wo, wi):
        n = self.exponent[slots]
        return (n + 1.0) * INV_TWO_PI * positive_power(self.cos_to_mirror(wo, wi), n)


def test_brdf_check_catches_a_wrong_normalisation():
    material = Phong(Color(0.5, 0.5, 0.5), kd=0.5, ks=0.5, exponent=50.0)
    rng = np.random.default_rng(1)
    hits = random_hits(rng, 200)
    wi = random_wi(rng, hits)
    ids = np.zeros(200, int)
    table = MaterialTable([material])
    check_brdf_and_pdf(table, ids, hits, wi)  # the right kernel passes
    table.kernels[0] = PhongWithWrongNormalisation(table.kernels[0].materials)
    with pytest.raises(AssertionError, match="BRDF"):
        check_brdf_and_pdf(table, ids, hits, wi)


class PhongWithWrongSampler(PhongKernel):
    """Draws the highlight with a sharper cosine power than its pdf claims."""

    def sample_specular(self, slots, wo, r1, r2):
        return super().sample_specular(slots, wo, r1 ** (1.0 / 3.0), r2)


def test_sampling_checks_catch_a_wrong_sampler(monkeypatch):
    material = Phong(Color(0.2, 0.2, 0.2), kd=0.2, ks=0.8, exponent=10.0)
    monkeypatch.setitem(KERNELS, Phong, PhongWithWrongSampler)
    batched = batched_samples(material, 70.0, 30_000, seed=1)
    assert not chi2_test(material, 70.0, samples=batched).passed(CHI2_ALPHA)
    with pytest.raises(AssertionError, match="absorbed fraction|albedo"):
        compare_with_scalar_sampler(material, 70.0)
