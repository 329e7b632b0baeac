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
from functools import partial

import numpy as np

from ..materials.material import Material
from .local_setup import (
    TWO_PI,
    Samples,
    close,
    color_text,
    get_samples,
    local_direction,
    vector_text,
)
from .quadrature import AdaptiveSimpson2D, CellRequest, integrate_cells, sample_spacing, subdivide
from .statistics import normal_quantile
from .subject import MaterialSubject, as_subject

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
    material: Material | MaterialSubject,
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
    ScatterInfo.pdf == pdf(...), and the direction is a unit vector. A draw with no
    scattered sample fails: it shows nothing."""
    subject = as_subject(material)
    samples = get_samples(subject, incident_deg, n, seed, phi_deg, samples, inside)
    idx = np.flatnonzero(samples.scattered)[:n]
    if len(idx) == 0:  # nothing to check is not a pass
        detail = f"no scattered samples: scattering() returned no direction in {samples.n} draws"
        return CheckResult("weights", incident_deg, False, detail, inside=inside)
    wi = samples.directions[idx]
    wo = np.broadcast_to(local_direction(incident_deg, phi_deg).tolist(), wi.shape)
    brdfs = np.asarray(subject.brdf(wo, wi, inside=inside), dtype=float).tolist()
    pdfs = np.asarray(subject.pdf(wo, wi, inside=inside), dtype=float).tolist()
    failures, first = 0, ""
    for k, f, pdf in zip(idx.tolist(), brdfs, pdfs, strict=True):
        x, y, z = samples.directions[k].tolist()
        weight = samples.weights[k].tolist()
        length = math.sqrt(x * x + y * y + z * z)
        problem = ""
        if not abs(length - 1.0) <= 1e-9:
            problem = f"direction has length {length!r}"
        elif not close(float(samples.pdfs[k]), pdf, rel_tol):
            problem = f"ScatterInfo.pdf = {samples.pdfs[k]:.9g} but pdf() = {pdf:.9g}"
        elif not pdf > 0.0:
            problem = f"pdf() = {pdf!r} for a direction scattering() returned"
        else:
            expect = [c * abs(z) / pdf for c in f]
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


def _power_weights(subject: MaterialSubject, samples: Samples, weights: np.ndarray) -> np.ndarray:
    """The weights with each transmitted sample's f(wo, wi) replaced by f(wi, wo): its
    share of the power arriving from wo (weight = f |cos| / pdf)."""
    out = weights.copy()
    below = np.flatnonzero(samples.transmitted)
    if len(below) == 0:
        return out
    wo = local_direction(samples.incident_deg, samples.phi_deg).tolist()
    d = samples.directions[below]
    f = np.asarray(subject.brdf(d, np.broadcast_to(wo, d.shape), inside=samples.inside), float)
    for k, row, z, pdf in zip(
        below, f.tolist(), d[:, 2].tolist(), samples.pdfs[below].tolist(), strict=True
    ):
        scale = abs(z) / pdf
        out[k] = (row[0] * scale, row[1] * scale, row[2] * scale)
    return out


class _HemisphereQuadrature:
    """Adaptive Simpson quadrature of BRDF * |cos| over the directions toward the
    light, in strips of theta, refined where the samples that went there disagree
    with it. Below the surface the integrand has six components: f(wo, wi) |cos|
    and the swapped f(wi, wo) |cos| (see the module's docstring). Every strip of
    both hemispheres is integrated together: one brdf() call per round."""

    def __init__(
        self, subject: MaterialSubject, samples: Samples, node_spacing: float, abs_tol: float
    ):
        self.subject, self.samples = subject, samples
        self.node_spacing, self.abs_tol = node_spacing, abs_tol
        self.wo = local_direction(samples.incident_deg, samples.phi_deg).tolist()
        # Where the samples went, as (theta, phi), and their weights' channel mean.
        ok = samples.scattered
        d = samples.directions[ok]
        self.theta_s = np.arccos(np.clip(d[:, 2], -1.0, 1.0))
        self.phi_s = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
        self.w_s = samples.weights[ok].mean(axis=1)
        self.lower: dict[int, bool] = {}  # id(integrator) -> below the surface

    def f_cos_sin(self, batches) -> list[np.ndarray]:
        """BRDF * |cos| * sin(theta) at the nodes of every (integrator, theta, phi) of
        a round, three components above the surface, six below: one brdf() call."""
        wo_rows, wi_rows, plan = [], [], []
        for quad, theta, phi in batches:
            lower = self.lower[id(quad)]
            ks = []
            for t, ph in zip(theta.tolist(), phi.tolist(), strict=True):
                s, c = math.sin(t), math.cos(t)
                if s <= 0.0 or (c >= 0.0 if lower else c <= 0.0):
                    ks.append(None)
                    continue
                wi = (s * math.cos(ph), s * math.sin(ph), c)
                wo_rows.append(self.wo)
                wi_rows.append(wi)
                if lower:  # and the swapped f(wi, wo)
                    wo_rows.append(wi)
                    wi_rows.append(self.wo)
                ks.append(abs(c) * s)
            plan.append((lower, ks))
        f = np.zeros((0, 3))
        if wo_rows:
            f = self.subject.brdf(np.array(wo_rows), np.array(wi_rows), inside=self.samples.inside)
            f = np.asarray(f, dtype=float).tolist()
        out, row = [], 0
        for lower, ks in plan:
            width = 6 if lower else 3
            values = []
            for k in ks:
                if k is None:
                    values.append((0.0,) * width)
                    continue
                a = f[row]
                if lower:
                    g = f[row + 1]
                    values.append((a[0] * k, a[1] * k, a[2] * k, g[0] * k, g[1] * k, g[2] * k))
                    row += 2
                else:
                    values.append((a[0] * k, a[1] * k, a[2] * k))
                    row += 1
            out.append(np.array(values, dtype=float).reshape(len(ks), width))
        return out

    def strips(self, lower: bool) -> list[tuple[AdaptiveSimpson2D, list[float]]]:
        """The integrators of one hemisphere's strips in theta, with their phi edges.
        Each strip has its own number of phi cells, fewer near the poles, so that no
        cell is much more than 4 node spacings wide on the sphere."""
        cell = 4.0 * self.node_spacing
        span = [0.5 * math.pi, math.pi] if lower else [0.0, 0.5 * math.pi]
        x_edges, _ = subdivide(span, cell)
        out = []
        for lo, hi in zip(x_edges[:-1], x_edges[1:], strict=True):
            widest = max(math.sin(lo), math.sin(hi))
            y_edges, _ = subdivide([0.0, TWO_PI], min(0.5 * math.pi, cell / widest))
            quad = AdaptiveSimpson2D(None, [lo, hi], y_edges, max_evaluations=40_000)
            quad.f = partial(self.f_of, quad)
            self.lower[id(quad)] = lower
            out.append((quad, y_edges))
        return out

    def f_of(self, quad: AdaptiveSimpson2D, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """The integrand of one strip's integrator alone."""
        return self.f_cos_sin([(quad, theta, phi)])[0]

    def integrate(self, two_sided: bool) -> list[tuple[list[float], float, int]]:
        """(integral per component, estimated error, BRDF evaluations) over the upper
        hemisphere and, when two_sided, the lower one."""
        n = self.samples.n
        hemispheres = [self.strips(False)] + ([self.strips(True)] if two_sided else [])
        cells = [
            (quad, j) for strips in hemispheres for quad, y in strips for j in range(len(y) - 1)
        ]
        first = integrate_cells(
            [(q, CellRequest(0, j, self.abs_tol, 1e-6)) for q, j in cells], self.f_cos_sin
        )
        # The samples in a cell estimate its integral too (sum of weights / n). A lobe
        # narrower than the nodes hides between them, or a node on its peak inflates
        # it: where the two disagree by more than 5 standard errors, or the quadrature
        # is less sure than the samples, integrate again with nodes a third of the
        # samples' spread apart wherever there are samples, before blaming the
        # material.
        again, where = [], []
        for k, ((quad, j), (value, e)) in enumerate(zip(cells, first, strict=True)):
            lo, hi = quad.x_edges
            y_edges = quad.y_edges
            in_strip = (self.theta_s >= lo) & (self.theta_s < hi)
            cell_of = np.searchsorted(y_edges, self.phi_s[in_strip], side="right") - 1
            mine = cell_of == j
            if np.count_nonzero(mine) < 2:
                continue
            ws = self.w_s[in_strip][mine]
            estimate = ws.sum() / n
            variance = max(float((ws * ws).sum()) / n - estimate * estimate, 0.0) / n
            spread = math.sqrt(variance)
            if abs(sum(value[:3]) / 3.0 - estimate) > 5.0 * spread or e > spread:
                t_in, p_in = self.theta_s[in_strip][mine], self.phi_s[in_strip][mine]
                points, spacing = (t_in, p_in), sample_spacing(t_in, p_in)
                again.append((quad, CellRequest(0, j, self.abs_tol, 1e-6, 0.0, points, spacing)))
                where.append(k)
        for quad in {id(q): q for q, _ in again}.values():
            quad.max_evaluations = quad.evaluations + 1_000_000
        for k, result in zip(where, integrate_cells(again, self.f_cos_sin), strict=True):
            first[k] = result
        out = []
        for strips in hemispheres:
            width = 3 if strips is hemispheres[0] else 6
            total, error, evaluations = [0.0] * width, 0.0, 0
            for quad, _ in strips:
                for (q, _), (value, e) in zip(cells, first, strict=True):
                    if q is quad:
                        total = [t + v for t, v in zip(total, value, strict=True)]
                        error += e
                evaluations += quad.evaluations
            out.append((total, error, evaluations))
        return out


def directional_albedo(
    material: Material | MaterialSubject,
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
    subject = as_subject(material)
    samples = get_samples(subject, incident_deg, n_samples, seed, phi_deg, samples, inside)
    if two_sided is None:
        two_sided = bool(samples.transmitted.any())
    w = np.where(samples.scattered[:, None], samples.weights, 0.0)
    mean, se = _mean_and_error(w)
    quadrature = _HemisphereQuadrature(subject, samples, node_spacing, abs_tol)
    parts = quadrature.integrate(two_sided)
    reflected, error, evaluations = parts[0]
    transmitted, power = [0.0] * 3, [0.0] * 3
    sampled_power, power_se = mean, se
    if two_sided:
        below, e, count = parts[1]
        transmitted, power = below[:3], below[3:]
        error, evaluations = error + e, evaluations + count
        sampled_power, power_se = _mean_and_error(_power_weights(subject, samples, w))
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
    material: Material | MaterialSubject,
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
