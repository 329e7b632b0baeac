# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 06 hidden checks: only the autograder holds them (assignments/week06/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

False failures: reflect and refract are compared with the laws of reflection and
Snell's law (exact up to rounding, incidence kept 2 degrees away from the critical
angle): a correct solution never fails. The dielectric check counts reflections
among N scatterings in each of CASES cases and rejects a count whose exact two-sided
binomial p-value is below ALPHA / CASES: a correct dielectric fails it with
probability at most ALPHA = 1e-4 per submission.
"""

import math

import numpy as np
import pytest

from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng, grading_seed

ALPHA = 1e-4
CASES = 3
N = 4000


def incidence(rng, cos_range=(0.05, 1.0)):
    """(unit normal n, unit direction d toward the surface, cos of incidence)."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    side = np.cross(n, rng.normal(size=3))
    side /= np.linalg.norm(side)
    cos = float(rng.uniform(*cos_range))
    d = -cos * n + math.sqrt(1 - cos * cos) * side
    return n, d, cos


# One case per task (06.1 reflect, 06.2 refract): a stub costs only its own points.
@pytest.mark.parametrize(
    "law", [pytest.param("reflect", marks=points(1)), pytest.param("refract", marks=points(1))]
)
def test_reflect_and_refract_at_new_directions(law, probe):
    """reflect and refract: the laws of reflection and Snell's law at new directions"""
    rng = grading_rng(601)
    reflections, refractions = [], []
    for _ in range(200):
        n, d, cos = incidence(rng)
        reflections.append((n, d))
        eta = float(rng.uniform(0.4, 2.5))
        sin_t = eta * math.sqrt(1 - cos * cos)
        if sin_t > math.sin(math.radians(88)):
            continue  # total internal reflection, or within 2 degrees of it
        refractions.append((n, d, eta, sin_t))
    if law == "reflect":
        reflected = probe.week06_reflect(cases=[[d, n] for n, d in reflections])
        refractions, refracted = [], []
    else:
        refracted = probe.week06_refract(cases=[[d, n, eta] for n, d, eta, _ in refractions])
        reflections, reflected = [], []
    for (n, d), got in zip(reflections, reflected, strict=True):
        want = d - 2 * (d @ n) * n
        assert np.allclose(got, want, atol=1e-12), (
            f"reflect (rtpy/vec3.py)(v={d.round(4)}, n={n.round(4)}) = {got.round(6)}, expected "
            f"v - 2 (v . n) n = {want.round(6)}"
        )
    for (n, d, eta, sin_t), got in zip(refractions, refracted, strict=True):
        where = f"refract (rtpy/vec3.py)(uv={d.round(4)}, n={n.round(4)}, etai_over_etat={eta:.4f})"
        assert abs(np.linalg.norm(got) - 1) < 1e-9, f"{where} = {got.round(6)}: not a unit vector"
        assert got @ n < 0, (
            f"{where} = {got.round(6)}: a refracted ray continues through the surface"
        )
        assert abs(math.sqrt(max(0.0, 1 - (got @ n) ** 2)) - sin_t) < 1e-9, (
            f"{where}: sin(theta_t) = {math.sqrt(max(0.0, 1 - (got @ n) ** 2)):.6f}, Snell's law "
            f"gives eta sin(theta_i) = {sin_t:.6f}"
        )
        assert abs(np.cross(np.cross(d, n), np.cross(got, n)) @ n) < 1e-9, (
            f"{where} = {got.round(6)}: the refracted ray stays in the plane of incidence"
        )


def binomial_p_value(k: int, n: int, p: float) -> float:
    """Two-sided p-value of k successes in n trials of probability p: twice the
    smaller tail, at most 1."""
    i = np.arange(n + 1)
    log_comb = np.array(
        [math.lgamma(n + 1) - math.lgamma(j + 1) - math.lgamma(n - j + 1) for j in i]
    )
    pmf = np.exp(log_comb + i * math.log(p) + (n - i) * math.log1p(-p))
    return min(1.0, 2.0 * min(pmf[: k + 1].sum(), pmf[k:].sum()))


@points(2)
def test_dielectric_reflects_with_the_schlick_probability_at_new_angles(probe):
    """Dielectric.scattering: reflects with probability R at new angles and indices"""
    rng = grading_rng(602)
    cases, asked = [], []
    for _ in range(CASES):
        ior = float(rng.uniform(1.2, 2.4))
        n, d, cos = incidence(rng, (0.1, 1.0))
        cases.append((ior, n, cos))
        asked.append(
            {"material": {"type": "Dielectric", "ior": ior, "albedo": [0.9, 0.95, 1.0]},
             "origin": -d, "direction": d, "normal": n, "front_face": True, "count": N}
        )  # fmt: skip
    got = probe.week06_scatter(cases=asked, generator=[grading_seed(603), 6])
    for (ior, n, cos), rows in zip(cases, got, strict=True):
        assert (rows[:, 0] == 1.0).all(), (
            f"Dielectric.scattering (rtpy/materials/dielectric.py), ior {ior:.3f}: returned None; "
            "a dielectric never absorbs, it returns a ScatterInfo for every ray"
        )
        reflected = int((rows[:, 1:4] @ n > 0).sum())
        r0 = ((1 - ior) / (1 + ior)) ** 2
        r = r0 + (1 - r0) * (1 - cos) ** 5  # entering the glass: no total reflection
        p = binomial_p_value(reflected, N, r)
        assert p > ALPHA / CASES, (
            f"Dielectric.scattering (rtpy/materials/dielectric.py), ior {ior:.3f}, entering at "
            f"{math.degrees(math.acos(cos)):.1f} degrees: reflects {reflected / N:.4f} of the rays, "
            f"Schlick's R is {r:.4f} (binomial p = {p:.2g}). Reflect with probability R "
            "(schlick(cos, 1 / ior) on the way in), refract otherwise"
        )
