"""Tests for rtpy.testing.local_setup: the flat surface of the material checks."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Lambertian
from rtpy.testing import brdf_between, draw_samples, incident_ray, local_direction, local_hit
from rtpy.vec3 import Vec3

from .materials_to_check import DiffuseTransmitter


def test_local_setup():
    ray = incident_ray(30.0)
    assert ray.direction.tolist() == pytest.approx([-0.5, 0.0, -math.sqrt(3) / 2], abs=1e-15)
    ray = incident_ray(60.0, 90.0)
    assert ray.direction.tolist() == pytest.approx([0.0, -math.sqrt(3) / 2, -0.5], abs=1e-15)
    hit = local_hit(Lambertian())
    assert hit.normal.tolist() == [0.0, 0.0, 1.0]
    assert hit.tangent.tolist() == [1.0, 0.0, 0.0]
    assert hit.front_face and hit.point.tolist() == [0.0, 0.0, 0.0]
    assert not local_hit(Lambertian(), inside=True).front_face  # the viewer inside


class Recorder(DiffuseTransmitter):
    """Records the hits and directions its BRDF is asked about."""

    def __init__(self) -> None:
        super().__init__()
        self.calls = []

    def BRDF(self, ray_view, ray_light, hit):
        self.calls.append((ray_view.direction, ray_light.direction, hit.normal, hit.front_face))
        return super().BRDF(ray_view, ray_light, hit)


def test_brdf_between_turns_the_setup_over_for_a_viewer_below():
    m = Recorder()
    wo, wi = local_direction(30.0, 20.0), local_direction(120.0, 200.0)
    assert brdf_between(m, wo, wi).e0 == pytest.approx(0.5 / math.pi)
    below = Vec3(wi.e0, wi.e1, wi.e2)
    assert brdf_between(m, below, wo, inside=False).e0 == pytest.approx(0.5 / math.pi)
    (d1, l1, n1, f1), (d2, l2, n2, f2) = m.calls
    assert (n1.tolist(), f1) == ([0.0, 0.0, 1.0], True)
    assert (d1.tolist(), l1.tolist()) == ([-c for c in wo.tolist()], wi.tolist())
    # The viewer below sees the other face: half a turn about x puts it above.
    assert (n2.tolist(), f2) == ([0.0, 0.0, 1.0], False)
    assert d2.tolist() == pytest.approx([-wi.e0, wi.e1, wi.e2], abs=1e-15)
    assert l2.tolist() == pytest.approx([wo.e0, -wo.e1, -wo.e2], abs=1e-15)


def test_samples_from_inside_are_drawn_on_their_own_stream():
    a = draw_samples(DiffuseTransmitter(), 30.0, 200)
    b = draw_samples(DiffuseTransmitter(), 30.0, 200, inside=True)
    assert not a.inside and b.inside
    assert not (a.directions == b.directions).all()
    assert a.transmitted.any() and b.transmitted.any()
