"""rtpy.materials.DiffuseLight: an area light's emission."""

from __future__ import annotations

from rtpy.materials import DiffuseLight
from rtpy.vec3 import Color

from .directions import UP, incoming, make_hit


def test_diffuse_light_emits_from_front_face_only():
    emit = Color(3.0, 2.0, 1.0)
    m = DiffuseLight(emit)
    assert m.is_emitter is True
    front = make_hit(m, UP, front_face=True)
    back = make_hit(m, UP, front_face=False)
    assert m.emitting(front).tolist() == [3.0, 2.0, 1.0]
    assert m.emitting(back).tolist() == [0.0, 0.0, 0.0]
    assert m.scattering(incoming((0, -1, 0), front), front) is None
    assert m.flat_color(front).tolist() == [1.0, 1.0, 1.0]


def test_two_sided_diffuse_light_emits_from_both_faces():
    m = DiffuseLight(Color(3.0, 2.0, 1.0), two_sided=True)
    assert m.emitting(make_hit(m, UP, front_face=True)).tolist() == [3.0, 2.0, 1.0]
    assert m.emitting(make_hit(m, UP, front_face=False)).tolist() == [3.0, 2.0, 1.0]
