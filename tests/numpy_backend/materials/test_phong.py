"""The Phong kernel: its cosine-power sampler equals the scalar one, and the checks of
test_table.py catch a wrong lobe and a wrong sampler."""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.materials import Phong
from rtpy.materials.phong import sample_cosine_power as scalar_cosine_power
from rtpy.numpy_backend.materials import KERNELS, MaterialTable, class_name
from rtpy.numpy_backend.materials.phong import PhongKernel, sample_cosine_power
from rtpy.numpy_backend.onb import ONB
from rtpy.testing import chi2_test
from rtpy.vec3 import Color

from .kernel_checks import (
    CHI2_ALPHA,
    ULP,
    batched_samples,
    check_brdf_and_pdf,
    compare_with_scalar_sampler,
    random_hits,
    random_wi,
)
from .sampler_checks import (
    AZIMUTH,
    LIBM_ULPS,
    check_scattering_equals_scalar,
    use_scalar_local_samplers,
)


def cosine_power_differences(exponent_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """|batched - scalar| of sample_cosine_power's local directions from the same
    numbers (exponents from 0 to 1e6, r1 at 0 and near 1), and the bound each must keep:
    cos(theta) = r1^(1/(n+1)) comes from pow, within LIBM_ULPS ulp; 1 - cos^2 then
    differs by at most (2 LIBM_ULPS + 2) ulp (the square and the difference rounded),
    which sin(theta) = sqrt(1 - cos^2) turns into at most that over sin(theta), and at
    most its square root; the azimuth adds AZIMUTH, the products an ulp each."""
    rng = np.random.default_rng(5)
    n = 20_000
    exponent = rng.choice([0.0, 0.5, 1.0, 8.0, 100.0, 1e4, 1e6], n)
    r1, r2 = rng.random(n), rng.random(n)
    r1[:20], r1[20:40] = 0.0, 1.0 - rng.random(20) * 1e-12
    batched = np.stack(sample_cosine_power(exponent * exponent_scale, r1, r2), axis=1)
    scalar = np.array([tuple(scalar_cosine_power(*x)) for x in zip(exponent, r1, r2, strict=True)])
    sin_theta = np.hypot(scalar[:, 0], scalar[:, 1])
    d_sin2 = (2 * LIBM_ULPS + 2) * ULP
    with np.errstate(divide="ignore"):
        d_sin = np.minimum(d_sin2 / sin_theta, np.sqrt(d_sin2))
    return np.abs(batched - scalar), (AZIMUTH + 2 * ULP + d_sin)[:, None]


def test_cosine_power_sampler_equals_scalar():
    difference, bound = cosine_power_differences()
    assert (difference <= bound).all(), np.max(difference / bound)
    # an exponent off by 1e-9 relative is not rounding
    difference, bound = cosine_power_differences(1.0 + 1e-9)
    assert not (difference <= bound).all()


class PhongWithWrongNormalisation(PhongKernel):
    """(n + 1) / (2 pi) in place of (n + 2) / (2 pi): off by a factor 1 + 1/(n+1)."""

    def highlight(self, b):
        n = self.exponent[b.slots]
        return super().highlight(b) * ((n + 1.0) / (n + 2.0))


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

    def sample_highlight(self, b, r1, r2):
        return super().sample_highlight(b, r1 ** (1.0 / 3.0), r2)


class PhongAroundTheNormal(PhongKernel):
    """Draws the highlight around the normal instead of the mirror direction."""

    def sample_highlight(self, b, r1, r2):
        return ONB(b.normal).to_world(sample_cosine_power(self.exponent[b.slots], r1, r2))


def test_sampling_checks_catch_a_wrong_sampler(monkeypatch):
    material = Phong(Color(0.2, 0.2, 0.2), kd=0.2, ks=0.8, exponent=10.0)
    monkeypatch.setitem(KERNELS, class_name(Phong), PhongWithWrongSampler)
    batched = batched_samples(material, 70.0, 30_000, seed=1)
    assert not chi2_test(material, 70.0, samples=batched).passed(CHI2_ALPHA)
    with pytest.raises(AssertionError, match="absorbed fraction|albedo"):
        compare_with_scalar_sampler(material, 70.0)


@pytest.mark.parametrize("kernel", [PhongWithWrongSampler, PhongAroundTheNormal])
def test_scattering_check_catches_a_wrong_sampler(monkeypatch, kernel):
    material = Phong(Color(0.2, 0.2, 0.2), kd=0.2, ks=0.8, exponent=10.0)
    rng = np.random.default_rng(2)
    hits = random_hits(rng, 100)
    ids = np.zeros(100, int)
    table = MaterialTable([material])
    use_scalar_local_samplers(monkeypatch)
    check_scattering_equals_scalar(table, ids, hits, np.random.default_rng(3))  # passes
    table.kernels[0] = kernel(table.kernels[0].materials)
    with pytest.raises(AssertionError, match="direction|absorbed"):
        check_scattering_equals_scalar(table, ids, hits, np.random.default_rng(3))
