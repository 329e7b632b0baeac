"""Directions, hits and quadrature for the reflection-model tests.

Plain tuples and math, independent of rtpy.vec3 and rtpy.onb, so that expected
values do not come from the code under test. Directions point away from the
surface: wo toward the viewer, wi toward the light.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import strategies as st

from rtpy.hit_info import HitInfo
from rtpy.io.scene_file import SceneError, load_scene_text
from rtpy.materials import MATERIALS
from rtpy.ray import Ray
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import Color, Vec3

from ..vectors import cross3, dot3, unit3

ALBEDO = (0.8, 0.5, 0.25)
ALBEDO_COLOR = Color(*ALBEDO)
POINT = (0.5, -0.25, 2.0)


# A tilted surface, so that no coordinate axis helps the code under test; and the
# axis-aligned one, where local and world coordinates are the same.
NORMAL = unit3((0.3, -0.5, 0.8))
TANGENT = unit3(cross3(NORMAL, (0.0, 0.0, 1.0)))
Z, X = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)
UP = (0.0, 1.0, 0.0)


# Directions above the surface (degrees from the normal, azimuths), and weights kd, ks.
thetas = st.floats(0.0, 89.9)
phis = st.floats(0.0, 360.0)
weights = st.floats(0.0, 1.0)


# Strengths every glossy model refuses, with the start of its message.
BAD_STRENGTHS = [
    ({"kd": -0.1}, r"kd: expected a number in \[0, 1\], found -0.1"),
    ({"ks": -1.0}, r"ks: expected a number in \[0, 1\]"),
    ({"ks": 1.5}, r"ks: expected a number in \[0, 1\], found 1.5"),
    ({"ks": math.inf}, r"ks: expected a finite number in \[0, 1\]"),
    ({"ks": math.nan}, r"ks: expected a finite number in \[0, 1\]"),
]


def approx3(values, rel=1e-9, abs_=1e-12):
    return pytest.approx(values, rel=rel, abs=abs_)


def mixture_pdf(kd: float, ks: float, cos_i: float, highlight_pdf: float) -> float:
    """p_d cos(theta_i) / pi + (1 - p_d) highlight_pdf, p_d = kd max(ALBEDO) / (kd max(ALBEDO)
    + ks): the density of the glossy models' mixture."""
    diffuse = kd * max(ALBEDO)
    p_d = diffuse / (diffuse + ks) if diffuse + ks > 0.0 else 1.0
    return p_d * cos_i / math.pi + (1.0 - p_d) * highlight_pdf


def frame(axis):
    """Two unit vectors completing `axis` to an orthonormal frame (Gram-Schmidt)."""
    helper = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0)
    k = dot3(helper, axis)
    t = unit3(tuple(helper[i] - k * axis[i] for i in range(3)))
    return t, cross3(axis, t)


def around(axis, cos_t, phi, tangent=None):
    """The unit vector at angle acos(cos_t) from axis, at azimuth phi from the tangent
    (by default the first vector of frame(axis))."""
    t, b = frame(axis) if tangent is None else (tangent, cross3(axis, tangent))
    s = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    c, d = s * math.cos(phi), s * math.sin(phi)
    return tuple(c * t[i] + d * b[i] + cos_t * axis[i] for i in range(3))


def direction(normal, theta_deg, phi_deg):
    """At theta_deg degrees from the normal, azimuth phi_deg in frame(normal)."""
    return around(normal, math.cos(math.radians(theta_deg)), math.radians(phi_deg))


def polar(theta, phi, normal=NORMAL, tangent=TANGENT):
    """At polar angle theta (radians) from the normal, azimuth phi from the tangent."""
    b = cross3(normal, tangent)
    s = math.sin(theta)
    return tuple(
        s * math.cos(phi) * tangent[k] + s * math.sin(phi) * b[k] + math.cos(theta) * normal[k]
        for k in range(3)
    )


def mirror(d, normal):
    """d reflected about the normal (d and the result both point away from the surface)."""
    k = 2.0 * dot3(d, normal)
    return tuple(k * normal[i] - d[i] for i in range(3))


def half(wo, wi):
    return unit3(tuple(wo[i] + wi[i] for i in range(3)))


def make_hit(material, normal=NORMAL, tangent=None, point=POINT, front_face=True) -> HitInfo:
    """A hit whose normal faces the arriving ray (as HitInfo promises); front_face False
    for a ray that arrives from inside the object."""
    hit = HitInfo(Vec3(*point), Vec3(*normal), 1.0, front_face, material)
    if tangent is not None:
        hit.tangent = Vec3(*tangent)
    return hit


def incoming(direction, hit) -> Ray:
    """A ray arriving at the hit point along `direction` (pointing toward the surface)."""
    d = Vec3(*unit3(direction))
    return Ray(hit.point - d, d)


def leaving(direction, hit) -> Ray:
    """A ray leaving the hit point along `direction`."""
    return Ray(hit.point, Vec3(*unit3(direction)))


def view_ray(wo) -> Ray:
    """The ray arriving at POINT from the viewer, who sits in direction wo."""
    return Ray(Vec3(*(POINT[i] + wo[i] for i in range(3))), Vec3(*(-x for x in wo)))


def light_ray(wi) -> Ray:
    return Ray(Vec3(*POINT), Vec3(*wi))


def brdf(m, wo, wi, normal=NORMAL, tangent=None) -> list[float]:
    return m.BRDF(view_ray(wo), light_ray(wi), make_hit(m, normal, tangent)).tolist()


def pdf(m, wo, wi, normal=NORMAL, tangent=None) -> float:
    return m.pdf(view_ray(wo), light_ray(wi), make_hit(m, normal, tangent))


def alive_fraction(m, wo, n: int, seed: int, normal=NORMAL) -> float:
    """The fraction of n scattering() calls from viewer direction wo that return a
    sample (the rest are absorbed)."""
    hit = make_hit(m, normal)
    with use_generator(make_generator(seed)):
        return sum(m.scattering(view_ray(wo), hit) is not None for _ in range(n)) / n


# --- quadrature ---------------------------------------------------------------------------

GL_X, GL_W = np.polynomial.legendre.leggauss(24)

# Gauss-Legendre pieces in u = cos(angle to the axis), finer toward u = 1 where
# cosine-power lobes concentrate; the azimuth uses the periodic trapezoid rule.
U_BREAKS = (-1.0, 0.0, 1e-4, 1e-3, 0.01, 0.1, 0.5, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.998)
U_BREAKS += (0.999, 0.9995, 0.9998, 0.9999, 0.99995, 0.99999, 1.0)


def sphere_integral(f, axis, n_phi=48) -> float:
    """Integral of f(direction) over the unit sphere, in the frame around `axis`."""
    total = 0.0
    for lo, hi in zip(U_BREAKS[:-1], U_BREAKS[1:], strict=True):
        h = 0.5 * (hi - lo)
        for x, w in zip(GL_X, GL_W, strict=True):
            u = lo + h * (x + 1.0)
            ring = sum(f(around(axis, u, 2.0 * math.pi * (k + 0.5) / n_phi)) for k in range(n_phi))
            total += w * h * ring * (2.0 * math.pi / n_phi)
    return total


GL12_X, GL12_W = np.polynomial.legendre.leggauss(12)
STEPS = (0.0, 1e-3, 3e-3, 0.01, 0.02, 0.04, 0.08, 0.15, 0.3)


def polar_integral(f, axis, peak) -> float:
    """Integral of f(direction) over the unit sphere, in polar coordinates (psi, phi)
    around `axis` (psi from the axis): Gauss-Legendre on cells whose edges crowd
    around the direction `peak`, where the lobe is.

    Around wo's antipode a half-vector lobe's density grows like
    1 / (4 wo . h) = 1 / (2 sin(psi / 2)) with psi the angle to -wo; the area element
    sin(psi) makes that smooth, which a grid in cos(psi) would not. So pass axis = -wo
    for a density."""
    t, b = frame(axis)
    psi_peak = math.acos(max(-1.0, min(1.0, dot3(peak, axis))))
    phi_peak = math.atan2(dot3(peak, b), dot3(peak, t))
    psi = {k * math.pi / 16 for k in range(17)}
    psi |= {psi_peak + s for s in STEPS} | {psi_peak - s for s in STEPS}
    psi = sorted(x for x in psi if 0.0 <= x <= math.pi)
    phi = {phi_peak + k * math.pi / 8 for k in range(-8, 9)}
    phi |= {phi_peak + s for s in STEPS} | {phi_peak - s for s in STEPS}
    phi = sorted(phi)
    total = 0.0
    for p0, p1 in zip(psi[:-1], psi[1:], strict=True):
        hp = 0.5 * (p1 - p0)
        for x, wx in zip(GL12_X, GL12_W, strict=True):
            ps = p0 + hp * (x + 1.0)
            cos_p, sin_p = math.cos(ps), math.sin(ps)
            ring = 0.0
            for q0, q1 in zip(phi[:-1], phi[1:], strict=True):
                hq = 0.5 * (q1 - q0)
                for y, wy in zip(GL12_X, GL12_W, strict=True):
                    ring += wy * hq * f(around(axis, cos_p, q0 + hq * (y + 1.0)))
            total += wx * hp * sin_p * ring
    return total


def theta_nodes(a: float, breaks=()) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights in theta on [0, pi/2], with breakpoints where
    tan(theta) is a fixed multiple of the width a (so narrow lobes are resolved), and
    at `breaks` (where the integrand has a kink)."""
    edges = [0.0]
    s = 0.125
    while math.atan(a * s) < math.pi / 2 - 1e-3 and s < 1e7:
        edges.append(math.atan(a * s))
        s *= 2.0
    edges = sorted({*edges, *(b for b in breaks if 0.0 < b < math.pi / 2), math.pi / 2})
    xs, ws = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        xs.append(lo + (hi - lo) * (GL_X + 1.0) / 2.0)
        ws.append(GL_W * (hi - lo) / 2.0)
    return np.concatenate(xs), np.concatenate(ws)


def hemisphere_integral(f, a: float, n_phi: int = 1, phi_offset: float = 0.0, breaks=()) -> float:
    """Integral of f(theta, phi) sin(theta) d(theta) d(phi) over the upper hemisphere
    around z, resolved for a lobe of width a (and kinks at the polar angles `breaks`).
    n_phi = 1 for integrands that do not depend on phi."""
    thetas, weights = theta_nodes(a, breaks)
    phis = phi_offset + 2.0 * math.pi * (np.arange(n_phi) + 0.5) / n_phi
    total = 0.0
    for t, w in zip(thetas, weights, strict=True):
        row = sum(f(t, p) for p in phis) * (2.0 * math.pi / n_phi)
        total += w * math.sin(t) * row
    return total


def half_vector_albedo(m, wo, a: float, n_phi: int) -> float:
    """Directional albedo of a material with kd = 0 seen from wo, on the axis-aligned
    surface (normal Z, tangent X): the integral of f cos(theta_i) d(w_i), written over
    the half vector h as f cos(theta_i) 4 (wo . h) d(w_h) (wi = the mirror of wo about
    h), resolved for a lobe of width a."""
    hit = make_hit(m, Z, X)

    def integrand(t, p):
        s = math.sin(t)
        h = (s * math.cos(p), s * math.sin(p), math.cos(t))
        wo_h = dot3(wo, h)
        if wo_h <= 0.0:
            return 0.0
        wi = tuple(2.0 * wo_h * h[k] - wo[k] for k in range(3))
        if wi[2] <= 0.0:
            return 0.0
        return m.BRDF(view_ray(wo), light_ray(wi), hit).e0 * wi[2] * 4.0 * wo_h

    # phi_offset keeps the nodes off the plane of incidence's seam.
    return hemisphere_integral(integrand, a, n_phi, phi_offset=0.01)


# --- checks ---------------------------------------------------------------------------------


def check_scattering(m, wo, expected_brdf, expected_pdf, n, seed, normal=NORMAL, tangent=None):
    """Draws n samples from m.scattering() with the viewer in direction wo. Every sample
    must be a unit direction above the surface (its ray starting on the surface or above
    it), not specular, with the pdf expected_pdf(wi) and the weight
    expected_brdf(wi) * cos(theta_i) / pdf. Returns the cosines of the samples (absorbed
    ones give none)."""
    hit = make_hit(m, normal, tangent)
    cosines = []
    with use_generator(make_generator(*seed)):
        for _ in range(n):
            s = m.scattering(view_ray(wo), hit)
            if s is None:
                continue
            wi = s.scattered_ray.direction.tolist()
            assert math.isclose(dot3(wi, wi), 1.0, abs_tol=1e-12)
            cos_i = dot3(wi, normal)
            assert cos_i > 0.0 and s.is_specular is False
            origin = s.scattered_ray.origin.tolist()
            assert dot3([origin[i] - POINT[i] for i in range(3)], normal) >= 0.0
            pdf = expected_pdf(wi)
            assert s.pdf == pytest.approx(pdf, rel=1e-7)
            weight = [x * cos_i / pdf for x in expected_brdf(wi)]
            assert s.attenuation.tolist() == pytest.approx(weight, rel=1e-7, abs=1e-12)
            cosines.append(cos_i)
    return cosines


def check_finite(m, pairs, n_samples, normal=NORMAL, tangent=None) -> None:
    """BRDF() and pdf() finite and >= 0 for every (wo, [wi, ...]) in pairs, and the
    samples scattering() draws from each wo finite, >= 0, with a pdf > 0."""
    hit = make_hit(m, normal, tangent)
    for wo, lights in pairs:
        for wi in lights:
            f = m.BRDF(view_ray(wo), light_ray(wi), hit).tolist()
            p = m.pdf(view_ray(wo), light_ray(wi), hit)
            assert all(math.isfinite(x) and x >= 0.0 for x in [*f, p]), (wo, wi, f, p)
        with use_generator(make_generator(3)):
            for _ in range(n_samples):
                s = m.scattering(view_ray(wo), hit)
                if s is not None:
                    values = [*s.attenuation.tolist(), *s.scattered_ray.direction.tolist()]
                    assert all(math.isfinite(x) for x in [*values, s.pdf])
                    assert min(s.attenuation.tolist()) >= 0.0 and s.pdf > 0.0


def check_defaults(cls, name: str, **expected):
    """The material cls() made with no arguments, after checking that scene files know
    it as `name`, that it has the attributes `expected` and the grey albedo
    [0.5, 0.5, 0.5] (which the flat integrators show), and that it is neither specular
    nor an emitter."""
    assert MATERIALS[name] is cls
    m = cls()
    assert {key: getattr(m, key) for key in expected} == expected
    hit = make_hit(m)
    assert m.albedo.value(hit).tolist() == [0.5, 0.5, 0.5]
    assert m.flat_color(hit).tolist() == [0.5, 0.5, 0.5]
    assert m.is_specular is False and m.is_emitter is False
    return m


def load_material(keys: str, name: str = "shiny"):
    """The material of a scene file with one sphere, whose [materials.<name>] table holds
    these keys (the file is called <name>.toml)."""
    text = (
        f'[materials.{name}]\n{keys}\n\n[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\n'
        f'radius = 0.5\nmaterial = "{name}"\n'
    )
    return load_scene_text(text, f"{name}.toml").objects[0].material


def check_nothing_below(m, wo, below, normal=NORMAL, tangent=None) -> None:
    """With the light below the surface, or the viewer: BRDF() and pdf() are 0, and
    scattering() absorbs."""
    for view, light in ((wo, below), (below, wo)):
        assert brdf(m, view, light, normal, tangent) == [0.0, 0.0, 0.0]
        assert pdf(m, view, light, normal, tangent) == 0.0
    assert m.scattering(view_ray(below), make_hit(m, normal, tangent)) is None


def check_brdf_and_pdf(m, wo, wi, expected_brdf, expected_pdf, normal=NORMAL) -> None:
    """BRDF() and pdf() are the expected values, to 1e-9 relative."""
    assert brdf(m, wo, wi, normal) == pytest.approx(expected_brdf, rel=1e-9, abs=1e-12)
    assert pdf(m, wo, wi, normal) == pytest.approx(expected_pdf, rel=1e-9, abs=1e-12)


def check_mean_weight(m, wo, expected, n, seed, normal=NORMAL, tangent=None) -> None:
    """The mean of scattering()'s weights (red channel; absorbed samples count 0) over n
    samples estimates the directional albedo exactly when the sampler draws with the
    density pdf() claims: it must agree with `expected` (a quadrature) within 4.5
    standard errors, plus 2e-3 for the quadrature."""
    hit = make_hit(m, normal, tangent)
    weights = []
    with use_generator(make_generator(*seed)):
        for _ in range(n):
            s = m.scattering(view_ray(wo), hit)
            weights.append(0.0 if s is None else s.attenuation.e0)
    mean, stderr = float(np.mean(weights)), float(np.std(weights)) / math.sqrt(n)
    assert abs(mean - expected) < 4.5 * stderr + 2e-3


# Polar angles from the normal to the horizon, for the checks at the extremes.
EXTREME_ANGLES = [0.0, 0.5, math.radians(89.0), math.radians(89.99), math.pi / 2 - 1e-12]


def extreme_pairs(dphis, normal=NORMAL, tangent=TANGENT):
    """(wo, [wi, ...]) for check_finite: wo at every EXTREME_ANGLES, and wi at every one of
    them and each azimuth offset from wo's in dphis."""
    return [
        (
            polar(t_o, 0.2, normal, tangent),
            [polar(t_i, 0.2 + d, normal, tangent) for t_i in EXTREME_ANGLES for d in dphis],
        )
        for t_o in EXTREME_ANGLES
    ]


def check_refused(material_type: str, keys: str, words, name: str = "shiny") -> None:
    """A [materials.<name>] table of this type with these keys is refused with a
    SceneError naming the table and containing every one of `words`."""
    with pytest.raises(SceneError) as e:
        load_material(f'type = "{material_type}"\n{keys}', name)
    for word in [*words, f"[materials.{name}]"]:
        assert word in str(e.value)
