"""The single checks of a material (chi2_test aside, see chi_square.py).

A material has three functions that must agree (see rtpy/materials/material.py):
scattering() draws directions, pdf() claims the density it draws them with, and
BRDF() is f_r, so that every sample's weight is BRDF * cos / pdf. Each check
returns a CheckResult, true when the check passed:

- check_weights: is every sample's attenuation BRDF * cos / pdf, and the
  ScatterInfo's pdf the value pdf() returns?
- check_energy: does the mean weight (the directional albedo by importance
  sampling) agree with a quadrature of BRDF * cos, and is the albedo <= 1?
- check_reciprocity: BRDF(wi, wo) == BRDF(wo, wi)?
- check_non_negative_finite: BRDF, pdf and weights finite and >= 0, also at
  grazing angles?
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..materials.material import Material
from ..ray import Ray
from ..sampling import generator, make_generator, use_generator
from ..vec3 import Vec3
from .local_setup import (
    NON_NEGATIVE,
    ORIGIN,
    RECIPROCITY,
    TWO_PI,
    Samples,
    close,
    color_text,
    get_samples,
    incident_ray,
    light_ray,
    local_direction,
    local_hit,
    sampling_generator,
    vector_text,
    view_ray,
)
from .quadrature import AdaptiveSimpson2D, sample_spacing, subdivide
from .statistics import normal_quantile

__all__ = [
    "GRAZING_ANGLES",
    "INCONCLUSIVE_QUADRATURE_ERROR",
    "AlbedoEstimate",
    "CheckResult",
    "check_energy",
    "check_non_negative_finite",
    "check_reciprocity",
    "check_weights",
    "directional_albedo",
]


@dataclass
class CheckResult:
    """One check at one incident angle (None for checks over all angles).

    True in a boolean context when the check passed, so `assert check_weights(m, 30)`
    works and shows the details when it fails."""

    check: str
    incident_deg: float | None
    passed: bool
    detail: str
    p_value: float | None = None
    skipped: bool = False

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        angle = "all" if self.incident_deg is None else f"{self.incident_deg:g} deg"
        status = "skipped" if self.skipped else ("pass" if self.passed else "FAIL")
        p = "" if self.p_value is None else f", p = {self.p_value:.3g}"
        return f"{self.check} at {angle}: {status}{p}: {self.detail}"


def check_weights(
    material: Material,
    incident_deg: float,
    n: int = 2000,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    rel_tol: float = 1e-9,
) -> CheckResult:
    """For the first n scattered (non-specular) samples: attenuation ==
    BRDF(ray_in, scattered, hit) * |cos| / pdf(ray_in, scattered, hit) per channel,
    ScatterInfo.pdf == pdf(...), and the direction is a unit vector."""
    samples = get_samples(material, incident_deg, n, seed, phi_deg, samples)
    ray_view = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material)
    idx = np.flatnonzero(samples.scattered)[:n]
    if len(idx) == 0:
        return CheckResult("weights", incident_deg, True, "no scattered samples", skipped=True)
    failures, first = 0, ""
    for k in idx:
        x, y, z = (float(c) for c in samples.directions[k])
        weight = [float(c) for c in samples.weights[k]]
        wi = Vec3(x, y, z)
        f = material.BRDF(ray_view, Ray(ORIGIN, wi), hit)
        pdf = material.pdf(ray_view, Ray(ORIGIN, wi), hit)
        length = math.sqrt(x * x + y * y + z * z)
        problem = ""
        if not abs(length - 1.0) <= 1e-9:
            problem = f"direction has length {length!r}"
        elif not close(float(samples.pdfs[k]), pdf, rel_tol):
            problem = f"ScatterInfo.pdf = {samples.pdfs[k]:.9g} but pdf() = {pdf:.9g}"
        elif not pdf > 0.0:
            problem = f"pdf() = {pdf!r} for a direction scattering() returned"
        else:
            expect = [c * abs(z) / pdf for c in (f.e0, f.e1, f.e2)]
            if not all(close(a, b, rel_tol) for a, b in zip(weight, expect, strict=True)):
                problem = (
                    f"attenuation {color_text(weight)} but BRDF * cos / pdf = {color_text(expect)}"
                )
        if problem:
            failures += 1
            if not first:
                theta = math.degrees(math.acos(max(-1.0, min(1.0, z / length))))
                first = f"e.g. wi = {vector_text((x, y, z))} (theta {theta:.2f} deg): {problem}"
    if failures:
        return CheckResult(
            "weights", incident_deg, False, f"{failures} of {len(idx)} samples wrong; {first}"
        )
    return CheckResult(
        "weights", incident_deg, True, f"{len(idx)} samples: attenuation = BRDF * cos / pdf"
    )


@dataclass
class AlbedoEstimate:
    """Directional albedo (the reflected fraction of light arriving from one
    direction: the integral of BRDF * cos over the hemisphere), per channel.

    sampled, standard_error: mean of the scattering() weights (absorbed samples
    count 0) and its standard error; quadrature, quadrature_error: adaptive
    Simpson quadrature of BRDF * cos over the upper hemisphere and its estimated
    error (the sum of the |S5 - S3| / 15 estimates of the cells)."""

    sampled: tuple[float, float, float]
    standard_error: tuple[float, float, float]
    quadrature: tuple[float, float, float]
    quadrature_error: float
    n_samples: int
    brdf_evaluations: int


def directional_albedo(
    material: Material,
    incident_deg: float,
    n_samples: int = 100_000,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    node_spacing: float = 0.035,
    abs_tol: float = 1e-7,
) -> AlbedoEstimate:
    """The directional albedo by importance sampling and by quadrature."""
    samples = get_samples(material, incident_deg, n_samples, seed, phi_deg, samples)
    w = np.where(samples.scattered[:, None], samples.weights, 0.0)
    n = samples.n
    mean = w.mean(axis=0)
    se = w.std(axis=0, ddof=1) / math.sqrt(n) if n > 1 else np.full(3, math.inf)

    ray_view = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material)

    def f_cos_sin(theta: float, ph: float) -> tuple[float, float, float]:
        s, c = math.sin(theta), math.cos(theta)
        if s <= 0.0 or c <= 0.0:
            return (0.0, 0.0, 0.0)
        f = material.BRDF(ray_view, Ray(ORIGIN, Vec3(s * math.cos(ph), s * math.sin(ph), c)), hit)
        k = c * s
        return (f.e0 * k, f.e1 * k, f.e2 * k)

    # Where the samples went, as (theta, phi), and their weights' channel mean.
    ok = samples.scattered
    d = samples.directions[ok]
    theta_s = np.arccos(np.clip(d[:, 2], -1.0, 1.0))
    phi_s = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
    w_s = samples.weights[ok].mean(axis=1)

    # Strips in theta; each strip has its own number of phi cells, fewer near the
    # normal, so that no cell is much more than 4 node spacings wide on the sphere.
    cell = 4.0 * node_spacing
    x_edges, _ = subdivide([0.0, 0.5 * math.pi], cell)
    total, error, evaluations = [0.0, 0.0, 0.0], 0.0, 0
    for lo, hi in zip(x_edges[:-1], x_edges[1:], strict=True):
        y_edges, _ = subdivide([0.0, TWO_PI], min(0.5 * math.pi, cell / math.sin(hi)))
        quad = AdaptiveSimpson2D(f_cos_sin, [lo, hi], y_edges, max_evaluations=40_000)
        in_strip = (theta_s >= lo) & (theta_s < hi)
        cell_of = np.searchsorted(y_edges, phi_s[in_strip], side="right") - 1
        for j in range(len(y_edges) - 1):
            value, e = quad.cell(0, j, abs_tol, 1e-6)
            # The samples in this cell estimate its integral too (sum of weights / n).
            # A lobe narrower than the nodes hides between them, or a node on its
            # peak inflates it: where the two disagree by more than 5 standard
            # errors, or the quadrature is less sure than the samples, integrate
            # again with nodes a third of the samples' spread apart wherever there
            # are samples, before blaming the material.
            mine = cell_of == j
            if np.count_nonzero(mine) >= 2:
                ws = w_s[in_strip][mine]
                estimate = ws.sum() / n
                spread = math.sqrt(max(float((ws * ws).sum()) / n - estimate * estimate, 0.0) / n)
                if abs(sum(value) / 3.0 - estimate) > 5.0 * spread or e > spread:
                    t_in, p_in = theta_s[in_strip][mine], phi_s[in_strip][mine]
                    quad.max_evaluations = quad.evaluations + 1_000_000
                    value, e = quad.cell(
                        0, j, abs_tol, 1e-6, points=(t_in, p_in), spacing=sample_spacing(t_in, p_in)
                    )
            total = [t + v for t, v in zip(total, value, strict=True)]
            error += e
        evaluations += quad.evaluations
    return AlbedoEstimate(
        sampled=tuple(float(x) for x in mean),
        standard_error=tuple(float(x) for x in se),
        quadrature=tuple(total),
        quadrature_error=error,
        n_samples=n,
        brdf_evaluations=evaluations,
    )


# A directional albedo whose quadrature is less certain than this cannot check anything.
INCONCLUSIVE_QUADRATURE_ERROR = 1e-3


def check_energy(
    material: Material,
    incident_deg: float,
    n_samples: int = 100_000,
    alpha: float = 0.01,
    max_albedo: float = 1.0,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
) -> CheckResult:
    """The sampled and the quadrature albedo agree, and the albedo is <= max_albedo.

    Agreement per channel: |sampled - quadrature| <= z * SE + allowance, with z
    the two-sided normal critical value for alpha and allowance = 10 times the
    quadrature's error estimate + 1e-6 (the estimate |S5 - S3| / 15 is
    asymptotically the error of the 5 x 5 rule and usually overestimates it; the
    factor 10 covers cells where the integrand is not smooth, the lobe's horizon
    cut-off, and 1e-6 covers rounding in the sums). Energy: sampled <= max_albedo
    + 4 SE and quadrature <= max_albedo + allowance, per channel. A check that
    passes only because the quadrature's error estimate exceeds
    INCONCLUSIVE_QUADRATURE_ERROR is reported as skipped (inconclusive).
    """
    a = directional_albedo(material, incident_deg, n_samples, seed, phi_deg, samples)
    z = normal_quantile(alpha)
    allowance = 10.0 * a.quadrature_error + 1e-6
    problems, worst_z = [], 0.0
    for ch, s, se, q in zip("RGB", a.sampled, a.standard_error, a.quadrature, strict=True):
        gap = abs(s - q)
        if gap > 0.0:
            worst_z = max(worst_z, gap / se if se > 0.0 else math.inf)
        if not gap <= z * se + allowance:
            problems.append(f"{ch}: sampled {s:.5f} +- {se:.5f} disagrees with quadrature {q:.5f}")
        if not s <= max_albedo + 4.0 * se + 1e-9 or not q <= max_albedo + allowance:
            problems.append(f"{ch}: albedo {s:.5f} (quadrature {q:.5f}) > {max_albedo:g}")
    detail = (
        f"albedo {color_text(a.sampled)} +- {color_text(a.standard_error, '.2g')} sampled, "
        f"{color_text(a.quadrature)} by quadrature"
    )
    if problems:
        return CheckResult("energy", incident_deg, False, "; ".join(problems) + "; " + detail)
    if a.quadrature_error > INCONCLUSIVE_QUADRATURE_ERROR:
        # The allowance has grown too wide for the check to mean anything.
        detail = f"inconclusive: quadrature error {a.quadrature_error:.2g}; " + detail
        return CheckResult("energy", incident_deg, True, detail, skipped=True)
    return CheckResult("energy", incident_deg, True, detail)


def check_reciprocity(
    material: Material, n_pairs: int = 2000, seed: int = 0, rel_tol: float = 1e-9
) -> CheckResult:
    """BRDF(wo -> wi) == BRDF(wi -> wo) for random pairs of directions above the
    surface (uniform on the hemisphere, a quarter of them within 1 degree of it)."""
    hit = local_hit(material)
    failures, first = 0, ""
    with use_generator(make_generator(seed, RECIPROCITY)):
        r = generator().random
        for k in range(n_pairs):
            dirs = []
            for _ in range(2):
                if k % 4 == 3:
                    theta = 89.0 + r()  # grazing
                else:
                    theta = math.degrees(math.acos(r()))  # uniform on the hemisphere
                dirs.append(local_direction(theta, 360.0 * r()))
            a, b = dirs
            f_ab = material.BRDF(view_ray(a), light_ray(b), hit)
            f_ba = material.BRDF(view_ray(b), light_ray(a), hit)
            x, y = (f_ab.e0, f_ab.e1, f_ab.e2), (f_ba.e0, f_ba.e1, f_ba.e2)
            if not all(close(p, q, rel_tol) for p, q in zip(x, y, strict=True)):
                failures += 1
                if not first:
                    first = (
                        f"e.g. wo = {vector_text(a.tolist())}, wi = {vector_text(b.tolist())}: "
                        f"BRDF {color_text(x)}, swapped {color_text(y)}"
                    )
    if failures:
        return CheckResult(
            "reciprocity", None, False, f"{failures} of {n_pairs} pairs differ; {first}"
        )
    return CheckResult("reciprocity", None, True, f"{n_pairs} direction pairs")


GRAZING_ANGLES = (0.0, 30.0, 60.0, 85.0, 89.0, 89.9, 89.999)
_LIGHT_THETAS = (0.0, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0, 89.9, 89.999, 90.0, 120.0, 180.0)
_LIGHT_PHIS = (0.0, 45.0, 90.0, 135.0, 180.0, 270.0)


def check_non_negative_finite(
    material: Material,
    incident_angles: Sequence[float] = GRAZING_ANGLES,
    n: int = 500,
    seed: int = 0,
) -> CheckResult:
    """BRDF, pdf, scattering weights and pdfs finite and >= 0 (and scattered
    directions finite), for incident angles down to grazing, light directions on
    a grid plus the mirror and the retro-reflection directions, and n samples
    of scattering() per incident angle."""
    problems: list[str] = []
    hit = local_hit(material)

    def bad_color(c) -> bool:
        return not all(math.isfinite(x) and x >= 0.0 for x in (c.e0, c.e1, c.e2))

    def bad_number(x) -> bool:
        return not (math.isfinite(x) and x >= 0.0)

    for theta in incident_angles:
        for phi in (0.0, 60.0):
            ray_in = incident_ray(theta, phi)
            wo = local_direction(theta, phi)
            lights = [local_direction(t, p) for t in _LIGHT_THETAS for p in _LIGHT_PHIS]
            lights += [Vec3(-wo.e0, -wo.e1, wo.e2), wo]
            for wi in lights:
                f = material.BRDF(ray_in, light_ray(wi), hit)
                p = material.pdf(ray_in, light_ray(wi), hit)
                if bad_color(f) or bad_number(p):
                    problems.append(
                        f"incident {theta:g} deg, wi {vector_text(wi.tolist())}: "
                        f"BRDF {color_text(f)}, pdf {p!r}"
                    )
            with use_generator(sampling_generator(seed, NON_NEGATIVE, theta, phi)):
                for _ in range(n):
                    s = material.scattering(ray_in, hit)
                    if s is None:
                        continue
                    d = s.scattered_ray.direction
                    if bad_color(s.attenuation) or bad_number(s.pdf):
                        problems.append(
                            f"incident {theta:g} deg: sample weight {color_text(s.attenuation)}, "
                            f"pdf {s.pdf!r}"
                        )
                    elif not all(math.isfinite(x) for x in (d.e0, d.e1, d.e2)):
                        problems.append(f"incident {theta:g} deg: direction {vector_text(d)}")
    if problems:
        return CheckResult(
            "finite >= 0",
            None,
            False,
            f"{len(problems)} bad values; e.g. {problems[0]}",
        )
    return CheckResult(
        "finite >= 0", None, True, f"incident angles {', '.join(f'{t:g}' for t in incident_angles)}"
    )
