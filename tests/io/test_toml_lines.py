"""Tests for rtpy.io.toml_lines: scene errors give the line of the key or table,
for syntax errors too."""

from __future__ import annotations

from rtpy.io.toml_lines import TomlLines, Where

from .scene_text import MINIMAL, assert_names, error_of, line_of


def test_toml_syntax_error_with_line_number():
    text = "[camera]\nwidth = 400\nvfov = 40 degrees\n"
    err = error_of(text)
    assert_names(err, "[camera]", "vfov")
    assert err.line == 3
    assert "TOML syntax error" in str(err) and "(line 3)" in str(err)


def test_toml_syntax_error_in_array_of_tables():
    text = MINIMAL + MINIMAL.split("\n\n", 1)[1].replace("radius = 0.5", "radius = 0.5.5")
    err = error_of(text)
    assert_names(err, "[[objects]] #2", "radius")
    assert err.line == line_of(text, "radius = 0.5.5")


def test_toml_duplicate_key_is_a_syntax_error():
    err = error_of("[render]\nspp = 1\nspp = 2\n")
    assert_names(err, "[render]", "spp")
    assert err.line == 3


def test_line_numbers_for_a_semantic_error():
    text = (
        "# comment\n\n[camera]\nwidth = 100\n\n"
        + MINIMAL
        + "\n"
        + MINIMAL.split("\n\n", 1)[1]
        + "\n"
        + MINIMAL.split("\n\n", 1)[1].replace("radius = 0.5", "radius = -2")
    )
    err = error_of(text)
    assert_names(err, "[[objects]] #3", "radius")
    assert err.line == line_of(text, "radius = -2")
    assert f"(line {err.line})" in str(err)


def test_line_number_falls_back_to_the_header_for_missing_keys():
    text = MINIMAL + "\n[materials.x]\n# nothing here\n"
    err = error_of(text)
    assert err.key == "type" and err.line == line_of(text, "[materials.x]")


def test_line_number_for_inline_tables():
    text = "camera = { width = 10, vfov = 400 }\n"
    err = error_of(text)
    assert_names(err, "[camera]", "vfov")
    assert err.line == 1


TEXT = """\
# a comment
width = 3
[camera]
vfov = 40
[materials.glass]
type = "dielectric"
[[objects]]
type = "sphere"
[[objects]]
"type" = "quad"
material = { name = "x" }
"""


def test_locate_finds_keys_in_tables_and_in_arrays_of_tables():
    lines = TomlLines(TEXT)
    assert lines.locate(("camera",), None, "vfov") == 4
    assert lines.locate(("camera",), None, "width") == 3  # not there: the header
    assert lines.locate(("materials", "glass"), None, "type") == 6
    assert lines.locate(("objects",), 0, "type") == 8
    assert lines.locate(("objects",), 1, "type") == 10  # a quoted key
    assert lines.locate(("objects",), 1, "material") == 11
    assert lines.locate((), None, "width") == 2  # before any header
    assert lines.locate(("render",), None, "spp") is None


def test_context_names_the_table_and_key_of_a_line():
    lines = TomlLines(TEXT)
    assert lines.context(4) == ("[camera]", "vfov")
    assert lines.context(7) == ("[[objects]] #1", None)
    assert lines.context(10) == ("[[objects]] #2", "type")
    assert lines.context(1) == (None, None)


def test_where_labels_tables_as_messages_show_them():
    assert Where.table("materials", "my glass").label == '[materials."my glass"]'
    assert Where.array("objects", 2).label == "[[objects]] #3"
    assert Where.array("objects", 2).index == 2
