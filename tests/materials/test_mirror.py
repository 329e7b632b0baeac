"""rtpy.materials.Mirror: the perfect reflection."""

from __future__ import annotations

import pytest

from rtpy.materials import Mirror

from ..vectors import dot3, unit3
from .directions import ALBEDO_COLOR, UP, incoming, make_hit


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
    m = Mirror(ALBEDO_COLOR)
    assert m.is_specular is True
    hit = make_hit(m, n)
    s = m.scattering(incoming(d, hit), hit)
    assert s.is_specular is True
    assert s.attenuation.tolist() == ALBEDO_COLOR.tolist()
    assert s.scattered_ray.direction.tolist() == pytest.approx(list(unit3(r)), abs=1e-15)
    off = [s.scattered_ray.origin.tolist()[i] - hit.point.tolist()[i] for i in range(3)]
    assert dot3(off, n) > 0.0
    rays = m.specular_rays(incoming(d, hit), hit)
    assert len(rays) == 1
    assert rays[0][0].direction.tolist() == pytest.approx(list(unit3(r)), abs=1e-15)
    assert rays[0][1].tolist() == ALBEDO_COLOR.tolist()


def test_mirror_default_albedo_is_white():
    m = Mirror()
    assert m.flat_color(make_hit(m, UP)).tolist() == [1.0, 1.0, 1.0]
