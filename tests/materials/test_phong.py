"""Tests for rtpy.materials.Phong: the BRDF, its density, its samples and its energy.

Expected values come from the formula of the scene-format contract, written out
again here in world coordinates (r = reflect(-wi about n)), not from the code
under test:

    f_r = kd * albedo / pi + ks * (n + 2) / (2 pi) * max(0, r . wo)^n
    pdf = p_d * cos(theta_i) / pi + (1 - p_d) * (n + 1) / (2 pi) * max(0, m . wi)^n

with p_d = kd * max(albedo) / (kd * max(albedo) + ks) and m the mirror image of wo.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from rtpy.hit_info import HitInfo
from rtpy.io.scene_file import SceneError, load_scene_text
from rtpy.materials import MATERIALS, Phong
from rtpy.ray import Ray
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import Color, Vec3

ALBEDO = (0.8, 0.5, 0.25)
POINT = (0.5, -0.25, 2.0)


# --- plain-tuple vector helpers (independent of rtpy.vec3 and rtpy.onb) ------------------


def dot3(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit3(a):
    k = 1.0 / math.sqrt(dot3(a, a))
    return (a[0] * k, a[1] * k, a[2] * k)


def cross3(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def frame(axis):
    """Two unit vectors completing `axis` to an orthonormal frame (Gram-Schmidt)."""
    helper = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0)
    k = dot3(helper, axis)
    t = unit3(tuple(helper[i] - k * axis[i] for i in range(3)))
    return t, cross3(axis, t)


def around(axis, cos_t, phi):
    """The unit vector at angle acos(cos_t) from axis, azimuth phi in frame(axis)."""
    t, b = frame(axis)
    s = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    c, d = s * math.cos(phi), s * math.sin(phi)
    return tuple(c * t[i] + d * b[i] + cos_t * axis[i] for i in range(3))


def direction(normal, theta_deg, phi_deg):
    t = math.radians(theta_deg)
    return around(normal, math.cos(t), math.radians(phi_deg))


def mirror(d, normal):
    """d reflected about the normal (d and the result both point away from the surface)."""
    k = 2.0 * dot3(d, normal)
    return tuple(k * normal[i] - d[i] for i in range(3))


NORMAL = unit3((0.3, -0.5, 0.8))


def make_hit(material, normal=NORMAL):
    return HitInfo(Vec3(*POINT), Vec3(*normal), 1.0, True, material)


def view_ray(wo) -> Ray:
    """The ray arriving at POINT from the viewer in direction wo."""
    return Ray(Vec3(*(POINT[i] + wo[i] for i in range(3))), Vec3(*(-x for x in wo)))


def light_ray(wi) -> Ray:
    return Ray(Vec3(*POINT), Vec3(*wi))


# --- the formulas ---------------------------------------------------------------------


def lobe_cos(wo, wi, normal):
    """r . wo with r = reflect(-wi about n), written as in the contract."""
    v = tuple(-x for x in wi)  # -wi points toward the surface
    k = 2.0 * dot3(v, normal)
    r = tuple(v[i] - k * normal[i] for i in range(3))
    return dot3(r, wo)


def expected_brdf(kd, ks, n, wo, wi, normal=NORMAL):
    if dot3(wo, normal) <= 0.0 or dot3(wi, normal) <= 0.0:
        return [0.0, 0.0, 0.0]
    c = lobe_cos(wo, wi, normal)
    spec = (n + 2.0) / (2.0 * math.pi) * c**n if c > 0.0 else 0.0
    return [kd * a / math.pi + ks * spec for a in ALBEDO]


def expected_pdf(kd, ks, n, wo, wi, normal=NORMAL):
    cos_i = dot3(wi, normal)
    if dot3(wo, normal) <= 0.0 or cos_i <= 0.0:
        return 0.0
    diffuse = kd * max(ALBEDO)
    p_d = diffuse / (diffuse + ks) if diffuse + ks > 0.0 else 1.0
    c = dot3(mirror(wo, normal), wi)  # m . wi, another route to r . wo
    spec = (n + 1.0) / (2.0 * math.pi) * c**n if c > 0.0 else 0.0
    return p_d * cos_i / math.pi + (1.0 - p_d) * spec


# --- quadrature on the sphere ---------------------------------------------------------

# Gauss-Legendre pieces in u = cos(angle to the axis), finer toward u = 1 where
# cosine-power lobes concentrate; the azimuth uses the periodic trapezoid rule.
U_BREAKS = (
    -1.0,
    0.0,
    1e-4,
    1e-3,
    0.01,
    0.1,
    0.5,
    0.8,
    0.9,
    0.95,
    0.98,
    0.99,
    0.995,
    0.998,
    0.999,
    0.9995,
    0.9998,
    0.9999,
    0.99995,
    0.99999,
    1.0,
)
GL_X, GL_W = np.polynomial.legendre.leggauss(24)


def sphere_integral(f, axis, n_phi=48):
    """Integral of f(direction) over the unit sphere, in the frame around `axis`."""
    total = 0.0
    for lo, hi in zip(U_BREAKS[:-1], U_BREAKS[1:], strict=True):
        half = 0.5 * (hi - lo)
        for x, w in zip(GL_X, GL_W, strict=True):
            u = lo + half * (x + 1.0)
            ring = sum(f(around(axis, u, 2.0 * math.pi * (k + 0.5) / n_phi)) for k in range(n_phi))
            total += w * half * ring * (2.0 * math.pi / n_phi)
    return total


# --- strategies -----------------------------------------------------------------------

thetas = st.floats(0.0, 89.9)
phis = st.floats(0.0, 360.0)
weights = st.floats(0.0, 1.0)
exponents = st.one_of(st.sampled_from([0.0, 1.0, 2.0, 10.0, 100.0]), st.floats(0.0, 500.0))


def approx3(values, rel=1e-9, abs_=1e-12):
    return pytest.approx(values, rel=rel, abs=abs_)


# --- BRDF and pdf ---------------------------------------------------------------------


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_brdf_and_pdf_match_the_formulas(kd, ks, n, to, po, ti, pi_):
    wo, wi = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
    assume(abs(lobe_cos(wo, wi, NORMAL)) > 1e-6)  # away from the lobe's edge (0^n)
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    hit = make_hit(m)
    f = m.BRDF(view_ray(wo), light_ray(wi), hit)
    assert f.tolist() == approx3(expected_brdf(kd, ks, n, wo, wi))
    p = m.pdf(view_ray(wo), light_ray(wi), hit)
    assert p == pytest.approx(expected_pdf(kd, ks, n, wo, wi), rel=1e-9, abs=1e-12)


@given(weights, weights, exponents, thetas, phis, st.floats(90.001, 180.0), phis)
def test_zero_below_the_surface(kd, ks, n, to, po, ti, pi_):
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    hit = make_hit(m)
    wo, below = direction(NORMAL, to, po), direction(NORMAL, ti, pi_)
    assert m.BRDF(view_ray(wo), light_ray(below), hit).tolist() == [0.0, 0.0, 0.0]
    assert m.pdf(view_ray(wo), light_ray(below), hit) == 0.0
    # A viewer below the surface sees no reflection either (and nothing is sampled).
    assert m.BRDF(view_ray(below), light_ray(wo), hit).tolist() == [0.0, 0.0, 0.0]
    assert m.pdf(view_ray(below), light_ray(wo), hit) == 0.0
    assert m.scattering(view_ray(below), hit) is None


def test_the_highlight_peaks_at_the_mirror_direction():
    m = Phong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=50.0)
    hit = make_hit(m)
    wo = direction(NORMAL, 35.0, 20.0)
    peak = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert peak == pytest.approx(52.0 / (2.0 * math.pi), rel=1e-12)
    off = m.BRDF(view_ray(wo), light_ray(direction(NORMAL, 35.0, 20.0 + 180.0 + 10.0)), hit).e0
    assert 0.0 < off < peak


@given(weights, weights, exponents, thetas, phis, thetas, phis)
def test_reciprocity(kd, ks, n, ta, pa, tb, pb):
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    hit = make_hit(m)
    a, b = direction(NORMAL, ta, pa), direction(NORMAL, tb, pb)
    assume(abs(lobe_cos(a, b, NORMAL)) > 1e-6)
    f_ab = m.BRDF(view_ray(a), light_ray(b), hit).tolist()
    f_ba = m.BRDF(view_ray(b), light_ray(a), hit).tolist()
    assert f_ab == approx3(f_ba, rel=1e-9)


# --- sampling -------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kd, ks, n",
    [(0.5, 0.5, 20.0), (0.2, 0.8, 3.0), (0.0, 1.0, 0.0), (1.0, 0.0, 5.0), (0.3, 0.6, 1e4)],
)
@pytest.mark.parametrize("theta_o", [0.0, 40.0, 80.0])
def test_scattering_weight_is_brdf_cos_over_pdf(kd, ks, n, theta_o):
    m = Phong(Color(*ALBEDO), kd=kd, ks=ks, exponent=n)
    hit = make_hit(m)
    wo = direction(NORMAL, theta_o, 30.0)
    scattered = 0
    with use_generator(make_generator(7, int(theta_o))):
        for _ in range(1500):
            s = m.scattering(view_ray(wo), hit)
            if s is None:
                continue
            scattered += 1
            wi = s.scattered_ray.direction.tolist()
            assert math.isclose(math.sqrt(dot3(wi, wi)), 1.0, abs_tol=1e-12)
            cos_i = dot3(wi, NORMAL)
            assert cos_i > 0.0
            assert s.is_specular is False
            pdf = expected_pdf(kd, ks, n, wo, wi)
            assert s.pdf == pytest.approx(pdf, rel=1e-7)
            f = expected_brdf(kd, ks, n, wo, wi)
            weight = [x * cos_i / pdf for x in f]
            assert s.attenuation.tolist() == approx3(weight, rel=1e-7)
            assert (
                dot3([s.scattered_ray.origin.tolist()[i] - POINT[i] for i in range(3)], NORMAL)
                >= 0.0
            )
    assert scattered > 500


@pytest.mark.parametrize("n", [0.0, 1.0, 8.0, 100.0])
@pytest.mark.parametrize("theta_o", [0.0, 50.0])
def test_the_lobe_sampler_draws_cos_power_around_the_mirror_direction(n, theta_o):
    """E[cos] = (n + 1) / (n + 2) and E[cos^2] = (n + 1) / (n + 3) for the density
    (n + 1) / (2 pi) cos^n around m, and the azimuth around m is uniform."""
    m = Phong(kd=0.0, ks=1.0, exponent=n)
    t = math.radians(theta_o)
    wo = (math.sin(t), 0.0, math.cos(t))
    axis = (-wo[0], 0.0, wo[2])
    side, up = frame(axis)
    rng = np.random.default_rng(11)
    cs, xs, ys = [], [], []
    for r1, r2 in rng.random((20000, 2)):
        wi = m.sample_specular(wo, r1, r2)
        assert wi is not None
        assert math.isclose(dot3(wi, wi), 1.0, abs_tol=1e-12)
        cs.append(dot3(wi, axis))
        xs.append(dot3(wi, side))
        ys.append(dot3(wi, up))
    cs = np.array(cs)
    k = len(cs)
    for power, mean in ((1, (n + 1) / (n + 2)), (2, (n + 1) / (n + 3))):
        values = cs**power
        assert abs(values.mean() - mean) < 5.0 * values.std() / math.sqrt(k) + 1e-12
    for v in (np.array(xs), np.array(ys)):
        assert abs(v.mean()) < 5.0 * math.sqrt(0.5 / k)


@pytest.mark.parametrize("n", [0.0, 0.5, 1.0, 30.0, 1000.0, 1e4])
@pytest.mark.parametrize("theta_o", [0.0, 45.0, 85.0])
def test_the_specular_pdf_integrates_to_one_over_the_sphere(n, theta_o):
    m = Phong(kd=0.0, ks=1.0, exponent=n)
    t = math.radians(theta_o)
    wo = (math.sin(t), 0.0, math.cos(t))
    axis = (-wo[0], 0.0, wo[2])
    total = sphere_integral(lambda wi: m.specular_pdf(wo, wi), axis)
    assert total == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("n", [0.0, 0.8, 1.0, 8.0, 30.0, 1000.0])
def test_energy_the_normalised_lobe_reflects_at_most_everything(n):
    """Integral of the specular f_r * cos(theta_i) over the hemisphere (the directional
    albedo of the lobe with ks = 1): exactly 1 at normal incidence, less elsewhere."""
    m = Phong(Color(*ALBEDO), kd=0.0, ks=1.0, exponent=n)
    hit = make_hit(m)

    def albedo(theta_o):
        wo = direction(NORMAL, theta_o, 0.0)

        def f_cos(wi):
            cos_i = dot3(wi, NORMAL)
            return m.BRDF(view_ray(wo), light_ray(wi), hit).e0 * cos_i if cos_i > 0 else 0.0

        return sphere_integral(f_cos, mirror(wo, NORMAL))

    assert albedo(0.0) == pytest.approx(1.0, abs=1e-6)
    previous = 1.0
    for theta_o in (30.0, 60.0, 85.0):
        a = albedo(theta_o)
        assert 0.0 < a <= 1.0 + 1e-6
        if n > 0.0:
            # The lobe comes nearer the horizon, so a larger part of it is cut off.
            assert a <= previous + 1e-6
        previous = a


# --- extremes -------------------------------------------------------------------------


@pytest.mark.parametrize("n", [0.0, 1.0, 1e4])
def test_grazing_angles_and_huge_exponents_give_finite_values(n):
    m = Phong(Color(*ALBEDO), kd=0.5, ks=0.5, exponent=n)
    hit = make_hit(m)
    for to in (0.0, 60.0, 89.99):
        wo = direction(NORMAL, to, 10.0)
        lights = [direction(NORMAL, ti, pi_) for ti in (0.0, 45.0, 89.99) for pi_ in (10, 190)]
        lights.append(mirror(wo, NORMAL))
        for wi in lights:
            f = m.BRDF(view_ray(wo), light_ray(wi), hit).tolist()
            p = m.pdf(view_ray(wo), light_ray(wi), hit)
            assert all(math.isfinite(x) and x >= 0.0 for x in [*f, p])
        with use_generator(make_generator(3)):
            for _ in range(300):
                s = m.scattering(view_ray(wo), hit)
                if s is not None:
                    values = [*s.attenuation.tolist(), s.pdf, *s.scattered_ray.direction.tolist()]
                    assert all(math.isfinite(x) for x in values)
                    assert min(s.attenuation.tolist()) >= 0.0 and s.pdf > 0.0
    # At the mirror direction the huge lobe is large but finite.
    wo = direction(NORMAL, 89.99, 10.0)
    f = m.BRDF(view_ray(wo), light_ray(mirror(wo, NORMAL)), hit).e0
    assert f == pytest.approx(0.5 * ALBEDO[0] / math.pi + 0.5 * (n + 2) / (2 * math.pi), rel=1e-6)


def test_exponent_zero_is_uniform_around_the_mirror_direction():
    m = Phong(kd=0.0, ks=1.0, exponent=0.0)
    wo = (0.6, 0.0, 0.8)
    assert m.specular_pdf(wo, (-0.6, 0.0, 0.8)) == pytest.approx(1.0 / (2.0 * math.pi))
    assert m.specular_pdf(wo, (0.0, 0.6, 0.8)) == pytest.approx(1.0 / (2.0 * math.pi))
    assert m.specular_pdf(wo, (0.8, 0.0, 0.6)) == 0.0  # at 90 degrees from m
    assert m.specular_pdf(wo, (0.6, 0.0, -0.8)) == 0.0  # behind the mirror direction
    assert m.specular(wo, (0.0, 0.6, 0.8)).tolist() == approx3([1.0 / math.pi] * 3)
    assert m.specular(wo, (0.8, 0.0, 0.6)).tolist() == [0.0, 0.0, 0.0]


# --- construction and loading ---------------------------------------------------------


def test_defaults_and_registration():
    m = Phong()
    assert (m.kd, m.ks, m.exponent) == (1.0, 0.0, 1.0)
    assert m.albedo.color == Color(0.5, 0.5, 0.5)
    assert MATERIALS["phong"] is Phong
    assert m.is_specular is False and m.is_emitter is False


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"kd": -0.1}, "kd must be a finite number >= 0"),
        ({"ks": -1.0}, "ks must be a finite number >= 0"),
        ({"ks": math.inf}, "ks must be a finite number >= 0"),
        ({"exponent": -1.0}, "exponent must be a finite number >= 0, got -1.0"),
        ({"exponent": math.nan}, "exponent must be a finite number >= 0"),
        ({"exponent": math.inf}, "exponent must be a finite number >= 0"),
        ({"exponent": "10"}, "exponent must be a finite number >= 0"),
        ({"exponent": True}, "exponent must be a finite number >= 0"),
    ],
)
def test_constructor_refuses_bad_parameters(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Phong(Color(*ALBEDO), **kwargs)


SCENE = """\
[materials.shiny]
type = "phong"
albedo = [0.7, 0.15, 0.1]
kd = 0.6
ks = 0.4
exponent = 8

[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "shiny"
"""


def test_the_loader_accepts_a_phong_material():
    scene = load_scene_text(SCENE, "phong.toml")
    m = scene.objects[0].material
    assert isinstance(m, Phong)
    assert m.albedo.color == Color(0.7, 0.15, 0.1)
    assert (m.kd, m.ks, m.exponent) == (0.6, 0.4, 8.0)


def test_the_loader_uses_the_defaults_and_refuses_bad_values():
    m = load_scene_text(SCENE.replace("kd = 0.6\nks = 0.4\nexponent = 8\n", ""), "p.toml")
    m = m.objects[0].material
    assert (m.kd, m.ks, m.exponent) == (1.0, 0.0, 1.0)
    with pytest.raises(SceneError, match=r"\[materials.shiny\] exponent: .*>= 0"):
        load_scene_text(SCENE.replace("exponent = 8", "exponent = -2"), "p.toml")
    with pytest.raises(SceneError, match=r"\[materials.shiny\] shininess: unknown key"):
        load_scene_text(SCENE.replace("exponent = 8", "shininess = 8"), "p.toml")
