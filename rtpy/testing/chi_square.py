"""Pearson's chi-square test of a material's scattering() against its pdf().

Are the directions scattering() draws distributed with density pdf()? The
directions of many draws are binned on the sphere, pdf() is integrated over
every bin, and Pearson's statistic compares the counts. Absorbed samples
(scattering() returns None) count as one more category, whose expected count
is N * (1 - integral of pdf over the sphere). The test follows Mitsuba 3's
chi2 test and pbrt-v4's bsdfs_test.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from ..materials.material import Material
from .local_setup import (
    ABSORBED,
    SPECULAR,
    TWO_PI,
    Samples,
    get_samples,
    local_direction,
    vector_text,
)
from .quadrature import AdaptiveSimpson2D, CellRequest, integrate_cells, sample_spacing, subdivide
from .statistics import chi2_sf
from .subject import MaterialSubject, as_subject

__all__ = ["PDF_INTEGRAL_SLACK", "Chi2Result", "chi2_test"]

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


# --- the histogram ---------------------------------------------------------------------------


@dataclass
class _Histogram:
    """Where the scattered samples went: counts per bin, equal-area bins in
    (cos theta, phi), and each finite direction's angles and bin."""

    observed: np.ndarray  # (theta_bins, phi_bins)
    theta: np.ndarray  # polar angle of each finite direction
    phi: np.ndarray  # its azimuth in [0, 2 pi)
    row: np.ndarray  # its bin
    column: np.ndarray
    not_finite: int  # directions with a NaN or infinite component

    def samples_in(self, bi: int, bj: int) -> tuple[np.ndarray, np.ndarray]:
        mine = (self.row == bi) & (self.column == bj)
        return self.theta[mine], self.phi[mine]


def _histogram(samples: Samples, theta_bins: int, phi_bins: int) -> _Histogram:
    d = samples.directions[samples.scattered]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    with np.errstate(invalid="ignore", divide="ignore"):
        z = np.clip(d[:, 2] / length, -1.0, 1.0)
    phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
    ok = np.isfinite(z) & np.isfinite(phi)
    z, phi = z[ok], phi[ok]
    row = np.clip(np.floor((1.0 - z) * 0.5 * theta_bins).astype(int), 0, theta_bins - 1)
    column = np.clip(np.floor(phi / TWO_PI * phi_bins).astype(int), 0, phi_bins - 1)
    observed = np.zeros((theta_bins, phi_bins))
    np.add.at(observed, (row, column), 1.0)
    return _Histogram(observed, np.arccos(z), phi, row, column, int(np.count_nonzero(~ok)))


# --- the integral of pdf() over every bin ----------------------------------------------------


class _BinIntegrals:
    """Adaptive Simpson quadrature of pdf() over the bins, in (theta, phi) with the
    solid angle sin(theta) dtheta dphi. Bins are split into cells at most 4 node
    spacings wide (5 Simpson nodes each); each hemisphere has its own integrator,
    so no cell straddles the horizon, where pdf() jumps. The tolerance per cell,
    in probability, is 0.01 * sqrt(expected count) / n, at least 0.01 / n: the
    chi2 statistic moves by < 1e-4 per bin. All the bins of a pass are integrated
    together, so the subject is asked for pdf() once per round of refinement."""

    def __init__(
        self, subject: MaterialSubject, samples: Samples, shape: tuple[int, int], spacing: float
    ) -> None:
        theta_bins, phi_bins = shape
        n = samples.n
        self.subject = subject
        self.wo = np.array(local_direction(samples.incident_deg, samples.phi_deg).tolist())
        self.inside = samples.inside
        self.half = half = theta_bins // 2
        self.bad_values: list[str] = []
        self.guides: dict[tuple[int, int], tuple] = {}  # bin -> (samples' theta, phi, spacing)
        self.abs_tol, self.sqrt_tol = 0.01 / n, 0.01 / math.sqrt(n)
        theta_edges = [math.acos(1.0 - 2.0 * i / theta_bins) for i in range(theta_bins)]
        theta_edges = [*theta_edges, math.pi]
        theta_edges[half] = 0.5 * math.pi
        phi_edges = [TWO_PI * j / phi_bins for j in range(phi_bins + 1)]
        cell = 4.0 * spacing
        self.y_edges, y_owner = subdivide(phi_edges, cell)
        self.sectors = [[c for c, o in enumerate(y_owner) if o == bj] for bj in range(phi_bins)]
        self.quads, self.strips = [], []
        for upper, edges in ((True, theta_edges[: half + 1]), (False, theta_edges[half:])):
            x_edges, x_owner = subdivide(edges, cell)
            f = partial(self.pdf_sin_batch, upper=upper)
            self.quads.append(AdaptiveSimpson2D(f, x_edges, self.y_edges, max_evaluations=300_000))
            self.strips.append([[c for c, o in enumerate(x_owner) if o == b] for b in range(half)])

    @property
    def evaluations(self) -> int:
        return sum(q.evaluations for q in self.quads)

    @staticmethod
    def directions(theta: np.ndarray, phi: np.ndarray, upper: bool):
        """(unit directions toward the light, sin(theta)) at the nodes; sin = 0 at the
        poles (zero solid angle). On the horizon the direction is the limit from the
        hemisphere being integrated: pdf() jumps there."""
        rows, sines = [], []
        for t, p in zip(theta.tolist(), phi.tolist(), strict=True):
            if t == 0.5 * math.pi:
                t = 0.5 * math.pi - 1e-9 if upper else 0.5 * math.pi + 1e-9
            s = math.sin(t)
            if s <= 0.0 or t >= math.pi:
                s = 0.0
            rows.append((s * math.cos(p), s * math.sin(p), math.cos(t)))
            sines.append(s)
        return np.array(rows, dtype=float).reshape(-1, 3), np.array(sines)

    def pdf_sin(self, batches) -> list[np.ndarray]:
        """pdf * sin(theta), the density per dtheta dphi, at the nodes of every
        (integrator, theta, phi) of a round: one pdf() call for them all."""
        parts = [self.directions(x, y, quad is self.quads[0]) for quad, x, y in batches]
        wi = np.concatenate([d for d, _ in parts])
        sines = np.concatenate([s for _, s in parts])
        asked = sines > 0.0
        p = np.zeros(len(wi))
        if asked.any():
            wo = np.broadcast_to(self.wo, (int(asked.sum()), 3))
            p[asked] = np.asarray(self.subject.pdf(wo, wi[asked], inside=self.inside), float)
        bad = asked & ~(np.isfinite(p) & (p >= 0.0))
        for k in np.flatnonzero(bad)[: 3 - len(self.bad_values)]:
            self.bad_values.append(f"pdf() = {float(p[k])!r} at wi = {vector_text(wi[k])}")
        values = np.where(bad, 0.0, p * sines)[:, None]
        bounds = np.cumsum([0] + [len(x) for _, x, _ in batches])
        return [values[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    def pdf_sin_batch(self, theta: np.ndarray, phi: np.ndarray, upper: bool) -> np.ndarray:
        """pdf * sin(theta) at nodes of one hemisphere."""
        quad = self.quads[0 if upper else 1]
        return self.pdf_sin([(quad, theta, phi)])[0]

    def integrate(self, bins, tol_scale: float = 1.0) -> list[tuple[float, float]]:
        """(integral of pdf over bin (bi, bj), its estimated error) for every bin, all
        integrated together. A bin with a guide (the samples in it) has nodes at most
        the guide's spacing apart wherever there are samples."""
        jobs, owners = [], []
        abs_tol, sqrt_tol = self.abs_tol * tol_scale, self.sqrt_tol * tol_scale
        for k, (bi, bj) in enumerate(bins):
            hemisphere, row = divmod(int(bi), self.half)
            quad = self.quads[hemisphere]
            guide = self.guides.get((bi, bj))
            for ci in self.strips[hemisphere][row]:
                for cj in self.sectors[bj]:
                    points, spacing = None, (0.0, 0.0)
                    if guide is not None:
                        t, p, spacing = guide
                        x0, x1 = quad.x_edges[ci], quad.x_edges[ci + 1]
                        y0, y1 = self.y_edges[cj], self.y_edges[cj + 1]
                        inside = (t >= x0) & (t <= x1) & (p >= y0) & (p <= y1)
                        points = (t[inside], p[inside])
                    request = CellRequest(ci, cj, abs_tol, 0.0, sqrt_tol, points, spacing)
                    jobs.append((quad, request))
                    owners.append(k)
        totals = [[0.0, 0.0] for _ in bins]
        for k, (value, e) in zip(owners, integrate_cells(jobs, self.pdf_sin), strict=True):
            totals[k][0] += value[0]
            totals[k][1] += e
        return [(t, e) for t, e in totals]

    def integrate_all(self, hist: _Histogram, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(integral of pdf over every bin, its estimated error), refined where the
        samples or the error estimates ask for it."""
        integral = np.zeros(hist.observed.shape)
        errors = np.zeros(hist.observed.shape)
        self.update(list(np.ndindex(*hist.observed.shape)), integral, errors)
        self.refine_where_samples_crowd(hist, integral, errors, n)
        self.refine_largest_errors(integral, errors, n)
        return integral, errors

    def update(self, bins, integral, errors, tol_scale: float = 1.0) -> None:
        bins = [(int(bi), int(bj)) for bi, bj in bins]
        for (bi, bj), (value, e) in zip(bins, self.integrate(bins, tol_scale), strict=True):
            integral[bi, bj], errors[bi, bj] = value, e

    def refine_where_samples_crowd(self, hist: _Histogram, integral, errors, n: int) -> None:
        """A lobe narrower than the node spacing can hide between the nodes. Where a
        bin holds many more samples than its integral predicts, integrate it again
        with nodes at most a third of the samples' spread apart wherever there are
        samples (and 100 times smaller tolerances), before blaming the material."""
        excess = (hist.observed - n * integral) / np.sqrt(n * integral + 1.0)
        suspects = np.argwhere(excess > 5.0)
        order = np.argsort(-excess[suspects[:, 0], suspects[:, 1]])
        chosen = [(int(bi), int(bj)) for bi, bj in suspects[order[:64]]]
        for bi, bj in chosen:
            t, p = hist.samples_in(bi, bj)
            self.guides[bi, bj] = (t, p, sample_spacing(t, p))
        if chosen:
            self.update(chosen, integral, errors, 0.01)

    def refine_largest_errors(self, integral, errors, n: int) -> None:
        """The absorbed category's expected count n * (1 - sum of integrals) collects
        the errors of all bins: refine the bins with the largest errors until the
        total error is below 0.2 samples (or after 3 rounds)."""
        scale = 1.0
        for _ in range(3):
            if n * errors.sum() <= 0.2:
                break
            scale *= 0.1
            share = errors / errors.sum()
            self.update(np.argwhere(share > 0.2 / share.size), integral, errors, scale)


# --- the statistic ---------------------------------------------------------------------------


def _outright_failure(
    bad_values: list[str], pdf_integral: float, errors, hist: _Histogram, integral
) -> str:
    """Why the test fails whatever the statistic says, or ""."""
    # A density integrates to at most 1 over the sphere (less where scattering()
    # absorbs). Pearson's statistic alone barely sees a pdf() a little too large
    # everywhere, so that is a failure of its own.
    excess_allowed = PDF_INTEGRAL_SLACK + 10.0 * float(errors.sum())
    if bad_values:
        return "pdf() is negative or not finite: " + "; ".join(bad_values)
    if pdf_integral > 1.0 + excess_allowed:
        return (
            f"pdf() integrates to {pdf_integral:.6f} over the sphere, more than 1 "
            f"(+ {excess_allowed:.1e} quadrature allowance): it is not normalised"
        )
    if hist.not_finite:
        return f"{hist.not_finite} scattered directions are not finite"
    empty = (hist.observed > 0) & (integral <= 0.0)
    if empty.any():
        bi, bj = np.argwhere(empty)[0]
        return (
            f"{int(hist.observed[empty].sum())} samples where pdf() is 0, e.g. "
            f"{int(hist.observed[bi, bj])} at {_bin_label(bi, bj, *integral.shape)}"
        )
    return ""


def _pearson(observed, expected, absorbed, expected_absorbed, uncertainty, min_expected):
    """(statistic, number of categories) of Pearson's test over the bins and the
    absorbed category, sum (o - e)^2 / var, categories expecting fewer than
    min_expected pooled into one (joined to the smallest other category when the
    pool is still too small).

    var is e, except for the absorbed category: its expected count carries the
    quadrature error of the whole sphere (uncertainty, in samples), usually far
    below a sample; where it is not, its term is divided by e + uncertainty^2, so
    that the quadrature cannot fail the material."""
    obs = np.append(observed.ravel(), absorbed)
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
    elif pooled[0] > 0.0 or pooled[1] > 0.0:
        k = int(np.argmin(e))
        o[k] += pooled[0]
        e[k] += pooled[1]
        v[k] += pooled[2]
    o, e, v = np.array(o), np.array(e), np.array(v)
    with np.errstate(divide="ignore", invalid="ignore"):
        contributions = np.where(v > 0.0, (o - e) ** 2 / v, np.where(o > 0.0, np.inf, 0.0))
    return float(contributions.sum()), len(o)


def _worst(observed, expected, min_expected, absorbed: float, expected_absorbed, pdf_integral):
    """The bin that deviates most, or the absorbed samples when they deviate by
    more than 3 standard deviations."""
    worst = ""
    with np.errstate(divide="ignore", invalid="ignore"):
        per_bin = np.where(expected >= min_expected, (observed - expected) ** 2 / expected, 0.0)
    if per_bin.max() > 0.0:
        bi, bj = np.unravel_index(int(np.argmax(per_bin)), per_bin.shape)
        worst = (
            f"worst bin {_bin_label(bi, bj, *observed.shape)}: "
            f"{int(observed[bi, bj])} samples, expected {expected[bi, bj]:.1f}"
        )
    if expected_absorbed >= min_expected or absorbed >= min_expected:
        z_abs = abs(absorbed - expected_absorbed) / math.sqrt(expected_absorbed + 1.0)
        if z_abs > 3.0:
            worst = (
                f"absorbed {int(absorbed)} samples but pdf() integrates to "
                f"{pdf_integral:.6f}, which predicts {expected_absorbed:.1f}"
            )
    return worst


def chi2_test(
    material: Material | MaterialSubject,
    incident_deg: float,
    n_samples: int = 100_000,
    theta_bins: int = 24,
    phi_bins: int = 48,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    node_spacing: float = 0.035,
    min_expected: float = 5.0,
    inside: bool = False,
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
    quadrature's uncertainty, and so does a draw too small to test (every bin
    pooled into one: nothing scattered, or almost nothing). inside: the viewer is
    inside the material (the hit on its back face). material: an rtpy Material or
    a MaterialSubject.
    """
    if theta_bins < 2 or theta_bins % 2 or phi_bins < 1:
        raise ValueError("theta_bins must be even and >= 2, phi_bins >= 1")
    subject = as_subject(material)
    if subject.is_specular:
        raise ValueError("a specular (delta) material has no density to test")
    start = time.perf_counter()
    samples = get_samples(subject, incident_deg, n_samples, seed, phi_deg, samples, inside)
    hist = _histogram(samples, theta_bins, phi_bins)
    bins = _BinIntegrals(subject, samples, (theta_bins, phi_bins), node_spacing)
    integral, errors = bins.integrate_all(hist, samples.n)
    result = _assess(samples, hist, bins, integral, errors, min_expected)
    result.seconds = time.perf_counter() - start
    return result


def _assess(samples: Samples, hist: _Histogram, bins, integral, errors, min_expected):
    """The Chi2Result of the samples binned in hist against the integrals of pdf()
    over the bins (and their estimated errors)."""
    n = samples.n
    n_absorbed = int(np.count_nonzero(samples.status == ABSORBED))
    n_specular = int(np.count_nonzero(samples.status == SPECULAR))
    expected = n * integral
    pdf_integral = float(integral.sum())
    expected_absorbed = max(0.0, n * (1.0 - pdf_integral))
    observed_absorbed = float(n_absorbed + n_specular)
    message = _outright_failure(bins.bad_values, pdf_integral, errors, hist, integral)
    uncertainty = n * float(errors.sum())
    statistic, n_categories = _pearson(
        hist.observed, expected, observed_absorbed, expected_absorbed, uncertainty, min_expected
    )
    dof = n_categories - 1
    if message:
        p_value = 0.0
    elif dof < 1:
        # Nothing to compare: a check of sampling needs samples (a material that
        # absorbs every draw, with pdf() 0, is consistent but tells nothing).
        p_value = 0.0
        scattered = n - n_absorbed - n_specular
        message = (
            f"too few scattered samples for a test ({scattered} of {n}; all bins pooled "
            "into one): scattering() must return directions for the test to check them"
        )
    else:
        p_value = chi2_sf(statistic, dof)
    worst = _worst(
        hist.observed, expected, min_expected, observed_absorbed, expected_absorbed, pdf_integral
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
        upper_integral=float(integral[: integral.shape[0] // 2].sum()),
        integration_error=float(errors.sum()),
        pdf_evaluations=bins.evaluations,
        n_categories=n_categories,
        observed=hist.observed,
        expected=expected,
        worst=worst,
        message=message,
        note=f"quadrature of pdf() uncertain by {uncertainty:.1f} samples"
        if uncertainty > 1.0
        else "",
    )
