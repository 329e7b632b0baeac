"""rtpy.materials.Metal: a reflection blurred by fuzz."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Metal, Mirror
from rtpy.sampling import make_generator, use_generator

from ..vectors import dot3, norm3, unit3
from .directions import ALBEDO_COLOR, UP, incoming, make_hit


def test_metal_with_zero_fuzz_is_a_mirror():
    metal, mirror = Metal(ALBEDO_COLOR, 0.0), Mirror(ALBEDO_COLOR)
    assert metal.is_specular is True
    hit = make_hit(metal, unit3((0.2, 1.0, -0.1)))
    with use_generator(make_generator(4)):
        for d in ((1, -1, 0), (0.3, -0.2, 0.9), (0, -1, 0)):
            a = metal.scattering(incoming(d, hit), hit)
            b = mirror.scattering(incoming(d, hit), hit)
            assert a.scattered_ray.direction.tolist() == b.scattered_ray.direction.tolist()
            assert a.scattered_ray.origin.tolist() == b.scattered_ray.origin.tolist()
            assert a.attenuation.tolist() == ALBEDO_COLOR.tolist()
            assert a.is_specular is True


@pytest.mark.parametrize("fuzz", [0.1, 0.3, 0.9])
def test_metal_fuzz_stays_near_the_reflection_and_above_the_surface(fuzz):
    m = Metal(ALBEDO_COLOR, fuzz)
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
            assert s.attenuation.tolist() == ALBEDO_COLOR.tolist()
            got.append(out)
    assert len(got) > 300
    # It does blur: not every direction equals the perfect reflection.
    assert max(math.acos(min(1.0, dot3(o, perfect))) for o in got) > 0.5 * max_angle


def test_rough_metal_at_grazing_incidence_absorbs_some_rays():
    m = Metal(ALBEDO_COLOR, 1.0)
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
    m = Metal(ALBEDO_COLOR, 0.7)
    hit = make_hit(m, UP)
    rays = m.specular_rays(incoming((1, -1, 0), hit), hit)
    assert len(rays) == 1
    assert rays[0][0].direction.tolist() == pytest.approx(list(unit3((1, 1, 0))), abs=1e-15)
    assert rays[0][1].tolist() == ALBEDO_COLOR.tolist()


def test_metal_rejects_negative_fuzz():
    with pytest.raises(ValueError):
        Metal(ALBEDO_COLOR, -0.1)
