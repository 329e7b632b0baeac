"""rtpy.testing: statistical checks that a material is consistent with itself.

A material has three functions that must agree (see rtpy/materials/material.py):
scattering() draws directions, pdf() claims the density it draws them with, and
BRDF() is f_r, so that every sample's weight is BRDF * cos / pdf. A mistake in
any of them (a wrong normalisation, a sampling formula that does not match the
pdf, a forgotten cosine) still renders *an* image, only a wrong one. These tools
find such mistakes, in the spirit of Mitsuba 3's chi2 test and pbrt-v4's
bsdfs_test.

How a student uses it::

    from rtpy.testing import check_material
    print(check_material(MyMaterial(...)))

prints a table with one line per check and incident angle, for example::

    check           angle  result  p-value   details
    chi2             30.0  pass    0.4121    100000 samples in 1152 bins (...)
    weights          30.0  FAIL    -         17 of 2000 samples: attenuation != ...

`assert_material(MyMaterial(...))` does the same in a test and raises an
AssertionError with that table when a check fails. The single checks can be run
on their own (they return a CheckResult, which is true when the check passed):

- chi2_test: are the directions scattering() draws distributed with density
  pdf()? The directions are binned on the sphere, pdf() is integrated over every
  bin, and Pearson's chi-square test compares the counts. Absorbed samples
  (scattering() returns None) count as one more category, whose expected count
  is N * (1 - integral of pdf over the sphere).
- check_weights: is every sample's attenuation BRDF * cos / pdf, and the
  ScatterInfo's pdf the value pdf() returns?
- check_energy: does the mean weight (the directional albedo by importance
  sampling) agree with a quadrature of BRDF * cos, and is the albedo <= 1?
- check_reciprocity: BRDF(wi, wo) == BRDF(wo, wi)?
- check_non_negative_finite: BRDF, pdf and weights finite and >= 0, also at
  grazing angles?

The local test setup: a flat surface at the origin with normal (0, 0, 1) and
tangent (1, 0, 0). The incoming ray arrives from incident angle theta (and
azimuth phi), that is ray_in.direction = -(sin t cos p, sin t sin p, cos t), so
the viewer sits at wo = (sin t cos p, sin t sin p, cos t). In this frame the
local and world coordinates are the same.

A failing check says what disagrees, at which incident angle, with a p-value
for the statistical ones. Statistical tests fail by chance with probability
alpha; check_material divides its alpha over the incident angles (Sidak), so a
correct material passes all of them with probability 1 - alpha.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..hit_info import HitInfo
from ..materials.material import Material
from ..ray import Ray
from ..sampling import generator, make_generator, use_generator
from ..texture import Texture
from ..vec3 import Vec3

__all__ = [
    "AdaptiveSimpson2D",
    "AlbedoEstimate",
    "Chi2Result",
    "CheckResult",
    "MaterialReport",
    "Samples",
    "assert_material",
    "check_energy",
    "check_material",
    "check_non_negative_finite",
    "check_reciprocity",
    "check_weights",
    "chi2_sf",
    "chi2_test",
    "directional_albedo",
    "draw_samples",
    "gamma_q",
    "incident_ray",
    "light_ray",
    "local_direction",
    "local_hit",
    "material_name",
    "normal_quantile",
    "sidak_alpha",
    "view_ray",
]

NORMAL = Vec3(0.0, 0.0, 1.0)
TANGENT = Vec3(1.0, 0.0, 0.0)
ORIGIN = Vec3(0.0, 0.0, 0.0)
TWO_PI = 2.0 * math.pi

# Tags that keep the random streams of the different checks apart.
_SAMPLING, _RECIPROCITY, _NON_NEGATIVE = 1, 2, 3


# --- the local test setup ------------------------------------------------------------------


def local_direction(theta_deg: float, phi_deg: float = 0.0) -> Vec3:
    """The unit vector at polar angle theta from the normal (0, 0, 1), azimuth phi from x."""
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    s = math.sin(t)
    return Vec3(s * math.cos(p), s * math.sin(p), math.cos(t))


def local_hit(material: Material | None = None) -> HitInfo:
    """A hit on the flat test surface: point at the origin, normal (0, 0, 1),
    tangent (1, 0, 0), front face, surface coordinates (0.5, 0.5)."""
    hit = HitInfo(ORIGIN, NORMAL, 1.0, True, material, None, 0.5, 0.5)
    hit.tangent = TANGENT
    return hit


def view_ray(wo: Vec3) -> Ray:
    """The ray arriving at the origin from the viewer in unit direction wo (direction -wo)."""
    return Ray(wo, Vec3(-wo.e0, -wo.e1, -wo.e2))


def light_ray(wi: Vec3) -> Ray:
    """The ray leaving the origin toward the light in unit direction wi."""
    return Ray(ORIGIN, wi)


def incident_ray(theta_deg: float, phi_deg: float = 0.0) -> Ray:
    """The incoming ray of the test setup: direction -(sin t cos p, sin t sin p, cos t)."""
    return view_ray(local_direction(theta_deg, phi_deg))


# --- statistics ------------------------------------------------------------------------------


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


def sidak_alpha(alpha: float, n_tests: int) -> float:
    """Per-test significance so that n_tests independent tests together reject a
    correct hypothesis with probability alpha: 1 - (1 - alpha)^(1/n)."""
    if not 0.0 < alpha < 1.0 or n_tests < 1:
        raise ValueError(f"need 0 < alpha < 1 and n_tests >= 1, got {alpha}, {n_tests}")
    return -math.expm1(math.log1p(-alpha) / n_tests)


def normal_quantile(alpha: float) -> float:
    """z with P(|Z| > z) = alpha for a standard normal Z (two-sided critical value)."""
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"need 0 < alpha < 1, got {alpha}")
    lo, hi = 0.0, 40.0
    for _ in range(200):  # bisection on erfc(z / sqrt 2), decreasing in z
        mid = 0.5 * (lo + hi)
        if math.erfc(mid / math.sqrt(2.0)) > alpha:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


# --- sampling the material ------------------------------------------------------------------

SCATTERED, ABSORBED, SPECULAR = 0, 1, 2


@dataclass
class Samples:
    """n draws of scattering() for one incident direction of the test setup.

    directions (n, 3), weights (n, 3) and pdfs (n,) are NaN where status is not
    SCATTERED; status is SCATTERED, ABSORBED (scattering returned None) or
    SPECULAR (a delta bounce, ScatterInfo.is_specular).
    """

    incident_deg: float
    phi_deg: float
    directions: np.ndarray
    weights: np.ndarray
    pdfs: np.ndarray
    status: np.ndarray
    seconds: float

    @property
    def n(self) -> int:
        return len(self.status)

    @property
    def scattered(self) -> np.ndarray:
        return self.status == SCATTERED


def _sampling_generator(seed: int, tag: int, incident_deg: float, phi_deg: float):
    return make_generator(seed, tag, round(incident_deg * 1e6), round(phi_deg * 1e6))


def draw_samples(
    material: Material, incident_deg: float, n: int = 100_000, seed: int = 0, phi_deg: float = 0.0
) -> Samples:
    """Call material.scattering() n times for the incoming ray of the test setup,
    under a generator fixed by (seed, incident angle, phi)."""
    ray_in = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material)
    nan = math.nan
    none_row = (nan, nan, nan, nan, nan, nan, nan)
    rows, status = [], []
    scatter = material.scattering
    start = time.perf_counter()
    with use_generator(_sampling_generator(seed, _SAMPLING, incident_deg, phi_deg)):
        for _ in range(n):
            s = scatter(ray_in, hit)
            if s is None:
                rows.append(none_row)
                status.append(ABSORBED)
            elif s.is_specular:
                rows.append(none_row)
                status.append(SPECULAR)
            else:
                d, a = s.scattered_ray.direction, s.attenuation
                rows.append((d.e0, d.e1, d.e2, a.e0, a.e1, a.e2, s.pdf))
                status.append(SCATTERED)
    seconds = time.perf_counter() - start
    table = np.array(rows, dtype=float).reshape(n, 7)
    return Samples(
        incident_deg,
        phi_deg,
        table[:, 0:3],
        table[:, 3:6],
        table[:, 6],
        np.array(status, dtype=np.int8),
        seconds,
    )


def _get_samples(material, incident_deg, n, seed, phi_deg, samples) -> Samples:
    if samples is None:
        return draw_samples(material, incident_deg, n, seed, phi_deg)
    if samples.incident_deg != incident_deg or samples.phi_deg != phi_deg:
        raise ValueError("the samples were drawn for another incident direction")
    return samples


# --- adaptive quadrature on the sphere -------------------------------------------------------

# Simpson weights on 3 nodes (0, 2, 4) and of the composite rule on 5 nodes (0..4)
# of an interval of length 1.
_S3 = (1 / 6, 0.0, 4 / 6, 0.0, 1 / 6)
_S5 = (1 / 12, 4 / 12, 2 / 12, 4 / 12, 1 / 12)


class AdaptiveSimpson2D:
    """Adaptive tensor-product Simpson quadrature over the cells of a grid.

    f(x, y) returns a tuple of k floats. The grid is given by its edges; cell
    (i, j) is [x_edges[i], x_edges[i+1]] x [y_edges[j], y_edges[j+1]]. A cell is
    integrated with the composite Simpson rule on 5 x 5 nodes (S55). Replacing
    it by the plain rule on 3 nodes in x (S35) or in y (S53) estimates the error
    along each axis: e_x = |S55 - S35| / 15, e_y = |S55 - S53| / 15 (Simpson's
    error falls 16-fold when the step halves). When e_x + e_y exceeds the
    tolerance, the cell is halved along the axes that carry the error, and the
    halves are integrated with the tolerance shared among them, down to
    max_depth halvings per axis and until f has been evaluated max_evaluations
    times (then cells are accepted as they are; the error estimate says so).
    Splitting per axis matters near the poles of (theta, phi) coordinates, where
    cells are thin wedges, and for lobes that are narrow in one direction only
    (a microfacet lobe at grazing incidence).

    The tolerance of a cell with result S is max(abs_tol, rel_tol * S,
    sqrt_tol * sqrt(S)) for the largest component: the chi-square test needs
    the error of an expected count E below a fraction of sqrt(E), its noise.
    Node values are cached, so neighbouring cells and halves share them.
    """

    split_share = 0.25  # halve along an axis that carries this share of the error

    def __init__(
        self,
        f: Callable[[float, float], tuple[float, ...]],
        x_edges: Sequence[float],
        y_edges: Sequence[float],
        max_depth: int = 16,
        max_evaluations: int = 1_000_000,
    ) -> None:
        self.f = f
        self.x_edges = list(x_edges)
        self.y_edges = list(y_edges)
        self.max_depth = max_depth
        self.max_evaluations = max_evaluations
        self.res = 4 << max_depth  # node positions per cell side at the finest level
        self.cache: dict[tuple[int, int, int, int], tuple[float, ...]] = {}

    @property
    def evaluations(self) -> int:
        return len(self.cache)

    def _value(self, i: int, a: int, j: int, b: int) -> tuple[float, ...]:
        res = self.res
        if a == res:  # the same node as the first of the next cell
            i, a = i + 1, 0
        if b == res:
            j, b = j + 1, 0
        key = (i, a, j, b)
        v = self.cache.get(key)
        if v is None:
            xe, ye = self.x_edges, self.y_edges
            x = xe[i] if a == 0 else xe[i] + (xe[i + 1] - xe[i]) * (a / res)
            y = ye[j] if b == 0 else ye[j] + (ye[j + 1] - ye[j]) * (b / res)
            v = self.cache[key] = tuple(self.f(x, y))
        return v

    def cell(
        self,
        i: int,
        j: int,
        abs_tol: float,
        rel_tol: float = 0.0,
        sqrt_tol: float = 0.0,
        points: tuple[np.ndarray, np.ndarray] | None = None,
        spacing: tuple[float, float] = (0.0, 0.0),
    ) -> tuple[list[float], float]:
        """(integral per component, estimated absolute error) over cell (i, j).

        points (x and y coordinates) and spacing (hx, hy) force refinement: every
        part of the cell that holds one of the points is split until its nodes
        are at most hx apart in x and hy apart in y, whatever the error estimate
        says. chi2_test passes the samples of a bin this way, so that a lobe
        narrower than the node spacing cannot hide between the nodes.
        """
        xe, ye = self.x_edges, self.y_edges
        width, height = xe[i + 1] - xe[i], ye[j + 1] - ye[j]
        if points is not None:  # to coordinates relative to the cell, in [0, 1]
            points = ((points[0] - xe[i]) / width, (points[1] - ye[j]) / height)
            if len(points[0]) == 0:
                points = None
        tols = (abs_tol, rel_tol, sqrt_tol, spacing[0] / width, spacing[1] / height)
        return self._integrate(i, j, 0, 0, 0, 0, width * height, tols, points)

    def _integrate(self, i, j, a0, b0, dx, dy, area, tols, points):
        abs_tol, rel_tol, sqrt_tol, hx, hy = tols  # hx, hy relative to the cell
        res = self.res
        sa, sb = (res >> dx) // 4, (res >> dy) // 4
        v = [[self._value(i, a0 + p * sa, j, b0 + q * sb) for q in range(5)] for p in range(5)]
        s55, s35, s53 = [], [], []
        for c in range(len(v[0][0])):
            rows = [[v[p][q][c] for q in range(5)] for p in range(5)]
            fine_y = [sum(w * x for w, x in zip(_S5, row, strict=True)) for row in rows]
            coarse_y = [sum(w * x for w, x in zip(_S3, row, strict=True)) for row in rows]
            s55.append(area * sum(w * x for w, x in zip(_S5, fine_y, strict=True)))
            s35.append(area * sum(w * x for w, x in zip(_S3, fine_y, strict=True)))
            s53.append(area * sum(w * x for w, x in zip(_S5, coarse_y, strict=True)))
        ex = max(abs(p - q) for p, q in zip(s55, s35, strict=True)) / 15.0
        ey = max(abs(p - q) for p, q in zip(s55, s53, strict=True)) / 15.0
        big = max(abs(x) for x in s55)
        tol = max(abs_tol, rel_tol * big, sqrt_tol * math.sqrt(big))
        force_x = points is not None and sa / res > hx
        force_y = points is not None and sb / res > hy
        split_x = dx < self.max_depth and (force_x or ex >= self.split_share * (ex + ey) > 0.0)
        split_y = dy < self.max_depth and (force_y or ey >= self.split_share * (ex + ey) > 0.0)
        converged = ex + ey <= tol and not (force_x or force_y)
        exhausted = len(self.cache) >= self.max_evaluations
        if converged or exhausted or not (split_x or split_y):
            # Accept, with Richardson's correction of S55's error along each axis
            # (unless it would make a non-negative integrand's integral negative).
            better = [(17.0 * p - q - r) / 15.0 for p, q, r in zip(s55, s35, s53, strict=True)]
            return (better if min(better) >= 0.0 or min(s55) < 0.0 else s55), ex + ey
        xs = (a0, a0 + 2 * sa) if split_x else (a0,)
        ys = (b0, b0 + 2 * sb) if split_y else (b0,)
        parts = len(xs) * len(ys)
        child_tols = (abs_tol / parts, rel_tol, sqrt_tol, hx, hy)
        ndx, ndy = dx + split_x, dy + split_y
        total, error = [0.0] * len(s55), 0.0
        for a in xs:
            for b in ys:
                inside = None
                if points is not None:
                    px, py = points
                    mask = (px >= a / res) & (px <= (a + 2 * sa * (1 + (not split_x))) / res)
                    mask &= (py >= b / res) & (py <= (b + 2 * sb * (1 + (not split_y))) / res)
                    if mask.any():
                        inside = (px[mask], py[mask])
                part, e = self._integrate(i, j, a, b, ndx, ndy, area / parts, child_tols, inside)
                total = [t + x for t, x in zip(total, part, strict=True)]
                error += e
        return total, error


def _subdivide(edges: Sequence[float], max_width: float) -> tuple[list[float], list[int]]:
    """Split every interval of `edges` into equal parts no wider than max_width.
    Returns the new edges and, for every new interval, the index of the old one."""
    new_edges, owner = [edges[0]], []
    for k in range(len(edges) - 1):
        lo, hi = edges[k], edges[k + 1]
        m = max(1, math.ceil((hi - lo) / max_width - 1e-9))
        for s in range(1, m + 1):
            new_edges.append(hi if s == m else lo + (hi - lo) * s / m)
            owner.append(k)
    return new_edges, owner


# --- chi-square test -------------------------------------------------------------------------

# How far above 1 the quadrature of a correct pdf() may come (on top of 10 times
# its own error estimate): the quadrature of narrow lobes is good to ~2e-6.
PDF_INTEGRAL_SLACK = 2e-5


@dataclass
class Chi2Result:
    """The outcome of chi2_test.

    observed / expected: counts per bin, shape (theta_bins, phi_bins); bin (i, j)
    covers cos(theta) in [1 - 2(i+1)/theta_bins, 1 - 2i/theta_bins] (row 0 at the
    normal) and phi in [2 pi j, 2 pi (j+1)] / phi_bins.
    pdf_integral: integral of pdf() over the whole sphere; upper_integral: over
    the upper hemisphere. n_absorbed counts None returns (and specular samples,
    n_specular of them, which have no density either); expected_absorbed is
    n_samples * (1 - pdf_integral), at least 0.
    message: why the test failed outright (p = 0), else "".
    note: a warning when the quadrature of pdf() did not reach its tolerance.
    """

    p_value: float
    statistic: float
    dof: int
    n_samples: int
    n_absorbed: int
    n_specular: int
    expected_absorbed: float
    pdf_integral: float
    upper_integral: float
    integration_error: float
    pdf_evaluations: int
    n_categories: int
    observed: np.ndarray = field(repr=False)
    expected: np.ndarray = field(repr=False)
    worst: str = ""
    message: str = ""
    note: str = ""
    seconds: float = 0.0

    def passed(self, alpha: float = 0.01) -> bool:
        return self.p_value >= alpha

    def summary(self, worst: bool = True) -> str:
        """One line: the statistic, the absorbed samples, and (worst=True) the bin
        that deviates most or the reason the test failed outright."""
        text = (
            f"chi2 {self.statistic:.1f}, dof {self.dof}; absorbed {self.n_absorbed} of "
            f"{self.n_samples} (expected {self.expected_absorbed:.1f})"
        )
        if self.message:
            return self.message + "; " + text
        if self.note:
            text += "; " + self.note
        if worst and self.worst:
            text += "; " + self.worst
        return text


def _bin_label(i: int, j: int, theta_bins: int, phi_bins: int) -> str:
    t0 = math.degrees(math.acos(1.0 - 2.0 * i / theta_bins))
    t1 = math.degrees(math.acos(max(-1.0, 1.0 - 2.0 * (i + 1) / theta_bins)))
    p0, p1 = 360.0 * j / phi_bins, 360.0 * (j + 1) / phi_bins
    return f"theta {t0:.1f}-{t1:.1f}, phi {p0:.1f}-{p1:.1f} deg"


def chi2_test(
    material: Material,
    incident_deg: float,
    n_samples: int = 100_000,
    theta_bins: int = 24,
    phi_bins: int = 48,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    node_spacing: float = 0.035,
    min_expected: float = 5.0,
) -> Chi2Result:
    """Pearson's chi-square test of scattering() against pdf().

    The directions of n_samples draws are binned on the sphere, equal-area bins
    in (cos theta, phi): theta_bins (even, so the horizon is a bin edge) by
    phi_bins. pdf() is integrated over every bin with adaptive Simpson
    quadrature in (theta, phi) (solid angle sin(theta) dtheta dphi), starting
    from nodes at most node_spacing radians apart. Bins expecting fewer than
    min_expected samples are pooled; the absorbed samples form one more
    category. A sample in a bin where pdf() integrates to 0 fails the test
    outright (p = 0), as does a pdf() value that is negative or not finite, or
    a pdf() whose integral over the sphere exceeds 1 by more than the
    quadrature's uncertainty.
    """
    if theta_bins < 2 or theta_bins % 2 or phi_bins < 1:
        raise ValueError("theta_bins must be even and >= 2, phi_bins >= 1")
    if material.is_specular:
        raise ValueError("a specular (delta) material has no density to test")
    start = time.perf_counter()
    samples = _get_samples(material, incident_deg, n_samples, seed, phi_deg, samples)
    n = samples.n
    ok = samples.scattered
    n_absorbed = int(np.count_nonzero(samples.status == ABSORBED))
    n_specular = int(np.count_nonzero(samples.status == SPECULAR))

    # Histogram of the scattered directions.
    d = samples.directions[ok]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    with np.errstate(invalid="ignore", divide="ignore"):
        z = np.clip(d[:, 2] / length, -1.0, 1.0)
    phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
    bad = ~np.isfinite(z) | ~np.isfinite(phi)
    ti = np.clip(np.floor((1.0 - z[~bad]) * 0.5 * theta_bins).astype(int), 0, theta_bins - 1)
    pj = np.clip(np.floor(phi[~bad] / TWO_PI * phi_bins).astype(int), 0, phi_bins - 1)
    observed = np.zeros((theta_bins, phi_bins))
    np.add.at(observed, (ti, pj), 1.0)

    # Integral of pdf over every bin, with theta-strips and phi-cells no wider than
    # 4 node spacings (5 Simpson nodes each).
    ray_view = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material)
    bad_values: list[str] = []
    horizon = 0.5 * math.pi

    def pdf_sin(theta: float, ph: float, upper: bool) -> tuple[float]:
        """pdf * sin(theta), the density per dtheta dphi. On the horizon the value is
        the limit from the hemisphere being integrated: pdf() jumps there."""
        if theta == horizon:
            theta = horizon - 1e-9 if upper else horizon + 1e-9
        s = math.sin(theta)
        if s <= 0.0 or theta >= math.pi:  # the poles: zero solid angle
            return (0.0,)
        wi = Vec3(s * math.cos(ph), s * math.sin(ph), math.cos(theta))
        p = material.pdf(ray_view, Ray(ORIGIN, wi), hit)
        if not (p >= 0.0 and math.isfinite(p)):
            if len(bad_values) < 3:
                bad_values.append(f"pdf() = {p!r} at wi = {_vec(wi.tolist())}")
            return (0.0,)
        return (p * s,)

    # Bins are split into cells at most 4 node spacings wide (5 Simpson nodes each);
    # each hemisphere has its own integrator, so no cell straddles the horizon.
    half = theta_bins // 2
    theta_edges = [math.acos(1.0 - 2.0 * i / theta_bins) for i in range(theta_bins)] + [math.pi]
    theta_edges[half] = horizon
    phi_edges = [TWO_PI * j / phi_bins for j in range(phi_bins + 1)]
    cell_width = 4.0 * node_spacing
    y_edges, y_owner = _subdivide(phi_edges, cell_width)
    sectors = [[c for c, o in enumerate(y_owner) if o == bj] for bj in range(phi_bins)]
    quads, strips = [], []
    for upper, edges in ((True, theta_edges[: half + 1]), (False, theta_edges[half:])):
        x_edges, x_owner = _subdivide(edges, cell_width)
        quads.append(
            AdaptiveSimpson2D(
                lambda t, p, u=upper: pdf_sin(t, p, u), x_edges, y_edges, max_evaluations=300_000
            )
        )
        strips.append([[c for c, o in enumerate(x_owner) if o == b] for b in range(half)])
    # Tolerance per cell, in probability: 0.01 * sqrt(expected count) / n, at least
    # 0.01 / n (see AdaptiveSimpson2D); the chi2 statistic moves by < 1e-4 per bin.
    abs_tol, sqrt_tol = 0.01 / n, 0.01 / math.sqrt(n)

    guides: dict[tuple[int, int], tuple] = {}  # bin -> (samples' theta, phi, spacing)

    def integrate_bin(bi: int, bj: int, tol_scale: float = 1.0) -> tuple[float, float]:
        hemisphere, row = divmod(bi, half)
        quad = quads[hemisphere]
        guide = guides.get((bi, bj))
        total, error = 0.0, 0.0
        for ci in strips[hemisphere][row]:
            for cj in sectors[bj]:
                points, spacing = None, (0.0, 0.0)
                if guide is not None:
                    t, p, spacing = guide
                    x0, x1 = quad.x_edges[ci], quad.x_edges[ci + 1]
                    y0, y1 = y_edges[cj], y_edges[cj + 1]
                    inside = (t >= x0) & (t <= x1) & (p >= y0) & (p <= y1)
                    points = (t[inside], p[inside])
                value, e = quad.cell(
                    ci, cj, abs_tol * tol_scale, 0.0, sqrt_tol * tol_scale, points, spacing
                )
                total += value[0]
                error += e
        return total, error

    integral = np.zeros((theta_bins, phi_bins))
    errors = np.zeros((theta_bins, phi_bins))
    for bi in range(theta_bins):
        for bj in range(phi_bins):
            integral[bi, bj], errors[bi, bj] = integrate_bin(bi, bj)

    # A lobe narrower than the node spacing can hide between the nodes. Where a bin
    # holds many more samples than its integral predicts, integrate it again with
    # nodes at most a third of the samples' spread apart wherever there are samples
    # (and 100 times smaller tolerances), before blaming the material.
    excess = (observed - n * integral) / np.sqrt(n * integral + 1.0)
    suspects = np.argwhere(excess > 5.0)
    if len(suspects):
        theta_s = np.arccos(z[~bad])
        phi_s = phi[~bad]
        order = np.argsort(-excess[suspects[:, 0], suspects[:, 1]])
        for bi, bj in suspects[order[:64]]:
            mine = (ti == bi) & (pj == bj)
            t, p = theta_s[mine], phi_s[mine]
            spread = (max(float(np.std(t)), 1e-6) / 3.0, max(float(np.std(p)), 1e-6) / 3.0)
            guides[bi, bj] = (t, p, spread)
            integral[bi, bj], errors[bi, bj] = integrate_bin(bi, bj, 0.01)

    # The absorbed category's expected count n * (1 - sum of integrals) collects the
    # errors of all bins. Refine the bins with the largest errors until the total
    # error is below 0.2 samples (or after 3 rounds).
    scale = 1.0
    for _ in range(3):
        if n * errors.sum() <= 0.2:
            break
        scale *= 0.1
        share = errors / errors.sum()
        for bi, bj in np.argwhere(share > 0.2 / share.size):
            integral[bi, bj], errors[bi, bj] = integrate_bin(bi, bj, scale)

    expected = n * integral
    pdf_integral = float(integral.sum())
    upper_integral = float(integral[: theta_bins // 2].sum())
    expected_absorbed = max(0.0, n * (1.0 - pdf_integral))
    observed_absorbed = float(n_absorbed + n_specular)

    message = ""
    # A density integrates to at most 1 over the sphere (less where scattering()
    # absorbs). Pearson's statistic alone barely sees a pdf() a little too large
    # everywhere, so that is a failure of its own.
    excess_allowed = PDF_INTEGRAL_SLACK + 10.0 * float(errors.sum())
    if bad_values:
        message = "pdf() is negative or not finite: " + "; ".join(bad_values)
    elif pdf_integral > 1.0 + excess_allowed:
        message = (
            f"pdf() integrates to {pdf_integral:.6f} over the sphere, more than 1 "
            f"(+ {excess_allowed:.1e} quadrature allowance): it is not normalised"
        )
    elif np.count_nonzero(bad):
        message = f"{int(np.count_nonzero(bad))} scattered directions are not finite"
    else:
        empty = (observed > 0) & (integral <= 0.0)
        if empty.any():
            bi, bj = np.argwhere(empty)[0]
            message = (
                f"{int(observed[empty].sum())} samples where pdf() is 0, e.g. "
                f"{int(observed[bi, bj])} at {_bin_label(bi, bj, theta_bins, phi_bins)}"
            )

    # Pearson's statistic over the bins and the absorbed category, small ones pooled.
    # The absorbed category's expected count carries the quadrature error of the
    # whole sphere, usually far below a sample; where it is not, its term is divided
    # by E + error^2 instead of E, so that the quadrature cannot fail the material.
    uncertainty = n * float(errors.sum())
    obs = np.append(observed.ravel(), observed_absorbed)
    exp = np.append(expected.ravel(), expected_absorbed)
    var = exp.copy()
    var[-1] += uncertainty**2
    small = exp < min_expected
    o, e, v = list(obs[~small]), list(exp[~small]), list(var[~small])
    pooled = (float(obs[small].sum()), float(exp[small].sum()), float(var[small].sum()))
    if pooled[1] >= min_expected or not e:
        if pooled[0] > 0.0 or pooled[1] > 0.0:
            o.append(pooled[0])
            e.append(pooled[1])
            v.append(pooled[2])
    elif pooled[0] > 0.0 or pooled[1] > 0.0:  # too small on its own: join the smallest
        k = int(np.argmin(e))
        o[k] += pooled[0]
        e[k] += pooled[1]
        v[k] += pooled[2]
    o, e, v = np.array(o), np.array(e), np.array(v)
    with np.errstate(divide="ignore", invalid="ignore"):
        contributions = np.where(v > 0.0, (o - e) ** 2 / v, np.where(o > 0.0, np.inf, 0.0))
    statistic = float(contributions.sum())
    dof = len(o) - 1
    if message:
        p_value = 0.0
    elif dof < 1:
        p_value = 1.0
        message = "too few samples for a test (all bins pooled into one)"
    else:
        p_value = chi2_sf(statistic, dof)

    worst = ""
    with np.errstate(divide="ignore", invalid="ignore"):
        per_bin = np.where(expected >= min_expected, (observed - expected) ** 2 / expected, 0.0)
    if per_bin.max() > 0.0:
        bi, bj = np.unravel_index(int(np.argmax(per_bin)), per_bin.shape)
        worst = (
            f"worst bin {_bin_label(bi, bj, theta_bins, phi_bins)}: "
            f"{int(observed[bi, bj])} samples, expected {expected[bi, bj]:.1f}"
        )
    if expected_absorbed >= min_expected or observed_absorbed >= min_expected:
        z_abs = abs(observed_absorbed - expected_absorbed) / math.sqrt(expected_absorbed + 1.0)
        if z_abs > 3.0:
            worst = (
                f"absorbed {int(observed_absorbed)} samples but pdf() integrates to "
                f"{pdf_integral:.6f}, which predicts {expected_absorbed:.1f}"
            )

    return Chi2Result(
        p_value=p_value,
        statistic=statistic,
        dof=dof,
        n_samples=n,
        n_absorbed=n_absorbed,
        n_specular=n_specular,
        expected_absorbed=expected_absorbed,
        pdf_integral=pdf_integral,
        upper_integral=upper_integral,
        integration_error=float(errors.sum()),
        pdf_evaluations=sum(q.evaluations for q in quads),
        n_categories=len(o),
        observed=observed,
        expected=expected,
        worst=worst,
        message=message,
        note=f"quadrature of pdf() uncertain by {uncertainty:.1f} samples"
        if uncertainty > 1.0
        else "",
        seconds=time.perf_counter() - start,
    )


# --- deterministic checks --------------------------------------------------------------------


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


def _close(a: float, b: float, rel_tol: float) -> bool:
    """Equal to rel_tol, or both below 1e-3 * rel_tol (1e-12 for rel_tol = 1e-9)."""
    return math.isclose(a, b, rel_tol=rel_tol, abs_tol=1e-3 * rel_tol)


def _vec(v: Sequence[float]) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in v) + ")"


def _fmt(v: Sequence[float], spec: str = ".6g") -> str:
    """(x, y, z); a grey colour (three equal numbers) as one number."""
    v = tuple(v)
    if len(v) == 3 and v[0] == v[1] == v[2]:
        return format(v[0], spec)
    return "(" + ", ".join(format(x, spec) for x in v) + ")"


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
    samples = _get_samples(material, incident_deg, n, seed, phi_deg, samples)
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
        elif not _close(float(samples.pdfs[k]), pdf, rel_tol):
            problem = f"ScatterInfo.pdf = {samples.pdfs[k]:.9g} but pdf() = {pdf:.9g}"
        elif not pdf > 0.0:
            problem = f"pdf() = {pdf!r} for a direction scattering() returned"
        else:
            expect = [c * abs(z) / pdf for c in (f.e0, f.e1, f.e2)]
            if not all(_close(a, b, rel_tol) for a, b in zip(weight, expect, strict=True)):
                problem = f"attenuation {_fmt(weight)} but BRDF * cos / pdf = {_fmt(expect)}"
        if problem:
            failures += 1
            if not first:
                theta = math.degrees(math.acos(max(-1.0, min(1.0, z / length))))
                first = f"e.g. wi = {_vec((x, y, z))} (theta {theta:.2f} deg): {problem}"
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
    samples = _get_samples(material, incident_deg, n_samples, seed, phi_deg, samples)
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
    x_edges, _ = _subdivide([0.0, 0.5 * math.pi], cell)
    total, error, evaluations = [0.0, 0.0, 0.0], 0.0, 0
    for lo, hi in zip(x_edges[:-1], x_edges[1:], strict=True):
        y_edges, _ = _subdivide([0.0, TWO_PI], min(0.5 * math.pi, cell / math.sin(hi)))
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
                    guide = (
                        max(float(np.std(t_in)), 1e-6) / 3.0,
                        max(float(np.std(p_in)), 1e-6) / 3.0,
                    )
                    quad.max_evaluations = quad.evaluations + 1_000_000
                    value, e = quad.cell(0, j, abs_tol, 1e-6, points=(t_in, p_in), spacing=guide)
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
        f"albedo {_fmt(a.sampled)} +- {_fmt(a.standard_error, '.2g')} sampled, "
        f"{_fmt(a.quadrature)} by quadrature"
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
    with use_generator(make_generator(seed, _RECIPROCITY)):
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
            if not all(_close(p, q, rel_tol) for p, q in zip(x, y, strict=True)):
                failures += 1
                if not first:
                    first = (
                        f"e.g. wo = {_vec(a.tolist())}, wi = {_vec(b.tolist())}: "
                        f"BRDF {_fmt(x)}, swapped {_fmt(y)}"
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
                        f"incident {theta:g} deg, wi {_vec(wi.tolist())}: BRDF {_fmt(f)}, pdf {p!r}"
                    )
            with use_generator(_sampling_generator(seed, _NON_NEGATIVE, theta, phi)):
                for _ in range(n):
                    s = material.scattering(ray_in, hit)
                    if s is None:
                        continue
                    d = s.scattered_ray.direction
                    if bad_color(s.attenuation) or bad_number(s.pdf):
                        problems.append(
                            f"incident {theta:g} deg: sample weight {_fmt(s.attenuation)}, "
                            f"pdf {s.pdf!r}"
                        )
                    elif not all(math.isfinite(x) for x in (d.e0, d.e1, d.e2)):
                        problems.append(f"incident {theta:g} deg: direction {_vec(d)}")
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


# --- everything at once ----------------------------------------------------------------------


def material_name(material: Material) -> str:
    """ClassName(parameter=value, ...) from the material's simple attributes."""
    parts = []
    for key, value in getattr(material, "__dict__", {}).items():
        if key.startswith("_"):
            continue
        if isinstance(value, bool | int | float | str):
            parts.append(f"{key}={value:g}" if isinstance(value, float) else f"{key}={value!r}")
        elif isinstance(value, Vec3):
            parts.append(f"{key}={_fmt(value)}")
        elif isinstance(value, Texture) and hasattr(value, "color"):
            parts.append(f"{key}={_fmt(value.color)}")
    return f"{type(material).__name__}({', '.join(parts)})"


@dataclass
class MaterialReport:
    """All checks of check_material; `passed` is True when every check passed."""

    material: str
    checks: list[CheckResult]
    alpha: float
    seconds: float = 0.0

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def failures(self) -> list[CheckResult]:
        return [c for c in self.checks if not c.passed]

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        n_fail = len(self.failures)
        verdict = "PASSED" if self.passed else f"FAILED ({n_fail} of {len(self.checks)} checks)"
        lines = [
            f"{self.material}: {verdict}",
            f"{'check':<12} {'angle':>6}  {'result':<7} {'p-value':<9} details",
        ]
        for c in self.checks:
            angle = "all" if c.incident_deg is None else f"{c.incident_deg:g}"
            result = "skipped" if c.skipped else ("pass" if c.passed else "FAIL")
            p = "-" if c.p_value is None else f"{c.p_value:.3g}"
            lines.append(f"{c.check:<12} {angle:>6}  {result:<7} {p:<9} {c.detail}")
        if not self.passed:
            lines.append(_hints(self.failures))
        lines.append(
            f"(chi2 tests reject at p < {self.alpha:.3g} each: alpha Sidak-corrected over "
            f"the incident angles; {self.seconds:.1f} s)"
        )
        return "\n".join(lines)


_HINTS = {
    "chi2": "chi2: scattering() does not draw directions with the density pdf() returns "
    "(compare the sampling formula with pdf(), its normalisation and its frame).",
    "weights": "weights: the attenuation must be BRDF * cos / pdf for the sampled direction.",
    "energy": "energy: the mean weight and the integral of BRDF * cos disagree, or exceed 1 "
    "(check the BRDF's normalisation, and that sampling covers every direction "
    "where the BRDF is not 0).",
    "reciprocity": "reciprocity: BRDF(wo, wi) must equal BRDF(wi, wo).",
    "finite >= 0": "finite >= 0: guard divisions by cosines that reach 0 at grazing angles.",
}


def _hints(failures: list[CheckResult]) -> str:
    seen = dict.fromkeys(c.check for c in failures)
    return "\n".join("hint: " + _HINTS[name] for name in seen if name in _HINTS)


def _run(check: str, incident_deg: float | None, fn: Callable[[], CheckResult]) -> CheckResult:
    try:
        return fn()
    except Exception as error:  # a crash is a failed check, reported like the others
        return CheckResult(check, incident_deg, False, f"raised {type(error).__name__}: {error}")


def check_material(
    material: Material,
    incident_angles: Sequence[float] = (0.0, 30.0, 60.0, 85.0, 89.9),
    n_samples: int = 100_000,
    alpha: float = 0.01,
    reciprocal: bool = True,
    seed: int = 0,
    max_albedo: float | None = 1.0,
    theta_bins: int = 24,
    phi_bins: int = 48,
) -> MaterialReport:
    """Run every check on `material` and return a MaterialReport (print it).

    Per incident angle: chi2_test, check_weights, check_energy (its <= max_albedo
    part skipped when max_albedo is None); once: check_reciprocity (when
    `reciprocal`) and check_non_negative_finite. The chi2 and energy tests use
    the per-test significance sidak_alpha(alpha, number of angles). One set of
    n_samples draws per angle serves the chi2, weights and energy checks.
    """
    start = time.perf_counter()
    angles = [float(t) for t in incident_angles]
    a = sidak_alpha(alpha, max(1, len(angles)))
    checks: list[CheckResult] = []
    specular = material.is_specular
    for theta in angles:
        if specular:
            checks.append(
                CheckResult("chi2", theta, True, "specular material: no density", skipped=True)
            )
            continue
        try:
            samples = draw_samples(material, theta, n_samples, seed)
        except Exception as error:
            checks.append(
                CheckResult("scattering", theta, False, f"raised {type(error).__name__}: {error}")
            )
            continue

        def chi2(theta=theta, samples=samples) -> CheckResult:
            r = chi2_test(
                material, theta, samples=samples, theta_bins=theta_bins, phi_bins=phi_bins
            )
            ok = r.passed(a)
            return CheckResult("chi2", theta, ok, r.summary(worst=not ok), p_value=r.p_value)

        checks.append(_run("chi2", theta, chi2))
        checks.append(
            _run("weights", theta, lambda t=theta, s=samples: check_weights(material, t, samples=s))
        )
        checks.append(
            _run(
                "energy",
                theta,
                lambda t=theta, s=samples: check_energy(
                    material,
                    t,
                    alpha=a,
                    max_albedo=math.inf if max_albedo is None else max_albedo,
                    samples=s,
                ),
            )
        )
    if reciprocal and not specular:
        checks.append(_run("reciprocity", None, lambda: check_reciprocity(material, seed=seed)))
    checks.append(_run("finite >= 0", None, lambda: check_non_negative_finite(material, seed=seed)))
    return MaterialReport(material_name(material), checks, a, time.perf_counter() - start)


def assert_material(material: Material, **options) -> MaterialReport:
    """check_material, raising AssertionError with the report's table when a check fails."""
    report = check_material(material, **options)
    if not report.passed:
        raise AssertionError("\n" + str(report))
    return report
