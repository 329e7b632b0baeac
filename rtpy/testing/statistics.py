"""Statistics for checks that must not fail by chance.

- Multiple tests: a check that makes n tests at once and must reject a correct
  renderer with probability at most alpha tests each at sidak_alpha(alpha, n)
  (exact for independent tests) or bonferroni_alpha(alpha, n) = alpha / n (valid
  for any dependence).
- Tails: normal_quantile(alpha) is the two-sided critical value of a z-test,
  bonferroni_z(alpha, n) that of n of them together; chi2_sf(x, k) is the
  p-value of a chi-square statistic x with k degrees of freedom.
- block_z_test compares two images block by block against the noise each side
  measured (used by the graders and by the backends' agreement test).
- peak_memory_mb / reset_peak_memory: rtpy.engine.memory's, kept here by name.

The module imports only numpy and the standard library.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from ..engine.memory import (  # importable from here too
    max_rss_mb,
    peak_memory_mb,
    reset_peak_memory,
)

__all__ = [
    "BLOCK",
    "BlockTest",
    "block_sums",
    "block_z_test",
    "bonferroni_alpha",
    "bonferroni_z",
    "chi2_sf",
    "gamma_q",
    "max_rss_mb",
    "normal_quantile",
    "peak_memory_mb",
    "reset_peak_memory",
    "sidak_alpha",
]

# --- multiple tests and normal tails ---------------------------------------------------------


def _check_alpha(alpha: float, n_tests: int = 1) -> None:
    if not 0.0 < alpha < 1.0 or n_tests < 1:
        raise ValueError(f"need 0 < alpha < 1 and n_tests >= 1, got {alpha}, {n_tests}")


def sidak_alpha(alpha: float, n_tests: int) -> float:
    """Per-test significance so that n_tests independent tests together reject a
    correct hypothesis with probability alpha: 1 - (1 - alpha)^(1/n)."""
    _check_alpha(alpha, n_tests)
    return -math.expm1(math.log1p(-alpha) / n_tests)


def bonferroni_alpha(alpha: float, n_tests: int) -> float:
    """Per-test significance so that n_tests tests, however dependent, together
    reject a correct hypothesis with probability at most alpha: alpha / n."""
    _check_alpha(alpha, n_tests)
    return alpha / n_tests


def normal_quantile(alpha: float) -> float:
    """z with P(|Z| > z) = alpha for a standard normal Z (two-sided critical value)."""
    _check_alpha(alpha)
    # The lower tail keeps its precision for tiny alpha, where 1 - alpha / 2 rounds.
    return -NormalDist().inv_cdf(0.5 * alpha)


def bonferroni_z(alpha: float, n_tests: int) -> float:
    """The two-sided critical z of each of n_tests z-tests at family-wise level alpha."""
    return normal_quantile(bonferroni_alpha(alpha, n_tests))


# --- the chi-square tail ---------------------------------------------------------------------


def gamma_q(a: float, x: float) -> float:
    """The regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a).

    Series for P = 1 - Q when x < a + 1, else Lentz's continued fraction for Q
    (Numerical Recipes, 3rd ed., section 6.2). Accurate to ~1e-14 relative.
    """
    if not (a > 0.0) or not (x >= 0.0):
        raise ValueError(f"gamma_q needs a > 0 and x >= 0, got a={a}, x={x}")
    if x == 0.0:
        return 1.0
    if math.isinf(x):
        return 0.0
    log_prefactor = -x + a * math.log(x) - math.lgamma(a)
    eps = 1e-16
    if x < a + 1.0:
        # P(a, x) = e^-x x^a / Gamma(a + 1) * sum_n x^n / ((a + 1) ... (a + n))
        ap, term = a, 1.0 / a
        total = term
        for _ in range(100_000):
            ap += 1.0
            term *= x / ap
            total += term
            if abs(term) < abs(total) * eps:
                return max(0.0, 1.0 - total * math.exp(log_prefactor))
        raise ArithmeticError(f"gamma_q series did not converge for a={a}, x={x}")
    tiny = 1e-300
    b = x + 1.0 - a
    c = 1.0 / tiny
    d = 1.0 / b
    h = d
    for i in range(1, 100_000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        if abs(d) < tiny:
            d = tiny
        c = b + an / c
        if abs(c) < tiny:
            c = tiny
        d = 1.0 / d
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < eps:
            return math.exp(log_prefactor) * h
    raise ArithmeticError(f"gamma_q continued fraction did not converge for a={a}, x={x}")


def chi2_sf(statistic: float, dof: int) -> float:
    """P(X >= statistic) for X chi-square distributed with dof degrees of freedom."""
    return gamma_q(0.5 * dof, 0.5 * max(0.0, statistic))


# --- z-tests of image blocks -----------------------------------------------------------------

BLOCK = 8  # pixels per side of the blocks block_z_test compares


def block_sums(image: np.ndarray, block: int = BLOCK) -> tuple[np.ndarray, np.ndarray]:
    """Sums over block x block squares of (..., H, W, C) -> (..., blocks, C), the
    blocks row by row (partial ones at the right and bottom edges), and each
    block's pixel count, shape (blocks, 1)."""
    h, w = image.shape[-3:-1]
    sums, counts = [], []
    for y in range(0, h, block):
        for x in range(0, w, block):
            part = image[..., y : y + block, x : x + block, :]
            sums.append(part.sum(axis=(-3, -2)))
            counts.append(part.shape[-3] * part.shape[-2])
    return np.stack(sums, axis=-2), np.array(counts, dtype=np.float64)[:, None]


@dataclass
class BlockTest:
    """The outcome of block_z_test: z and the block means per block and channel."""

    z: np.ndarray  # (blocks, channels): |mean_a - mean_b| / standard error
    threshold: float  # the Bonferroni-corrected critical z
    mean_a: np.ndarray  # (blocks, channels)
    mean_b: np.ndarray
    blocks_x: int  # blocks per row of the image
    block: int = BLOCK

    @property
    def passed(self) -> bool:
        return bool(self.z.max() < self.threshold)

    @property
    def failing_share(self) -> float:
        """The fraction of blocks with a channel beyond the threshold."""
        return float((self.z > self.threshold).any(axis=1).mean())

    def worst(self, other: str = "the reference") -> str:
        """Where the two images differ most: the block, the channel, both means, z."""
        b, c = np.unravel_index(np.argmax(self.z), self.z.shape)
        bx, by = b % self.blocks_x, b // self.blocks_x
        n = self.block
        channel = "RGB"[c] if self.z.shape[1] == 3 else f"channel {c}"
        failing = int((self.z > self.threshold).any(axis=1).sum())
        return (
            f"the {n}x{n} block at pixels x={bx * n}.., y={by * n}.. ({channel}) is "
            f"{self.mean_a[b, c]:.4g} where {other} has {self.mean_b[b, c]:.4g} "
            f"(z = {self.z[b, c]:.1f}, allowed {self.threshold:.1f}; "
            f"{failing} of {len(self.z)} blocks differ)"
        )


def block_z_test(
    mean_a: np.ndarray,
    var_a: np.ndarray,
    mean_b: np.ndarray,
    var_b: np.ndarray,
    alpha: float,
    block: int = BLOCK,
) -> BlockTest:
    """Do two images (H, W, C) have the same expectation, block by block?

    Each pixel of mean_a is an independent estimate with variance var_a (the same
    for b), measured from the noise of the renders it averages. A block of n
    pixels then has a mean with variance sum(var) / n^2, and the two block means
    differ significantly when |mean_a - mean_b| / sqrt(var_a + var_b) exceeds the
    two-sided normal quantile at alpha / (blocks x channels) (Bonferroni): two
    correct renderers are flagged with probability below alpha. A variance floor
    of 1e-9 relative stands for rounding in blocks that have no noise at all.
    """
    if np.shape(mean_a) != np.shape(mean_b):
        raise ValueError(f"image shapes differ: {np.shape(mean_a)} vs {np.shape(mean_b)}")
    sum_a, n = block_sums(np.asarray(mean_a, dtype=np.float64), block)
    sum_b, _ = block_sums(np.asarray(mean_b, dtype=np.float64), block)
    var_sum, _ = block_sums(np.add(var_a, var_b, dtype=np.float64), block)
    a, b, var = sum_a / n, sum_b / n, var_sum / (n * n)
    floor = (1e-9 * np.maximum(1.0, np.maximum(np.abs(a), np.abs(b)))) ** 2
    z = np.abs(a - b) / np.sqrt(var + floor)
    blocks_x = -(-np.shape(mean_a)[1] // block)
    return BlockTest(z, bonferroni_z(alpha, z.size), a, b, blocks_x, block)
