"""rtpy.materials.Dielectric: glass, Snell refraction with Schlick's reflectance."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Dielectric, schlick
from rtpy.sampling import make_generator, use_generator

from ..vectors import norm3
from .directions import ALBEDO_COLOR, incoming, make_hit


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
    m = Dielectric(ior, ALBEDO_COLOR)
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
    assert w_refl.tolist() == pytest.approx([a * R for a in ALBEDO_COLOR.tolist()], rel=1e-12)
    assert w_refr.tolist() == pytest.approx([a * (1 - R) for a in ALBEDO_COLOR.tolist()], rel=1e-12)
    # Weights sum to the albedo.
    total = [a + b for a, b in zip(w_refl.tolist(), w_refr.tolist(), strict=True)]
    assert total == pytest.approx(ALBEDO_COLOR.tolist(), rel=1e-14)
    # Snell: sin(theta_t) = sin(theta_i) / ior, continuing forward and down.
    t = refr.direction.tolist()
    assert norm3(t) == pytest.approx(1.0, abs=1e-12)
    assert t[0] == pytest.approx(math.sin(th) / ior, abs=1e-12)
    assert t[1] == pytest.approx(-math.sqrt(1 - (math.sin(th) / ior) ** 2), abs=1e-12)
    assert refr.origin.e1 < hit.point.e1 < refl.origin.e1
    assert schlick(math.cos(th), 1 / ior) == pytest.approx(R, rel=1e-12)


def test_total_internal_reflection_from_inside():
    ior = 1.5
    m = Dielectric(ior, ALBEDO_COLOR)
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
                assert s.attenuation.tolist() == ALBEDO_COLOR.tolist()
        rays = m.specular_rays(ray, hit)
        assert len(rays) == 1
        assert rays[0][1].tolist() == ALBEDO_COLOR.tolist()
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
