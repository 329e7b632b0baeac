"""rtpy.materials.Material: what every material has by default, and the registry of
materials by the names scene files use."""

from __future__ import annotations

import math

import pytest

import rtpy.materials as materials
from rtpy.materials import MATERIALS, Dielectric, DiffuseLight, Lambertian, Metal, Mirror
from rtpy.materials.material import Material, as_texture, check_strengths
from rtpy.texture import CheckerTexture, SolidColor
from rtpy.vec3 import BLACK, WHITE, Color

from .directions import ALBEDO_COLOR, POINT, UP, incoming, leaving, make_hit


def test_non_emitters_emit_nothing():
    for m in (Lambertian(ALBEDO_COLOR), Mirror(), Metal(), Dielectric()):
        assert m.emitting(make_hit(m, UP)).tolist() == [0.0, 0.0, 0.0]
        assert m.is_emitter is False


def test_registry_names():
    assert MATERIALS["lambertian"] is Lambertian
    assert MATERIALS["mirror"] is Mirror
    assert MATERIALS["metal"] is Metal
    assert MATERIALS["dielectric"] is Dielectric
    assert MATERIALS["diffuse_light"] is DiffuseLight


def test_every_bundled_scene_file_type_is_exported_from_rtpy():
    """A material a scene file can name can be made in Python as rtpy.<Class>."""
    import rtpy

    for name, cls in MATERIALS.items():
        assert getattr(rtpy, cls.__name__, None) is cls, f"{name}: rtpy.{cls.__name__} missing"
        assert cls.__name__ in rtpy.__all__


def test_the_base_class_scatters_reflects_and_emits_nothing():
    m = Material()
    hit = make_hit(m, UP)
    view, light = incoming((1, -1, 0), hit), leaving((0, 1, 0), hit)
    assert m.scattering(view, hit) is None
    assert m.BRDF(view, light, hit) == BLACK and m.pdf(view, light, hit) == 0.0
    assert m.emitting(hit) == BLACK and m.specular_rays(view, hit) == []
    assert m.is_specular is False and m.is_emitter is False


def test_flat_color_is_the_albedo_where_there_is_one_else_white():
    board = CheckerTexture(1.0, Color(1, 0, 0), Color(0, 0, 1))
    assert Material().flat_color(make_hit(Material(), UP)) == WHITE
    for albedo, point, expected in (
        (ALBEDO_COLOR, POINT, ALBEDO_COLOR),
        (board, (0.5, 0.5, 0.5), Color(1, 0, 0)),
        (board, (1.5, 0.5, 0.5), Color(0, 0, 1)),
    ):
        m = Lambertian(albedo)
        assert m.flat_color(make_hit(m, UP, point=point)) == expected
    assert isinstance(as_texture(ALBEDO_COLOR), SolidColor) and as_texture(board) is board


@pytest.mark.parametrize(
    "kd, ks, message",
    [
        (-0.1, 0.0, r"^kd: expected a number in \[0, 1\]"),
        (0.5, 1.01, r"^ks: expected a number in \[0, 1\]"),
        (0.5, math.inf, r"^ks: expected a finite number"),
        (math.nan, 0.0, r"^kd: expected a finite number"),
        ("1", 0, "^kd: "),
    ],
)
def test_lobe_strengths_are_numbers_in_0_1(kd, ks, message):
    with pytest.raises((TypeError, ValueError), match=message):
        check_strengths(kd, ks)
    assert check_strengths(1, 0) == (1.0, 0.0) and type(check_strengths(1, 0)[0]) is float


def test_register_material_makes_a_class_a_scene_file_type(monkeypatch):
    monkeypatch.setattr(materials, "MATERIALS", dict(MATERIALS))

    @materials.register_material("half_grey")
    class HalfGrey(Lambertian):
        pass

    assert materials.MATERIALS["half_grey"] is HalfGrey and "half_grey" not in MATERIALS
