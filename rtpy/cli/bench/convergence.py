"""Error against a reference, bias tests and convergence slopes of `rtpy bench`.

Each spp level is rendered `repeats` times with independent seeds. A level
records: the wall time of one render, paths/s, the peak resident memory of the
render, and against the reference R (over its mask, all channels):

- MSE = mean (I - R)^2 - mean var(R)   (the reference's own noise subtracted),
  RMSE = sqrt(MSE), relMSE = MSE / mean R^2 (independent of the scene's units);
- bias = mean (I - R), given relative to mean R, with its standard error from
  the spread of each pixel's values over the repeats (pixels are independent:
  SE^2 = sum_p s_p^2 / (repeats P^2) + the reference's variance); it is
  significant when |bias / SE| exceeds the two-sided normal quantile at a
  family-wise level ALPHA, Bonferroni-corrected over every level of the run,
  and is more than BIAS_FLOOR of mean R (rays start 1e-9 off surfaces);
- efficiency = 1 / (relMSE * seconds per render).

For each series it fits log MSE = a + slope log spp by weighted least squares,
each level weighted by 1 / var(log MSE), var(log MSE) ~ (SE(MSE) / MSE)^2 with
SE(MSE) from the spread of the per-pixel squared errors; the slope's standard
error is sqrt(1 / sum w (x - mean_w x)^2). An unbiased estimator has
E[MSE] = sigma^2 / spp exactly (independent samples), so slope = -1; a bias b
adds b^2, which flattens the slope as spp grows. With a stratified or Sobol sampler
(rtpy.sampler) the samples of a pixel are not independent and the MSE may fall
faster than 1/spp: a slope steeper than -1 is "faster than 1/N", never bias (a bias
flattens the slope); only a slope above -1 + SLOPE_TOLERANCE is a problem there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...testing.reference import Reference
from ...testing.statistics import bonferroni_z

ALPHA = 1e-3  # family-wise false-alarm rate of the bias tests of one run
SLOPE_TOLERANCE = 0.15  # |slope + 1| allowed for an unbiased estimator
# Rays leave surfaces 1e-9 (relative) off them, so even exact estimators are off by
# about that much: a bias below BIAS_FLOOR (relative) is never flagged, and an RMSE
# below ROUNDING (relative) counts as zero error (no slope to fit).
BIAS_FLOOR = 1e-6
ROUNDING = 1e-7


def error_stats(images: np.ndarray, ref: Reference) -> dict[str, float]:
    """Errors of `images` (repeats, H, W, 3), independent renders, against ref:
    mse and its standard error mse_se, rel_mse, bias and its standard error
    bias_se, rel_bias (the Level fields of the same names)."""
    e = images[:, ref.mask, :] - ref.image[ref.mask]  # (repeats, P, 3)
    var_ref = ref.variance[ref.mask]  # (P, 3)
    sq = (e * e - var_ref).mean(axis=2).ravel()  # per render and pixel
    n = sq.size
    mse = float(sq.mean())
    mse_se = float(sq.std(ddof=1) / math.sqrt(n)) if n > 1 else math.inf
    ref_sq = float((ref.image[ref.mask] ** 2).mean())
    per_pixel = e.mean(axis=2)  # (repeats, P)
    repeats, pixels = per_pixel.shape
    bias = float(per_pixel.mean())
    if repeats > 1:
        s2 = per_pixel.var(axis=0, ddof=1)
        bias_var = s2.sum() / (repeats * pixels**2)
    else:
        bias_var = math.inf
    bias_var += float(var_ref.mean(axis=1).sum()) / pixels**2
    ref_mean = float(ref.image[ref.mask].mean())
    return {
        "mse": mse,
        "mse_se": mse_se,
        "rel_mse": mse / ref_sq if ref_sq > 0 else math.nan,
        "bias": bias,
        "bias_se": math.sqrt(bias_var),
        "rel_bias": bias / ref_mean if ref_mean != 0 else math.nan,
    }


def z_score(bias: float, se: float, scale: float) -> float:
    """bias / se; for a noise-free estimate (se = 0), 0 if the bias is rounding
    (below 1e-12 of the reference's scale), else infinite."""
    if se > 0:
        return bias / se
    return 0.0 if abs(bias) <= 1e-12 * max(scale, 1e-300) else math.copysign(math.inf, bias)


@dataclass
class Level:
    """One spp level of one (scene, backend, integrator) series."""

    scene: str
    backend: str
    integrator: str
    spp: int
    repeats: int
    width: int
    height: int
    seconds: float  # per render (mean over the repeats)
    paths_per_second: float
    peak_mb: float
    rmse: float
    mse: float
    mse_se: float
    rel_mse: float
    bias: float
    bias_se: float
    rel_bias: float
    bias_z: float
    exact: bool = False  # RMSE below ROUNDING of the reference's scale: no error
    significant: bool = False
    efficiency: float = math.nan
    reference: str = ""
    sampler: str = "independent"


@dataclass
class Fit:
    """The fitted slope of log MSE against log spp for one series."""

    scene: str
    backend: str
    integrator: str
    slope: float | None
    slope_se: float | None
    levels: int
    note: str = ""
    sampler: str = "independent"

    @property
    def slope_ok(self) -> bool:
        """-1 within the tolerance; with a sampler other than independent, also any
        steeper slope (faster than 1/N)."""
        if self.slope is None:
            return False
        return abs(self.slope + 1.0) < SLOPE_TOLERANCE or self.faster

    @property
    def faster(self) -> bool:
        """A stratifying sampler's error falls faster than 1/N (slope below -1 by more
        than the tolerance)."""
        return (
            self.sampler != "independent"
            and self.slope is not None
            and self.slope < -1.0 - SLOPE_TOLERANCE
        )


def series_key(x: Level | Fit) -> tuple[str, str, str, str]:
    """What a series is: (scene, backend, integrator variant, sampler)."""
    return x.scene, x.backend, x.integrator, x.sampler


def series_name(x: Level | Fit) -> str:
    """scene/backend/variant, and the sampler when it is not the independent one."""
    name = f"{x.scene}/{x.backend}/{x.integrator}"
    return name if x.sampler == "independent" else f"{name}/{x.sampler}"


def fit_slope(spps, mses, mse_ses, zero: float = 0.0) -> tuple[float | None, float | None]:
    """Weighted least-squares slope of log MSE on log spp and its standard error;
    (None, None) with fewer than 2 levels of MSE above `zero`."""
    pts = [
        (math.log(s), math.log(m), (se / m) ** 2)
        for s, m, se in zip(spps, mses, mse_ses, strict=True)
        if m > zero and math.isfinite(se)
    ]
    if len({p[0] for p in pts}) < 2:
        return None, None
    x = np.array([p[0] for p in pts])
    y = np.array([p[1] for p in pts])
    w = 1.0 / np.maximum(np.array([p[2] for p in pts]), 1e-300)
    xm = (w * x).sum() / w.sum()
    ym = (w * y).sum() / w.sum()
    sxx = (w * (x - xm) ** 2).sum()
    slope = float((w * (x - xm) * (y - ym)).sum() / sxx)
    return slope, float(math.sqrt(1.0 / sxx))


@dataclass
class BenchResult:
    levels: list[Level] = field(default_factory=list)
    fits: list[Fit] = field(default_factory=list)
    z_critical: float = math.nan
    settings: dict = field(default_factory=dict)
    interrupted: bool = False  # stopped by Ctrl-C: holds the levels finished before

    def finish(self) -> None:
        """Decide significance (Bonferroni over all levels) and efficiency."""
        self.z_critical = bonferroni_z(ALPHA, max(1, len(self.levels)))
        for lv in self.levels:
            lv.significant = bool(
                abs(lv.bias_z) > self.z_critical and not abs(lv.rel_bias) <= BIAS_FLOOR
            )
            denom = lv.rel_mse * lv.seconds
            lv.efficiency = 1.0 / denom if denom > 0 and not lv.exact else math.inf

    def problems(self, variants=None) -> list[str]:
        """Series that fail the unbiasedness check: a significant bias at any level,
        or a fitted slope outside -1 +- SLOPE_TOLERANCE (series with zero error,
        which have no slope, pass on their bias alone)."""
        out = []
        for lv in self.levels:
            if (variants is None or lv.integrator in variants) and lv.significant:
                out.append(
                    f"{series_name(lv)} spp {lv.spp}: bias "
                    f"{lv.bias:+.3g} (z = {lv.bias_z:.1f} > {self.z_critical:.2f})"
                )
        for f in self.fits:
            if (variants is None or f.integrator in variants) and f.slope is not None:
                if not f.slope_ok:
                    out.append(
                        f"{series_name(f)}: slope {f.slope:.3f} "
                        f"+- {f.slope_se:.3f} outside -1 +- {SLOPE_TOLERANCE}"
                    )
        return out
