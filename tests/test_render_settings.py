"""Tests for rtpy.render_settings: one table of render settings, from which
RenderSettings, the scene loader, the command line and rtpy.render all check
their values, and so give the same answer for the same value."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rtpy
from rtpy.cli.options import UsageError
from rtpy.io.scene_file import SceneError, load_scene_text
from rtpy.render_settings import (
    RENDER_KEYS,
    SETTINGS,
    RenderSettings,
    SettingError,
)
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.vec3 import Color, Vec3

from .cli.test_main import checked_by_the_command_line
from .io.scene_text import VALUES, toml_value


def test_render_settings_fields_are_the_field_settings_with_their_defaults():
    fields = {f.name: f.default for f in dataclasses.fields(RenderSettings)}
    assert fields == {name: s.default for name, s in SETTINGS.items() if s.field}
    for setting in SETTINGS.values():
        assert setting.check(setting.default) == setting.default


def test_the_render_table_takes_exactly_the_render_keys():
    """The loader's list of valid [render] keys is the table's."""
    with pytest.raises(SceneError) as info:
        load_scene_text("[render]\nbogus = 1\n", "s.toml")
    message = str(info.value)
    listed = re.search(r"valid keys: (.*?) \(line", message).group(1).split(", ")
    assert listed == list(RENDER_KEYS)
    assert set(RENDER_KEYS) == {n for n, s in SETTINGS.items() if s.table == "render"}


def test_wrong_types_are_type_errors_and_wrong_values_value_errors_naming_the_setting():
    with pytest.raises(TypeError, match=r"^spp: expected an integer in \[1, 1000000\]"):
        RenderSettings(spp="16")
    with pytest.raises(ValueError, match=r"^spp: .*found 0$"):
        RenderSettings(spp=0)
    with pytest.raises(ValueError, match=r"^integrator: .* — did you mean 'path'\?$"):
        RenderSettings(integrator="pth")
    with pytest.raises(
        TypeError, match=r'^gamma: expected a number in \(0, 100\] or "srgb", found true$'
    ):
        RenderSettings(gamma=True)
    with pytest.raises(ValueError, match=r'^gamma: expected one of "srgb", found .*"linear"$'):
        RenderSettings(gamma="linear")
    with pytest.raises(TypeError, match=r"^spq: not a render setting .* did you mean 'spp'\?$"):
        RenderSettings().with_overrides(spq=4)
    assert RenderSettings().with_overrides(spp=None, seed=3) == RenderSettings(seed=3)


def test_gamma_is_a_number_or_srgb():
    assert RenderSettings(gamma="srgb").gamma == "srgb"
    assert RenderSettings().gamma == 2.0  # the course's display gamma stays the default


def test_numbers_are_stored_as_python_numbers():
    s = RenderSettings(spp=np.int64(4), gamma=2, max_depth=np.int32(3))
    assert (type(s.spp), type(s.gamma), type(s.max_depth)) == (int, float, int)
    assert s == RenderSettings(spp=4, gamma=2.0, max_depth=3)


def test_rtpy_render_checks_every_setting_before_rendering():
    scene = Scene([Sphere(Vec3(0, 0, -1), 0.5, rtpy.Lambertian())])
    scene.camera = rtpy.Camera(width=4)
    for options, error, name in [
        ({"spp": 2.5}, TypeError, "spp"),
        ({"max_depth": 0}, ValueError, "max_depth"),
        ({"width": 0}, ValueError, "width"),
        ({"width": "8"}, TypeError, "width"),
        ({"background": [1.0, 2.0]}, TypeError, "background"),
        ({"background": Color(-1, 0, 0)}, ValueError, "background"),
        ({"sky": 1}, TypeError, "sky"),
        ({"nee": "yes"}, TypeError, "nee"),
    ]:
        with pytest.raises(error, match=f"^{name}: expected"):
            rtpy.render(scene, **options)
    image = rtpy.render(scene, spp=1, background=Color(0.25, 0.5, 1.0), sky=False)
    assert image.linear[0, 0].tolist() == [0.25, 0.5, 1.0]


def through_scene_file(key: str, value) -> str | object:
    """The value as the scene loader reads it in its table, or its error detail."""
    table = SETTINGS[key].table
    try:
        scene = load_scene_text(f"[{table}]\n{key} = {toml_value(value)}\n", "s.toml")
    except SceneError as e:
        assert (e.table, e.key) == (f"[{table}]", key), str(e)
        return e.detail + (f" — did you mean '{e.suggestion}'?" if e.suggestion else "")
    if table == "camera":
        return scene.camera.width
    return getattr(scene.settings if SETTINGS[key].field else scene, key)


def through_api(key: str, value) -> str | object:
    try:
        return SETTINGS[key].check(value)
    except SettingError as e:
        return str(e).removeprefix(f"{key}: ")


def through_command_line(key: str, value) -> str | object:
    try:
        (checked,) = checked_by_the_command_line("--set", f"{key}={toml_value(value)}").values()
    except UsageError as e:
        return str(e).removeprefix(f"--set {key}: ")
    return checked


@settings(max_examples=300, deadline=None)
@given(key=st.sampled_from(sorted(SETTINGS)), value=VALUES)
def test_scene_file_api_and_command_line_give_the_same_answer(key, value):
    """Whatever the value, the three readers of a setting accept it as the same
    value or refuse it with the same words."""
    if SETTINGS[key].table == "camera" and isinstance(value, int) and 0 < value <= 16384:
        value = min(value, 64)  # a camera that wide is fine, but slow to build
    answers = [through_scene_file(key, value), through_api(key, value)]
    answers.append(through_command_line(key, value))
    assert answers[0] == answers[1] == answers[2], answers


@pytest.mark.parametrize(
    "key,value",
    [("spp", 0), ("spp", 10**7), ("max_depth", 501), ("integrator", "pth"), ("gamma", 0)],
)
def test_limits_are_the_same_everywhere(key, value):
    answers = {through_scene_file(key, value), through_api(key, value)}
    answers.add(through_command_line(key, value))
    (answer,) = answers
    assert answer.startswith("expected") and str(value) in answer
