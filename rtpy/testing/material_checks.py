"""The checks of a material that its samples make (chi2_test aside, see chi_square.py).

A material has three functions that must agree (see rtpy/materials/material.py):
scattering() draws directions, pdf() claims the density it draws them with, and
BRDF() is f_r, so that every sample's weight is BRDF * |cos| / pdf. Each check
returns a CheckResult, true when the check passed:

- check_weights: is every sample's attenuation BRDF * |cos| / pdf, and the
  ScatterInfo's pdf the value pdf() returns?
- check_energy: does the mean weight (the directional albedo by importance
  sampling) agree with a quadrature of BRDF * |cos|, and is no light created?

The checks look from outside the material, or with inside=True from inside it
(glass seen from within; see local_setup.py). The checks at chosen directions,
reciprocity and finite values, are in pointwise_checks.py.

Where the light arriving from one direction goes: directional_albedo integrates
BRDF * |cos| over the directions toward the light twice, by importance sampling
(the mean of scattering()'s weights) and by adaptive quadrature. A material that
transmits (glass) scatters to both sides of the surface: the quadrature then covers
the whole sphere. Its BSDF for radiance is not symmetric (radiance is scaled by
(eta_o / eta_i)^2 on refraction), so the mean weight is not the fraction of the
light that passes: from inside glass it exceeds 1. The fraction of the power
arriving from wo that leaves toward wi is f(wi, wo) |cos(theta_i)|, the BSDF with its
arguments swapped (the light coming from wo): check_energy bounds that, which is the
same for a reciprocal BRDF.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..materials.material import Material
from ..ray import Ray
from ..vec3 import Vec3
from .local_setup import (
    ORIGIN,
    TWO_PI,
    Samples,
    brdf_between,
    close,
    color_text,
    get_samples,
    incident_ray,
    local_direction,
    local_hit,
    vector_text,
)
from .quadrature import AdaptiveSimpson2D, sample_spacing, subdivide
from .statistics import normal_quantile

__all__ = [
    "INCONCLUSIVE_QUADRATURE_ERROR",
    "AlbedoEstimate",
    "CheckResult",
    "check_energy",
    "check_weights",
    "directional_albedo",
]


@dataclass
class CheckResult:
    """One check at one incident angle (None for checks over all angles), from
    outside the material or (inside) from inside it.

    True in a boolean context when the check passed, so `assert check_weights(m, 30)`
    works and shows the details when it fails."""

    check: str
    incident_deg: float | None
    passed: bool
    detail: str
    p_value: float | None = None
    skipped: bool = False
    inside: bool = False

    def __bool__(self) -> bool:
        return self.passed

    @property
    def angle_text(self) -> str:
        """The incident angle in degrees ("all" for checks over all angles), with
        " in" when seen from inside."""
        angle = "all" if self.incident_deg is None else f"{self.incident_deg:g}"
        return angle + (" in" if self.inside else "")

    def __str__(self) -> str:
        angle = "all" if self.incident_deg is None else f"{self.incident_deg:g} deg"
        angle += " from inside" if self.inside else ""
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
    inside: bool = False,
) -> CheckResult:
    """For the first n scattered (non-specular) samples: attenuation ==
    BRDF(ray_in, scattered, hit) * |cos| / pdf(ray_in, scattered, hit) per channel,
    ScatterInfo.pdf == pdf(...), and the direction is a unit vector."""
    samples = get_samples(material, incident_deg, n, seed, phi_deg, samples, inside)
    ray_view = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material, inside)
    idx = np.flatnonzero(samples.scattered)[:n]
    if len(idx) == 0:
        detail = "no scattered samples"
        return CheckResult("weights", incident_deg, True, detail, skipped=True, inside=inside)
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
        detail = f"{failures} of {len(idx)} samples wrong; {first}"
        return CheckResult("weights", incident_deg, False, detail, inside=inside)
    detail = f"{len(idx)} samples: attenuation = BRDF * cos / pdf"
    return CheckResult("weights", incident_deg, True, detail, inside=inside)


RGB = tuple[float, float, float]


@dataclass
class AlbedoEstimate:
    """Directional albedo (the integral of BRDF * |cos| over the directions toward the
    light, for the viewer of the test setup), per channel.

    sampled, standard_error: mean of the scattering() weights (absorbed samples
    count 0) and its standard error; quadrature, quadrature_error: adaptive
    Simpson quadrature of BRDF * |cos| over the upper hemisphere (the whole sphere
    for a material that transmits) and its estimated error (the sum of the
    |S5 - S3| / 15 estimates of the cells).

    reflected, transmitted: the quadrature's parts above and below the surface.
    transmitted_power: the fraction of the power arriving from the viewer's
    direction that passes through the surface, the quadrature of f(wi, wo) |cos|
    below it (equal to transmitted without refraction's radiance scaling);
    sampled_power, power_standard_error: the fraction of the power scattered, by
    sampling (the weights of the transmitted samples with f(wi, wo) for f(wo, wi)).
    power = reflected + transmitted_power, and lost = 1 - power is what the
    material absorbs (or, for single-scattering microfacets, blocks). two_sided:
    the quadrature covered the lower hemisphere (else transmitted is 0).
    """

    sampled: RGB
    standard_error: RGB
    quadrature: RGB
    quadrature_error: float
    n_samples: int
    brdf_evaluations: int
    reflected: RGB = (0.0, 0.0, 0.0)
    transmitted: RGB = (0.0, 0.0, 0.0)
    transmitted_power: RGB = (0.0, 0.0, 0.0)
    sampled_power: RGB = (0.0, 0.0, 0.0)
    power_standard_error: RGB = (0.0, 0.0, 0.0)
    two_sided: bool = False

    @property
    def power(self) -> RGB:
        return tuple(r + t for r, t in zip(self.reflected, self.transmitted_power, strict=True))

    @property
    def lost(self) -> RGB:
        return tuple(1.0 - p for p in self.power)


def _mean_and_error(w: np.ndarray) -> tuple[RGB, RGB]:
    n = len(w)
    se = w.std(axis=0, ddof=1) / math.sqrt(n) if n > 1 else np.full(3, math.inf)
    return tuple(float(x) for x in w.mean(axis=0)), tuple(float(x) for x in se)


def _power_weights(material: Material, samples: Samples, weights: np.ndarray) -> np.ndarray:
    """The weights with each transmitted sample's f(wo, wi) replaced by f(wi, wo): its
    share of the power arriving from wo (weight = f |cos| / pdf)."""
    out = weights.copy()
    wo = local_direction(samples.incident_deg, samples.phi_deg)
    for k in np.flatnonzero(samples.transmitted):
        x, y, z = (float(c) for c in samples.directions[k])
        f = brdf_between(material, Vec3(x, y, z), wo, samples.inside)
        scale = abs(z) / float(samples.pdfs[k])
        out[k] = (f.e0 * scale, f.e1 * scale, f.e2 * scale)
    return out


class _HemisphereQuadrature:
    """Adaptive Simpson quadrature of BRDF * |cos| over one hemisphere of directions
    toward the light, in strips of theta, refined where the samples that went there
    disagree with it. Below the surface the integrand has six components: f(wo, wi)
    |cos| and the swapped f(wi, wo) |cos| (see the module's docstring)."""

    def __init__(self, material: Material, samples: Samples, node_spacing: float, abs_tol: float):
        self.material, self.samples = material, samples
        self.node_spacing, self.abs_tol = node_spacing, abs_tol
        self.ray_view = incident_ray(samples.incident_deg, samples.phi_deg)
        self.wo = local_direction(samples.incident_deg, samples.phi_deg)
        self.hit = local_hit(material, samples.inside)
        # Where the samples went, as (theta, phi), and their weights' channel mean.
        ok = samples.scattered
        d = samples.directions[ok]
        self.theta_s = np.arccos(np.clip(d[:, 2], -1.0, 1.0))
        self.phi_s = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
        self.w_s = samples.weights[ok].mean(axis=1)

    def f_cos_sin(self, theta: float, ph: float, lower: bool) -> tuple[float, ...]:
        s, c = math.sin(theta), math.cos(theta)
        if s <= 0.0 or (c >= 0.0 if lower else c <= 0.0):
            return (0.0,) * (6 if lower else 3)
        wi = Vec3(s * math.cos(ph), s * math.sin(ph), c)
        f = self.material.BRDF(self.ray_view, Ray(ORIGIN, wi), self.hit)
        k = abs(c) * s
        if not lower:
            return (f.e0 * k, f.e1 * k, f.e2 * k)
        g = brdf_between(self.material, wi, self.wo, self.samples.inside)
        return (f.e0 * k, f.e1 * k, f.e2 * k, g.e0 * k, g.e1 * k, g.e2 * k)

    def integrate(self, lower: bool) -> tuple[list[float], float, int]:
        """(integral per component, estimated error, BRDF evaluations) over the
        upper or the lower hemisphere."""
        n = self.samples.n
        # Strips in theta; each strip has its own number of phi cells, fewer near the
        # poles, so that no cell is much more than 4 node spacings wide on the sphere.
        cell = 4.0 * self.node_spacing
        span = [0.5 * math.pi, math.pi] if lower else [0.0, 0.5 * math.pi]
        x_edges, _ = subdivide(span, cell)
        total, error, evaluations = [0.0] * (6 if lower else 3), 0.0, 0
        for lo, hi in zip(x_edges[:-1], x_edges[1:], strict=True):
            widest = max(math.sin(lo), math.sin(hi))
            y_edges, _ = subdivide([0.0, TWO_PI], min(0.5 * math.pi, cell / widest))
            quad = AdaptiveSimpson2D(
                lambda t, p: self.f_cos_sin(t, p, lower), [lo, hi], y_edges, max_evaluations=40_000
            )
            in_strip = (self.theta_s >= lo) & (self.theta_s < hi)
            cell_of = np.searchsorted(y_edges, self.phi_s[in_strip], side="right") - 1
            for j in range(len(y_edges) - 1):
                value, e = quad.cell(0, j, self.abs_tol, 1e-6)
                # The samples in this cell estimate its integral too (sum of weights / n).
                # A lobe narrower than the nodes hides between them, or a node on its
                # peak inflates it: where the two disagree by more than 5 standard
                # errors, or the quadrature is less sure than the samples, integrate
                # again with nodes a third of the samples' spread apart wherever there
                # are samples, before blaming the material.
                mine = cell_of == j
                if np.count_nonzero(mine) >= 2:
                    ws = self.w_s[in_strip][mine]
                    estimate = ws.sum() / n
                    variance = max(float((ws * ws).sum()) / n - estimate * estimate, 0.0) / n
                    spread = math.sqrt(variance)
                    if abs(sum(value[:3]) / 3.0 - estimate) > 5.0 * spread or e > spread:
                        t_in, p_in = self.theta_s[in_strip][mine], self.phi_s[in_strip][mine]
                        quad.max_evaluations = quad.evaluations + 1_000_000
                        value, e = quad.cell(
                            0,
                            j,
                            self.abs_tol,
                            1e-6,
                            points=(t_in, p_in),
                            spacing=sample_spacing(t_in, p_in),
                        )
                total = [t + v for t, v in zip(total, value, strict=True)]
                error += e
            evaluations += quad.evaluations
        return total, error, evaluations


def directional_albedo(
    material: Material,
    incident_deg: float,
    n_samples: int = 100_000,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    node_spacing: float = 0.035,
    abs_tol: float = 1e-7,
    inside: bool = False,
    two_sided: bool | None = None,
) -> AlbedoEstimate:
    """The directional albedo by importance sampling and by quadrature, for the viewer
    at incident_deg outside the surface (inside: inside it). two_sided: integrate below
    the surface too (a material that transmits); None: when a sample went there."""
    samples = get_samples(material, incident_deg, n_samples, seed, phi_deg, samples, inside)
    if two_sided is None:
        two_sided = bool(samples.transmitted.any())
    w = np.where(samples.scattered[:, None], samples.weights, 0.0)
    mean, se = _mean_and_error(w)
    quadrature = _HemisphereQuadrature(material, samples, node_spacing, abs_tol)
    reflected, error, evaluations = quadrature.integrate(lower=False)
    transmitted, power = [0.0] * 3, [0.0] * 3
    sampled_power, power_se = mean, se
    if two_sided:
        below, e, count = quadrature.integrate(lower=True)
        transmitted, power = below[:3], below[3:]
        error, evaluations = error + e, evaluations + count
        sampled_power, power_se = _mean_and_error(_power_weights(material, samples, w))
    return AlbedoEstimate(
        sampled=mean,
        standard_error=se,
        quadrature=tuple(r + t for r, t in zip(reflected, transmitted, strict=True)),
        quadrature_error=error,
        n_samples=samples.n,
        brdf_evaluations=evaluations,
        reflected=tuple(reflected),
        transmitted=tuple(transmitted),
        transmitted_power=tuple(power),
        sampled_power=sampled_power,
        power_standard_error=power_se,
        two_sided=two_sided,
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
    inside: bool = False,
    two_sided: bool | None = None,
) -> CheckResult:
    """The sampled and the quadrature albedo agree, and the albedo is <= max_albedo.

    Agreement per channel: |sampled - quadrature| <= z * SE + allowance, with z
    the two-sided normal critical value for alpha and allowance = 10 times the
    quadrature's error estimate + 1e-6 (the estimate |S5 - S3| / 15 is
    asymptotically the error of the 5 x 5 rule and usually overestimates it; the
    factor 10 covers cells where the integrand is not smooth, the lobe's horizon
    cut-off, and 1e-6 covers rounding in the sums). Energy: the fraction of the
    power scattered (the albedo, for a reciprocal BRDF; reflected plus transmitted
    for glass) is <= max_albedo: sampled <= max_albedo + 4 SE and quadrature <=
    max_albedo + allowance, per channel. A check that passes only because the
    quadrature's error estimate exceeds INCONCLUSIVE_QUADRATURE_ERROR is reported as
    skipped (inconclusive). inside and two_sided as for directional_albedo.
    """
    a = directional_albedo(
        material,
        incident_deg,
        n_samples,
        seed,
        phi_deg,
        samples,
        inside=inside,
        two_sided=two_sided,
    )
    z = normal_quantile(alpha)
    allowance = 10.0 * a.quadrature_error + 1e-6
    problems = []
    for ch, s, se, q in zip("RGB", a.sampled, a.standard_error, a.quadrature, strict=True):
        if not abs(s - q) <= z * se + allowance:
            problems.append(f"{ch}: sampled {s:.5f} +- {se:.5f} disagrees with quadrature {q:.5f}")
    power = zip("RGB", a.sampled_power, a.power_standard_error, a.power, strict=True)
    for ch, s, se, q in power:
        if not s <= max_albedo + 4.0 * se + 1e-9 or not q <= max_albedo + allowance:
            problems.append(f"{ch}: albedo {s:.5f} (quadrature {q:.5f}) > {max_albedo:g}")
    detail = (
        f"albedo {color_text(a.sampled)} +- {color_text(a.standard_error, '.2g')} sampled, "
        f"{color_text(a.quadrature)} by quadrature"
    )
    if a.two_sided:
        detail += (
            f"; of the power: reflected {color_text(a.reflected, '.4f')}, transmitted "
            f"{color_text(a.transmitted_power, '.4f')}, lost {color_text(a.lost, '.4f')}"
        )
    if problems:
        detail = "; ".join(problems) + "; " + detail
        return CheckResult("energy", incident_deg, False, detail, inside=inside)
    if a.quadrature_error > INCONCLUSIVE_QUADRATURE_ERROR:
        # The allowance has grown too wide for the check to mean anything.
        detail = f"inconclusive: quadrature error {a.quadrature_error:.2g}; " + detail
        return CheckResult("energy", incident_deg, True, detail, skipped=True, inside=inside)
    return CheckResult("energy", incident_deg, True, detail, inside=inside)
