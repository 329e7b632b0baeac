"""Tests for rtpy.materials: Lambertian, Mirror, Metal, Dielectric and DiffuseLight."""

from __future__ import annotations

import math

import pytest

from rtpy.hit_info import HitInfo
from rtpy.materials import (
    MATERIALS,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Metal,
    Mirror,
    schlick,
)
from rtpy.ray import Ray
from rtpy.sampling import make_generator, use_generator
from rtpy.texture import CheckerTexture
from rtpy.vec3 import Color

from ..vectors import V, dot3, norm3, unit3

ALBEDO = Color(0.8, 0.5, 0.25)


def make_hit(material, normal=(0.0, 1.0, 0.0), point=(0.5, 0.0, -0.25), front_face=True):
    """A hit whose normal faces the arriving ray (as HitInfo promises)."""
    return HitInfo(V(*point), V(*normal), 1.0, front_face, material)


def incoming(direction, hit) -> Ray:
    """A ray arriving at the hit point along `direction` (pointing toward the surface)."""
    d = V(*unit3(direction))
    return Ray(hit.point - d, d)


def leaving(direction, hit) -> Ray:
    return Ray(hit.point, V(*unit3(direction)))


# --- Lambertian ------------------------------------------------------------------------

NORMALS = [(0.0, 1.0, 0.0), (0.0, 0.0, -1.0), unit3((0.3, -0.5, 0.8)), unit3((1e-9, 0, -1))]


@pytest.mark.parametrize("normal", NORMALS)
def test_lambertian_brdf_and_pdf(normal):
    m = Lambertian(ALBEDO)
    hit = make_hit(m, normal)
    view = incoming(tuple(-x for x in normal), hit)
    helper = (1.0, 0.0, 0.0) if abs(normal[0]) < 0.9 else (0.0, 1.0, 0.0)
    for k in (0.0, 0.3, 1.0, 5.0):
        # Directions above the surface at various angles.
        wi = unit3(tuple(normal[i] + k * helper[i] for i in range(3)))
        cos = dot3(wi, normal)
        if cos <= 0.0:
            continue
        f = m.BRDF(view, leaving(wi, hit), hit)
        assert f.tolist() == pytest.approx([a / math.pi for a in ALBEDO.tolist()], rel=1e-15)
        assert m.pdf(view, leaving(wi, hit), hit) == pytest.approx(cos / math.pi, rel=1e-12)
        # Mirror image below the surface: no reflection, no density.
        below = tuple(wi[i] - 2 * cos * normal[i] for i in range(3))
        assert m.BRDF(view, leaving(below, hit), hit).tolist() == [0.0, 0.0, 0.0]
        assert m.pdf(view, leaving(below, hit), hit) == 0.0
    # Exactly in the tangent plane: zero too.
    tangent = unit3(
        (
            helper[1] * normal[2] - helper[2] * normal[1],
            helper[2] * normal[0] - helper[0] * normal[2],
            helper[0] * normal[1] - helper[1] * normal[0],
        )
    )
    assert m.pdf(view, leaving(tangent, hit), hit) == pytest.approx(0.0, abs=1e-16)


@pytest.mark.parametrize("normal", NORMALS)
def test_lambertian_scattering_weight_pdf_and_hemisphere(normal):
    m = Lambertian(ALBEDO)
    hit = make_hit(m, normal)
    view = incoming(tuple(-x for x in normal), hit)
    n = 2000
    cos_sum = 0.0
    with use_generator(make_generator(1234)):
        for _ in range(n):
            s = m.scattering(view, hit)
            assert s is not None
            assert s.is_specular is False
            d = s.scattered_ray.direction.tolist()
            assert math.isclose(norm3(d), 1.0, abs_tol=1e-12)
            cos = dot3(d, normal)
            assert cos >= -1e-15
            assert s.attenuation.tolist() == ALBEDO.tolist()
            assert s.pdf == pytest.approx(cos / math.pi, rel=1e-9, abs=1e-15)
            # The Monte Carlo weight is consistent with BRDF and pdf.
            if cos > 1e-6:
                f = m.BRDF(view, s.scattered_ray, hit)
                w = [fi * cos / s.pdf for fi in f.tolist()]
                assert w == pytest.approx(s.attenuation.tolist(), abs=1e-12)
                assert m.pdf(view, s.scattered_ray, hit) == pytest.approx(s.pdf, rel=1e-12)
            # The ray starts on the side of the surface it leaves to.
            off = [s.scattered_ray.origin.tolist()[i] - hit.point.tolist()[i] for i in range(3)]
            assert dot3(off, normal) >= 0.0
            cos_sum += cos
    # Cosine-weighted: E[cos] = 2/3, var = 1/2 - 4/9.
    assert abs(cos_sum / n - 2 / 3) < 4 * math.sqrt((0.5 - 4 / 9) / n)


def test_lambertian_uses_its_texture():
    tex = CheckerTexture(1.0, Color(1, 0, 0), Color(0, 0, 1))
    m = Lambertian(tex)
    even = make_hit(m, point=(0.5, 0.5, 0.5))
    odd = make_hit(m, point=(1.5, 0.5, 0.5))
    with use_generator(make_generator(1)):
        assert m.scattering(incoming((0, -1, 0), even), even).attenuation.tolist() == [1, 0, 0]
        assert m.scattering(incoming((0, -1, 0), odd), odd).attenuation.tolist() == [0, 0, 1]
    assert m.flat_color(even).tolist() == [1, 0, 0]


def test_lambertian_default_albedo():
    m = Lambertian()
    assert m.flat_color(make_hit(m)).tolist() == [0.5, 0.5, 0.5]
    assert m.is_specular is False and m.is_emitter is False


# --- Mirror and Metal --------------------------------------------------------------------


@pytest.mark.parametrize(
    "d, n, r",
    [
        ((1, -1, 0), (0, 1, 0), (1, 1, 0)),
        ((0, 0, -1), (0, 0, 1), (0, 0, 1)),
        ((0.3, -0.4, 0.5), (0, 1, 0), (0.3, 0.4, 0.5)),
        ((1, 0, -1), unit3((0, 0, 1)), (1, 0, 1)),
    ],
)
def test_mirror_reflects_exactly(d, n, r):
    m = Mirror(ALBEDO)
    assert m.is_specular is True
    hit = make_hit(m, n)
    s = m.scattering(incoming(d, hit), hit)
    assert s.is_specular is True
    assert s.attenuation.tolist() == ALBEDO.tolist()
    assert s.scattered_ray.direction.tolist() == pytest.approx(list(unit3(r)), abs=1e-15)
    off = [s.scattered_ray.origin.tolist()[i] - hit.point.tolist()[i] for i in range(3)]
    assert dot3(off, n) > 0.0
    rays = m.specular_rays(incoming(d, hit), hit)
    assert len(rays) == 1
    assert rays[0][0].direction.tolist() == pytest.approx(list(unit3(r)), abs=1e-15)
    assert rays[0][1].tolist() == ALBEDO.tolist()


def test_mirror_default_albedo_is_white():
    m = Mirror()
    assert m.flat_color(make_hit(m)).tolist() == [1.0, 1.0, 1.0]


def test_metal_with_zero_fuzz_is_a_mirror():
    metal, mirror = Metal(ALBEDO, 0.0), Mirror(ALBEDO)
    assert metal.is_specular is True
    hit = make_hit(metal, unit3((0.2, 1.0, -0.1)))
    with use_generator(make_generator(4)):
        for d in ((1, -1, 0), (0.3, -0.2, 0.9), (0, -1, 0)):
            a = metal.scattering(incoming(d, hit), hit)
            b = mirror.scattering(incoming(d, hit), hit)
            assert a.scattered_ray.direction.tolist() == b.scattered_ray.direction.tolist()
            assert a.scattered_ray.origin.tolist() == b.scattered_ray.origin.tolist()
            assert a.attenuation.tolist() == ALBEDO.tolist()
            assert a.is_specular is True


@pytest.mark.parametrize("fuzz", [0.1, 0.3, 0.9])
def test_metal_fuzz_stays_near_the_reflection_and_above_the_surface(fuzz):
    m = Metal(ALBEDO, fuzz)
    n = (0.0, 1.0, 0.0)
    hit = make_hit(m, n)
    d = unit3((1.0, -1.0, 0.0))
    perfect = (d[0], -d[1], d[2])
    max_angle = math.asin(min(1.0, fuzz))  # unit reflection + a point of a fuzz-radius sphere
    got = []
    with use_generator(make_generator(1234)):
        for _ in range(500):
            s = m.scattering(incoming(d, hit), hit)
            if s is None:
                continue
            out = s.scattered_ray.direction.tolist()
            assert math.isclose(norm3(out), 1.0, abs_tol=1e-12)
            assert dot3(out, n) > 0.0
            ang = math.acos(max(-1.0, min(1.0, dot3(out, perfect))))
            assert ang <= max_angle + 1e-9
            assert s.attenuation.tolist() == ALBEDO.tolist()
            got.append(out)
    assert len(got) > 300
    # It does blur: not every direction equals the perfect reflection.
    assert max(math.acos(min(1.0, dot3(o, perfect))) for o in got) > 0.5 * max_angle


def test_rough_metal_at_grazing_incidence_absorbs_some_rays():
    m = Metal(ALBEDO, 1.0)
    n = (0.0, 1.0, 0.0)
    hit = make_hit(m, n)
    d = unit3((1.0, -0.05, 0.0))
    none = 0
    with use_generator(make_generator(8)):
        for _ in range(400):
            s = m.scattering(incoming(d, hit), hit)
            if s is None:
                none += 1
            else:
                assert s.scattered_ray.direction.e1 > 0.0
    assert 0 < none < 400


def test_metal_specular_rays_ignore_fuzz():
    m = Metal(ALBEDO, 0.7)
    hit = make_hit(m)
    rays = m.specular_rays(incoming((1, -1, 0), hit), hit)
    assert len(rays) == 1
    assert rays[0][0].direction.tolist() == pytest.approx(list(unit3((1, 1, 0))), abs=1e-15)
    assert rays[0][1].tolist() == ALBEDO.tolist()


def test_metal_rejects_negative_fuzz():
    with pytest.raises(ValueError):
        Metal(ALBEDO, -0.1)


# --- Dielectric -----------------------------------------------------------------------------


def test_dielectric_normal_incidence_from_outside():
    m = Dielectric(1.5)
    assert m.is_specular is True
    n = (0.0, 0.0, 1.0)
    hit = make_hit(m, n, point=(0.0, 0.0, 0.0))
    d = (0.0, 0.0, -1.0)
    ray = incoming(d, hit)
    R = ((1 - 1.5) / (1 + 1.5)) ** 2
    assert R == pytest.approx(0.04)
    trials, reflected = 20000, 0
    with use_generator(make_generator(1234)):
        for _ in range(trials):
            s = m.scattering(ray, hit)
            assert s is not None and s.is_specular
            assert s.attenuation.tolist() == [1.0, 1.0, 1.0]
            out = s.scattered_ray.direction
            assert abs(out.e0) < 1e-15 and abs(out.e1) < 1e-15
            if out.e2 > 0.0:
                reflected += 1
                assert abs(out.e2 - 1.0) < 1e-15
                assert s.scattered_ray.origin.e2 > 0.0
            else:
                # Transmitted straight through, starting below the surface.
                assert abs(out.e2 + 1.0) < 1e-15
                assert s.scattered_ray.origin.e2 < 0.0
    sigma = math.sqrt(trials * R * (1 - R))
    assert abs(reflected - trials * R) < 4 * sigma


@pytest.mark.parametrize("theta_deg", [20.0, 45.0, 70.0, 85.0])
def test_dielectric_oblique_from_outside_refracts_by_snell(theta_deg):
    ior = 1.5
    m = Dielectric(ior, ALBEDO)
    n = (0.0, 1.0, 0.0)
    hit = make_hit(m, n)
    th = math.radians(theta_deg)
    d = (math.sin(th), -math.cos(th), 0.0)
    ray = incoming(d, hit)
    r0 = ((1 - ior) / (1 + ior)) ** 2
    R = r0 + (1 - r0) * (1 - math.cos(th)) ** 5
    rays = m.specular_rays(ray, hit)
    assert len(rays) == 2
    (refl, w_refl), (refr, w_refr) = rays
    assert refl.direction.tolist() == pytest.approx([d[0], -d[1], 0.0], abs=1e-14)
    assert w_refl.tolist() == pytest.approx([a * R for a in ALBEDO.tolist()], rel=1e-12)
    assert w_refr.tolist() == pytest.approx([a * (1 - R) for a in ALBEDO.tolist()], rel=1e-12)
    # Weights sum to the albedo.
    total = [a + b for a, b in zip(w_refl.tolist(), w_refr.tolist(), strict=True)]
    assert total == pytest.approx(ALBEDO.tolist(), rel=1e-14)
    # Snell: sin(theta_t) = sin(theta_i) / ior, continuing forward and down.
    t = refr.direction.tolist()
    assert norm3(t) == pytest.approx(1.0, abs=1e-12)
    assert t[0] == pytest.approx(math.sin(th) / ior, abs=1e-12)
    assert t[1] == pytest.approx(-math.sqrt(1 - (math.sin(th) / ior) ** 2), abs=1e-12)
    assert refr.origin.e1 < hit.point.e1 < refl.origin.e1
    assert schlick(math.cos(th), 1 / ior) == pytest.approx(R, rel=1e-12)


def test_total_internal_reflection_from_inside():
    ior = 1.5
    m = Dielectric(ior, ALBEDO)
    critical = math.asin(1 / ior)
    n = (0.0, 1.0, 0.0)  # facing the ray, which travels inside the glass
    hit = make_hit(m, n, front_face=False)
    for theta in (critical + 1e-3, math.radians(60.0), math.radians(89.0)):
        d = (math.sin(theta), -math.cos(theta), 0.0)
        ray = incoming(d, hit)
        with use_generator(make_generator(5)):
            for _ in range(200):
                s = m.scattering(ray, hit)
                assert s.scattered_ray.direction.tolist() == pytest.approx(
                    [d[0], -d[1], 0.0], abs=1e-14
                )
                assert s.attenuation.tolist() == ALBEDO.tolist()
        rays = m.specular_rays(ray, hit)
        assert len(rays) == 1
        assert rays[0][1].tolist() == ALBEDO.tolist()
        assert rays[0][0].direction.tolist() == pytest.approx([d[0], -d[1], 0.0], abs=1e-14)


def test_from_inside_below_critical_angle_refracts_out():
    ior = 1.5
    m = Dielectric(ior)
    n = (0.0, 1.0, 0.0)
    hit = make_hit(m, n, front_face=False)
    th = math.radians(30.0)
    d = (math.sin(th), -math.cos(th), 0.0)
    rays = m.specular_rays(incoming(d, hit), hit)
    assert len(rays) == 2
    t = rays[1][0].direction.tolist()
    sin_t = ior * math.sin(th)
    assert t == pytest.approx([sin_t, -math.sqrt(1 - sin_t * sin_t), 0.0], abs=1e-12)
    # Schlick with the cosine on the incident side (inside the glass).
    r0 = 0.04
    R = r0 + (1 - r0) * (1 - math.cos(th)) ** 5
    assert rays[0][1].r() == pytest.approx(R, rel=1e-12)
    assert rays[0][1].r() + rays[1][1].r() == pytest.approx(1.0, rel=1e-14)


def test_dielectric_rejects_bad_ior():
    with pytest.raises(ValueError):
        Dielectric(0.0)


# --- DiffuseLight ---------------------------------------------------------------------------


def test_diffuse_light_emits_from_front_face_only():
    emit = Color(3.0, 2.0, 1.0)
    m = DiffuseLight(emit)
    assert m.is_emitter is True
    front = make_hit(m, front_face=True)
    back = make_hit(m, front_face=False)
    assert m.emitting(front).tolist() == [3.0, 2.0, 1.0]
    assert m.emitting(back).tolist() == [0.0, 0.0, 0.0]
    assert m.scattering(incoming((0, -1, 0), front), front) is None
    assert m.flat_color(front).tolist() == [1.0, 1.0, 1.0]


def test_two_sided_diffuse_light_emits_from_both_faces():
    m = DiffuseLight(Color(3.0, 2.0, 1.0), two_sided=True)
    assert m.emitting(make_hit(m, front_face=True)).tolist() == [3.0, 2.0, 1.0]
    assert m.emitting(make_hit(m, front_face=False)).tolist() == [3.0, 2.0, 1.0]


def test_non_emitters_emit_nothing():
    for m in (Lambertian(ALBEDO), Mirror(), Metal(), Dielectric()):
        assert m.emitting(make_hit(m)).tolist() == [0.0, 0.0, 0.0]
        assert m.is_emitter is False


def test_registry_names():
    assert MATERIALS["lambertian"] is Lambertian
    assert MATERIALS["mirror"] is Mirror
    assert MATERIALS["metal"] is Metal
    assert MATERIALS["dielectric"] is Dielectric
    assert MATERIALS["diffuse_light"] is DiffuseLight
