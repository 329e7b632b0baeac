"""Tests for rtpy.testing.statistics: tails, multiple-test corrections, the block
z-test."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.testing.statistics import (
    block_sums,
    block_z_test,
    bonferroni_alpha,
    bonferroni_z,
    chi2_sf,
    gamma_q,
    normal_quantile,
    sidak_alpha,
)


@pytest.mark.parametrize("x", [1e-6, 0.1, 1.0, 3.5, 20.0, 700.0])
def test_gamma_q_closed_forms(x):
    assert gamma_q(1.0, x) == pytest.approx(math.exp(-x), rel=1e-12)
    assert gamma_q(0.5, x) == pytest.approx(math.erfc(math.sqrt(x)), rel=1e-10)


@pytest.mark.parametrize("k", [2, 3, 7, 20, 50])
@pytest.mark.parametrize("ratio", [0.05, 0.5, 0.9, 1.0, 1.1, 2.0, 5.0])
def test_gamma_q_integer_a_is_a_poisson_sum(k, ratio):
    # Q(k, x) = e^-x sum_{j<k} x^j / j!: both the series (x < k + 1) and the
    # continued fraction (x > k + 1) branches.
    x = ratio * k
    expected = math.exp(-x) * sum(x**j / math.factorial(j) for j in range(k))
    assert gamma_q(float(k), x) == pytest.approx(expected, rel=1e-11)


@pytest.mark.parametrize(
    ("statistic", "dof", "p"),
    [
        # critical values from a chi-square table (rounded to 3 decimals)
        (2.706, 1, 0.10),
        (3.841, 1, 0.05),
        (6.635, 1, 0.01),
        (10.828, 1, 0.001),
        (9.488, 4, 0.05),
        (18.307, 10, 0.05),
        (23.209, 10, 0.01),
        (43.773, 30, 0.05),
        (124.342, 100, 0.05),
        (135.807, 100, 0.01),
    ],
)
def test_chi2_sf_matches_table_values(statistic, dof, p):
    assert chi2_sf(statistic, dof) == pytest.approx(p, rel=2e-3)


def test_chi2_sf_matches_scipy():
    stats = pytest.importorskip("scipy.stats")
    for dof in (1, 2, 3, 5, 10, 47, 100, 575, 1000, 2303):
        for ratio in (0.01, 0.3, 0.8, 0.95, 1.0, 1.05, 1.2, 1.5, 3.0):
            x = ratio * dof
            assert chi2_sf(x, dof) == pytest.approx(stats.chi2.sf(x, dof), rel=1e-9, abs=1e-300)


def test_gamma_q_edges():
    assert gamma_q(3.0, 0.0) == 1.0
    assert gamma_q(3.0, math.inf) == 0.0
    assert gamma_q(10.0, 1e4) == 0.0  # underflows, never negative
    assert chi2_sf(-1.0, 5) == 1.0
    with pytest.raises(ValueError):
        gamma_q(0.0, 1.0)
    with pytest.raises(ValueError):
        gamma_q(1.0, -1.0)


def test_sidak_alpha():
    assert sidak_alpha(0.01, 1) == pytest.approx(0.01, rel=1e-14)
    a = sidak_alpha(0.05, 7)
    assert (1.0 - a) ** 7 == pytest.approx(0.95, rel=1e-14)
    assert sidak_alpha(0.01, 5) == pytest.approx(0.0020080, rel=1e-4)
    assert 0.01 / 160 < sidak_alpha(0.01, 160) < 0.01 / 159
    with pytest.raises(ValueError):
        sidak_alpha(0.0, 3)
    with pytest.raises(ValueError):
        sidak_alpha(0.01, 0)


def test_normal_quantile():
    assert normal_quantile(0.05) == pytest.approx(1.959963985, rel=1e-9)
    assert normal_quantile(0.01) == pytest.approx(2.575829304, rel=1e-9)
    assert normal_quantile(1e-6) == pytest.approx(4.891638476, rel=1e-9)
    # the tail: P(|Z| > z) = erfc(z / sqrt 2), also where 1 - alpha / 2 rounds to 1
    for alpha in (0.3, 1e-3, 1e-9, 1e-15, 1e-40):
        assert math.erfc(normal_quantile(alpha) / math.sqrt(2)) == pytest.approx(alpha, rel=1e-9)
    for alpha in (0.0, 1.0, -0.5, math.nan):
        with pytest.raises(ValueError):
            normal_quantile(alpha)


def test_bonferroni():
    assert bonferroni_alpha(0.01, 4) == 0.0025
    assert bonferroni_z(1e-3, 1) == normal_quantile(1e-3)
    assert bonferroni_z(1e-3, 100) == normal_quantile(1e-5)
    # Bonferroni is the more cautious correction: a smaller per-test level
    assert bonferroni_alpha(0.05, 7) < sidak_alpha(0.05, 7)
    with pytest.raises(ValueError):
        bonferroni_alpha(0.01, 0)


# --- the block z-test ------------------------------------------------------------------------


def test_block_sums_cover_the_image_with_partial_blocks_at_the_edges():
    image = np.arange(10 * 13 * 3, dtype=float).reshape(10, 13, 3)
    sums, counts = block_sums(image, 8)
    assert sums.shape == (4, 3) and counts[:, 0].tolist() == [64, 40, 16, 10]
    assert sums.sum(axis=0) == pytest.approx(image.sum(axis=(0, 1)))
    assert sums[3].tolist() == image[8:, 8:].sum(axis=(0, 1)).tolist()
    stacked, _ = block_sums(np.stack([image, 2 * image]), 8)  # leading axes are kept
    assert stacked.shape == (2, 4, 3) and np.array_equal(stacked[1], 2 * sums)


def noisy_means(rng, truth: np.ndarray, sigma: float, renders: int):
    """The mean of `renders` noisy images and the variance of each of its pixels,
    measured from their spread, as a renderer's repeated renders give them."""
    stack = truth + rng.normal(0.0, sigma, (renders, *truth.shape))
    return stack.mean(axis=0), stack.var(axis=0, ddof=1) / renders


def test_block_z_test_passes_equal_expectations_at_the_promised_rate():
    """Two independent noisy estimates of the same image: at alpha = 0.05 the test
    fails in at most about 5 % of 400 trials (the Bonferroni correction makes it
    conservative), while without the correction almost every trial fails."""
    rng = np.random.default_rng(5)
    truth = rng.uniform(0.2, 1.0, (32, 40, 3))
    fails = uncorrected = 0
    for _ in range(400):
        a, var_a = noisy_means(rng, truth, 0.3, 4)
        b, var_b = noisy_means(rng, truth, 0.3, 4)
        test = block_z_test(a, var_a, b, var_b, alpha=0.05)
        fails += not test.passed
        uncorrected += bool(test.z.max() > normal_quantile(0.05))
    # binomial(400, 0.05): mean 20, sd 4.4; 4 sd above is 38
    assert fails <= 38
    assert uncorrected > 300


def test_block_z_test_catches_a_small_shift_of_one_region():
    rng = np.random.default_rng(6)
    truth = rng.uniform(0.2, 1.0, (32, 32, 3))
    a, var_a = noisy_means(rng, truth, 0.3, 8)
    shifted = truth.copy()
    shifted[8:16, 16:24] *= 1.2  # one block, 20 % brighter
    b, var_b = noisy_means(rng, shifted, 0.3, 8)
    test = block_z_test(a, var_a, b, var_b, alpha=1e-3)
    assert not test.passed
    assert test.failing_share == 1 / 16
    assert "x=16.., y=8.." in test.worst() and "1 of 16 blocks differ" in test.worst()
    assert "where the reference has" in test.worst()
    assert "where numpy has" in test.worst("numpy")


def test_block_z_test_of_noiseless_images_allows_rounding_only():
    image = np.full((8, 8, 3), 0.5)
    zero = np.zeros_like(image)
    assert block_z_test(image, zero, image * (1 + 1e-13), zero, alpha=1e-3).passed
    assert not block_z_test(image, zero, image * (1 + 1e-6), zero, alpha=1e-3).passed
    with pytest.raises(ValueError, match="shapes differ"):
        block_z_test(image, zero, image[:4], zero[:4], alpha=1e-3)
