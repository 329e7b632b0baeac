"""Tests for rtpy.io.obj: the statements read, corner forms, negative indices, fan
triangulation and the errors with their line numbers."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.io.obj import ObjError, mesh_from_obj, parse_obj, read_obj
from rtpy.materials import Lambertian
from rtpy.mesh import SmoothTriangle, Transform
from rtpy.vec3 import Vec3

SQUARE = """\
# a unit square in z = 0, as one quad face
o square
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
vt 0 0
g front
s 1
usemtl white
f 1 2 3 4
"""


def test_positions_normals_and_a_fanned_quad():
    obj = parse_obj(SQUARE)
    assert obj.positions.tolist() == [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    assert obj.normals.tolist() == [[0, 0, 1]]
    # n corners -> n - 2 triangles fanned from the first, in the file's winding; -1: no normal
    assert obj.triangles.tolist() == [[[0, -1], [1, -1], [2, -1]], [[0, -1], [2, -1], [3, -1]]]


def test_a_pentagon_becomes_three_triangles():
    text = "".join(f"v {i} {i * i} 0\n" for i in range(5)) + "f 1 2 3 4 5\n"
    tris = parse_obj(text).triangles
    assert tris[:, :, 0].tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]


@pytest.mark.parametrize(
    "face, normals",
    [
        ("f 1 2 3", [-1, -1, -1]),
        ("f 1/1 2/1 3/1", [-1, -1, -1]),
        ("f 1//1 2//2 3//1", [0, 1, 0]),
        ("f 1/1/2 2/1/1 3/1/2", [1, 0, 1]),
    ],
)
def test_corner_forms(face, normals):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 1 0\n" + face + "\n"
    ((a, b, c),) = parse_obj(text).triangles.tolist()
    assert [a[0], b[0], c[0]] == [0, 1, 2]
    assert [a[1], b[1], c[1]] == normals


def test_negative_indices_count_back_from_the_last_defined_above_the_face():
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf -3//-1 -2//-1 -1//-1\nv 5 5 5\nf -4 -3 -1\n"
    first, second = parse_obj(text).triangles.tolist()
    assert first == [[0, 0], [1, 0], [2, 0]]
    assert [p for p, _ in second] == [0, 1, 3]  # -1 is now the fourth vertex


def test_homogeneous_w_divides_the_position_and_comments_are_ignored():
    obj = parse_obj("v 2 4 6 2   # w = 2\n\n   # only a comment\n")
    assert obj.positions.tolist() == [[1, 2, 3]]


@pytest.mark.parametrize(
    "text, line, words",
    [
        ("v 0 0 0\nv 1 0\n", 2, "expected 3 to 4 numbers after 'v'"),
        ("v 0 0 zero\n", 1, "expected numbers after 'v'"),
        ("v 0 0 nan\n", 1, "finite"),
        ("v 0 0 0 0\n", 1, "w = 0"),
        ("vn 0 1\n", 1, "expected 3 numbers after 'vn'"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3 corners"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "vertex index 4 is out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "vertex index 0 is out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n", 4, "vertex index -4 is out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", 4, "normal index 1 is out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", 4, "texture coordinate index 1"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", 4, "expected an integer vertex index"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n", 4, "expected a corner"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf /1 2 3\n", 4, "expected a corner"),
        ("\n\nbogus 1 2\n", 3, "unknown statement 'bogus'"),
    ],
)
def test_malformed_lines_are_errors_with_their_line_number(text, line, words):
    with pytest.raises(ObjError) as info:
        parse_obj(text)
    assert info.value.line == line
    assert words in info.value.detail
    assert str(info.value) == f"{info.value.detail} (line {line})"


def test_read_obj_reads_a_file_and_refuses_non_utf8(tmp_path):
    path = tmp_path / "square.obj"
    path.write_text(SQUARE)
    assert len(read_obj(path).triangles) == 2
    path.write_bytes(b"v 0 0 0\nv 1 0 0 \xff\n")
    with pytest.raises(ObjError) as info:
        read_obj(path)
    assert info.value.line == 2 and "UTF-8" in str(info.value)
    with pytest.raises(FileNotFoundError):
        read_obj(tmp_path / "missing.obj")


def test_a_file_with_no_faces_is_read_as_empty():
    assert parse_obj("v 0 0 0\n").triangles.shape == (0, 3, 2)
    assert parse_obj("").positions.shape == (0, 3)


def test_mesh_from_obj_reads_a_file_into_a_mesh(tmp_path):
    """What Mesh.from_obj was: the core's Mesh no longer reads a file format."""
    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n")
    mesh = mesh_from_obj(path, Lambertian(), Transform(scale=Vec3(2, 2, 2)))
    assert [type(t) for t in mesh.triangles] == [SmoothTriangle, SmoothTriangle]
    assert mesh.triangles[1].c == Vec3(0, 2, 0)
    assert rtpy.mesh_from_obj is mesh_from_obj and len(mesh_from_obj(path, Lambertian())) == 2


@pytest.mark.parametrize("control", ["\f", "\v", "\x1c", "\x85", "\u2028"])
def test_a_comment_holding_a_form_feed_or_other_break_is_a_comment(control):
    """Lines end at \\n, \\r\\n or \\r: a form feed (or another character that
    str.splitlines takes for a line break) inside a comment leaves it one comment,
    and the line numbers of errors after it right."""
    text = f"# page one{control}page two: not a statement\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    obj = parse_obj(text)
    assert obj.triangles.shape == (1, 3, 2) and read_bytes_agree(text)
    with pytest.raises(ObjError) as caught:
        parse_obj(text + "f 1 2 x\n")
    assert caught.value.line == 6


def read_bytes_agree(text: str) -> bool:
    """The numpy reader gives parse_obj's answer (or leaves the file to it)."""
    from rtpy.io.obj_arrays import parse_obj_bytes

    fast = parse_obj_bytes(text.encode())
    return fast is None or np.array_equal(fast.triangles, parse_obj(text).triangles)
