"""rtpy.materials.Lambertian: the diffuse BRDF albedo / pi, its cosine-weighted samples."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Lambertian
from rtpy.sampling import make_generator, use_generator
from rtpy.texture import CheckerTexture
from rtpy.vec3 import Color

from ..vectors import dot3, norm3, unit3
from .directions import ALBEDO_COLOR, UP, incoming, leaving, make_hit

NORMALS = [(0.0, 1.0, 0.0), (0.0, 0.0, -1.0), unit3((0.3, -0.5, 0.8)), unit3((1e-9, 0, -1))]


@pytest.mark.parametrize("normal", NORMALS)
def test_lambertian_brdf_and_pdf(normal):
    m = Lambertian(ALBEDO_COLOR)
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
        assert f.tolist() == pytest.approx([a / math.pi for a in ALBEDO_COLOR.tolist()], rel=1e-15)
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
    m = Lambertian(ALBEDO_COLOR)
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
            assert s.attenuation.tolist() == ALBEDO_COLOR.tolist()
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
    even = make_hit(m, UP, point=(0.5, 0.5, 0.5))
    odd = make_hit(m, UP, point=(1.5, 0.5, 0.5))
    with use_generator(make_generator(1)):
        assert m.scattering(incoming((0, -1, 0), even), even).attenuation.tolist() == [1, 0, 0]
        assert m.scattering(incoming((0, -1, 0), odd), odd).attenuation.tolist() == [0, 0, 1]
    assert m.flat_color(even).tolist() == [1, 0, 0]


def test_lambertian_default_albedo():
    m = Lambertian()
    assert m.flat_color(make_hit(m, UP)).tolist() == [0.5, 0.5, 0.5]
    assert m.is_specular is False and m.is_emitter is False
