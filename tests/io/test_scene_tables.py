"""Tests for rtpy.io.scene_tables: unknown keys and types, missing keys and tables
of the wrong shape are SceneErrors that name the table and key and suggest the
nearest valid name."""

from __future__ import annotations

import pytest

from .scene_text import MINIMAL, assert_names, error_of


def test_unknown_key_with_suggestion():
    text = "[camera]\nvfov = 30\nlook_att = [0, 0, 1]\n"
    err = error_of(text)
    assert_names(err, "[camera]", "look_att", "look_at")
    assert err.line == 3
    assert "(line 3)" in str(err)


def test_unknown_key_in_object_and_light():
    err = error_of(MINIMAL + "radiu = 2\n")
    assert_names(err, "[[objects]] #1", "radiu", "radius")
    err = error_of('[[lights]]\ntype = "point"\nposition = [0, 0, 0]\nintensty = [1, 1, 1]\n')
    assert_names(err, "[[lights]] #1", "intensty", "intensity")


@pytest.mark.parametrize(
    ("text", "table", "key"),
    [
        (
            '[[objects]]\ntype = "sphere"\ncenter = [0, 0, 0]\nmaterial = "m"\n',
            "[[objects]] #1",
            "radius",
        ),
        (
            '[[objects]]\ntype = "quad"\nq = [0, 0, 0]\nu = [1, 0, 0]\nmaterial = "m"\n',
            "[[objects]] #1",
            "v",
        ),
        (
            '[[objects]]\ntype = "triangle"\na = [0, 0, 0]\nb = [1, 0, 0]\nc = [0, 1, 0]\n',
            "[[objects]] #1",
            "material",
        ),
        ("[[objects]]\ncenter = [0, 0, 0]\n", "[[objects]] #1", "type"),
        ("[materials.m]\nalbedo = [1, 1, 1]\n", "[materials.m]", "type"),
        ('[materials.m]\ntype = "diffuse_light"\n', "[materials.m]", "emit"),
        ('[textures.t]\ntype = "solid"\n', "[textures.t]", "color"),
        ('[textures.t]\ntype = "checker"\neven = [0, 0, 0]\n', "[textures.t]", "odd"),
        ('[textures.t]\ntype = "image"\n', "[textures.t]", "path"),
        ('[[lights]]\ntype = "point"\nintensity = [1, 1, 1]\n', "[[lights]] #1", "position"),
        ('[[lights]]\ntype = "point"\nposition = [1, 1, 1]\n', "[[lights]] #1", "intensity"),
    ],
)
def test_missing_required_key(text, table, key):
    err = error_of('[materials.m]\ntype = "lambertian"\n' * ("materials.m" not in text) + text)
    assert_names(err, table, key)
    assert "missing" in str(err)


@pytest.mark.parametrize(
    ("text", "table", "suggestion"),
    [
        (MINIMAL.replace('"sphere"', '"sphear"'), "[[objects]] #1", "sphere"),
        (MINIMAL.replace('"lambertian"', '"lambertain"'), "[materials.red]", "lambertian"),
        ('[textures.t]\ntype = "checkers"\n', "[textures.t]", "checker"),
        ('[[lights]]\ntype = "pont"\n', "[[lights]] #1", "point"),
    ],
)
def test_unknown_type_with_suggestion(text, table, suggestion):
    err = error_of(text)
    assert_names(err, table, "type", suggestion)
    assert "unknown" in str(err)


def test_wrong_table_shapes():
    err = error_of("camera = 5\n")
    assert_names(err, "[camera]", None)
    err = error_of('[objects]\ntype = "sphere"\n')
    assert_names(err, "[[objects]]", None)
    assert "[[objects]]" in str(err)
    err = error_of("[materials]\nred = 3\n")
    assert_names(err, "[materials]", "red")
    err = error_of("objects = [1, 2]\n")
    assert_names(err, "[[objects]] #1", None)
