"""Tests for rtpy.testing.local_setup: the flat surface of the material checks."""

from __future__ import annotations

import math

import pytest

from rtpy.materials import Lambertian
from rtpy.testing import incident_ray, local_hit


def test_local_setup():
    ray = incident_ray(30.0)
    assert ray.direction.tolist() == pytest.approx([-0.5, 0.0, -math.sqrt(3) / 2], abs=1e-15)
    ray = incident_ray(60.0, 90.0)
    assert ray.direction.tolist() == pytest.approx([0.0, -math.sqrt(3) / 2, -0.5], abs=1e-15)
    hit = local_hit(Lambertian())
    assert hit.normal.tolist() == [0.0, 0.0, 1.0]
    assert hit.tangent.tolist() == [1.0, 0.0, 0.0]
    assert hit.front_face and hit.point.tolist() == [0.0, 0.0, 0.0]
