"""rtpy.hit_info.HitInfo: the record of a hit, with its surface coordinates, tangent and
shading frame computed on first access."""

from __future__ import annotations

import pytest

from rtpy.hit_info import HitInfo
from rtpy.hittable import Hittable
from rtpy.materials import Lambertian
from rtpy.vec3 import Vec3

from .vectors import dot3, norm3

NORMAL = Vec3(0.0, 0.6, 0.8)


class Counting(Hittable):
    """An object whose surface coordinates and tangent say how often they were asked for."""

    def __init__(self, tangent: Vec3 | None) -> None:
        self.material = Lambertian()
        self.tangent, self.calls = tangent, {"uv": 0, "tangent": 0}

    def surface_uv(self, hit):
        self.calls["uv"] += 1
        return 0.25, 0.75

    def surface_tangent(self, hit):
        self.calls["tangent"] += 1
        return self.tangent


def hit_on(obj, **kw) -> HitInfo:
    return HitInfo(Vec3(1.0, 2.0, 3.0), NORMAL, 2.5, True, Lambertian(), obj, **kw)


def test_surface_coordinates_are_asked_of_the_object_once_and_only_when_needed():
    obj = Counting(None)
    hit = hit_on(obj)
    assert obj.calls["uv"] == 0
    assert (hit.u, hit.v, hit.u) == (0.25, 0.75, 0.25)
    assert obj.calls["uv"] == 1
    given = hit_on(obj, u=0.5, v=0.125)  # a shape that knows them passes them in
    assert (given.u, given.v) == (0.5, 0.125) and obj.calls["uv"] == 1
    assert (hit_on(None).u, hit_on(None).v) == (0.0, 0.0)  # no object: (0, 0)


def test_the_tangent_is_the_objects_or_else_any_perpendicular_unit_vector():
    along_x = Vec3(1.0, 0.0, 0.0)
    obj = Counting(along_x)
    hit = hit_on(obj)
    assert hit.tangent is along_x and hit.tangent is along_x
    assert obj.calls["tangent"] == 1
    for other in (hit_on(Counting(None)), hit_on(None)):
        t = other.tangent.tolist()
        assert norm3(t) == pytest.approx(1.0, abs=1e-15)
        assert dot3(t, NORMAL.tolist()) == pytest.approx(0.0, abs=1e-15)


def test_the_frame_has_the_normal_as_z_and_the_tangent_as_x():
    hit = hit_on(Counting(Vec3(1.0, 0.3, 0.0)))  # not perpendicular: made so
    frame = hit.frame
    assert frame is hit.frame  # computed once, shared by BRDF(), pdf() and scattering()
    assert frame.w is NORMAL
    u, v = frame.u.tolist(), frame.v.tolist()
    assert dot3(u, NORMAL.tolist()) == pytest.approx(0.0, abs=1e-15)
    assert u[0] > 0.9 and norm3(u) == pytest.approx(1.0, abs=1e-15)
    assert dot3(v, u) == pytest.approx(0.0, abs=1e-15)
    # Setting the tangent (an anisotropic material's brush direction) renews the frame.
    hit.tangent = Vec3(0.0, 0.8, -0.6)
    assert hit.frame is not frame
    assert hit.frame.u.tolist() == pytest.approx([0.0, 0.8, -0.6], abs=1e-15)


def test_repr_names_the_hit():
    text = repr(hit_on(None))
    assert text.startswith("HitInfo(t=2.5") and "front_face=True" in text
