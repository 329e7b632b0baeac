"""rtpy.materials.microfacet: the GGX and Beckmann formulas against their textbook
forms (Walter et al. 2007), D's normalisation, the samplers' inverted CDFs, and the
same numbers on numpy arrays as on floats."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.materials import microfacet as mf

ALPHAS = (0.05, 0.3, 1.0)


def projected_integral(d_of_theta) -> float:
    """The integral of D(h) cos(theta_h) over the hemisphere of h (midpoint rule in
    theta, D the same around the normal), which D's normalisation makes 1."""
    n = 200_000
    theta = (np.arange(n) + 0.5) * (0.5 * math.pi / n)
    return float(
        np.sum(d_of_theta(theta) * np.cos(theta) * np.sin(theta))
        * 2.0
        * math.pi
        * (0.5 * math.pi / n)
    )


@pytest.mark.parametrize("alpha", ALPHAS)
def test_ggx_d_is_the_textbook_form_and_normalised(alpha):
    a2 = alpha * alpha
    for theta in (0.0, 0.3, 1.2):
        c, s = math.cos(theta), math.sin(theta)
        textbook = a2 / (math.pi * c**4 * (a2 + math.tan(theta) ** 2) ** 2)
        assert mf.ggx_d(a2, c * c, s * s) == pytest.approx(textbook, rel=1e-12)
    total = projected_integral(lambda t: mf.ggx_d(a2, np.cos(t) ** 2, np.sin(t) ** 2))
    assert total == pytest.approx(1.0, rel=1e-4)


@pytest.mark.parametrize("alpha", ALPHAS)
def test_beckmann_d_is_the_textbook_form_and_normalised(alpha):
    a2 = alpha * alpha

    def d(cos2, sin2):
        return mf.beckmann_d(a2, cos2, mf.beckmann_exponent(a2, cos2, sin2))

    for theta in (0.0, 0.3, 1.2):
        c, s = math.cos(theta), math.sin(theta)
        textbook = math.exp(-(math.tan(theta) ** 2) / a2) / (math.pi * a2 * c**4)
        assert d(c * c, s * s) == pytest.approx(textbook, rel=1e-12)
    total = projected_integral(np.vectorize(lambda t: d(math.cos(t) ** 2, math.sin(t) ** 2)))
    assert total == pytest.approx(1.0, rel=1e-4)


@pytest.mark.parametrize("alpha", ALPHAS)
def test_the_g1_terms_are_the_textbook_forms(alpha):
    for theta in (0.1, 0.7, 1.5):
        c, s, tan = math.cos(theta), math.sin(theta), math.tan(theta)
        textbook_ggx = 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * tan * tan))
        assert mf.ggx_g1(alpha * alpha, c, s * s) == pytest.approx(textbook_ggx, rel=1e-12)
        a = mf.beckmann_a(alpha, c, s * s)
        assert a == pytest.approx(1.0 / (alpha * tan), rel=1e-12)
        textbook_lambda = (math.erf(a) - 1.0) / 2.0 + math.exp(-a * a) / (
            2.0 * a * math.sqrt(math.pi)
        )
        assert mf.beckmann_lambda(a) == pytest.approx(textbook_lambda, rel=1e-9, abs=1e-15)
    assert mf.ggx_g1(alpha * alpha, 1.0, 0.0) == 1.0  # looking straight down
    assert mf.ggx_g1(alpha * alpha, 1e-12, 1.0) == pytest.approx(2e-12 / alpha, rel=1e-9)  # grazing


def test_beckmann_lambda_keeps_its_precision_where_erf_cancels():
    """For a = 5, Lambda is about 1e-13: (erf(a) - 1) / 2 + ... would keep no digit."""
    a = 5.0
    # The asymptotic series of erfc: Lambda ~ exp(-a^2) / (4 a^3 sqrt(pi)) (1 - 3 / (2 a^2) + ...)
    leading = math.exp(-a * a) / (4.0 * a**3 * math.sqrt(math.pi))
    series = leading * (1.0 - 3.0 / (2.0 * a * a) + 15.0 / (4.0 * a**4) - 105.0 / (8.0 * a**6))
    assert mf.beckmann_lambda(a) == pytest.approx(series, rel=2e-3)


@pytest.mark.parametrize("r1", [0.0, 0.1, 0.5, 0.99])
def test_the_samplers_invert_the_cdfs_of_d_cos(r1):
    """P(tan^2 <= x) is x / (alpha^2 + x) for GGX and 1 - exp(-x / alpha^2) for Beckmann."""
    a2 = 0.09
    x = mf.ggx_tan2(a2, r1)
    assert x / (a2 + x) == pytest.approx(r1, abs=1e-15)
    x = mf.beckmann_tan2(a2, r1)
    assert -math.expm1(-x / a2) == pytest.approx(r1, abs=1e-15)


def test_cos_sin_of_tan2():
    for tan2 in (0.0, 1e-10, 1.0, 1e8):
        c, s = mf.cos_sin_of_tan2(tan2)
        assert c * c + s * s == pytest.approx(1.0, rel=1e-15)
        assert s == pytest.approx(math.sqrt(tan2) * c, rel=1e-15)
