"""Tests for rtpy.io.ply: PLY files in ASCII and both binary byte orders read into the
positions, normals and fanned triangles they hold; numpy's reading of whole elements
gives the record-by-record reading's answer on any bytes; every mistake is a PlyError
naming its line or record."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rtpy.io.ply import PlyError, _Columns, parse_header, parse_ply, read_ply

FORMATS = ("ascii", "binary_little_endian", "binary_big_endian")
CODES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4"}
CODES.update({"uint": "u4", "float": "f4", "double": "f8", "int32": "i4", "float64": "f8"})


def ply_bytes(fmt, elements) -> bytes:
    """A PLY file of elements [(name, [(property, type, count type or None)], records)],
    each record a list of values (a list of numbers for a list property)."""
    head = ["ply", f"format {fmt} 1.0", "comment written by tests/io/test_ply.py"]
    for name, props, records in elements:
        head.append(f"element {name} {len(records)}")
        for prop, kind, count in props:
            head.append(
                f"property list {count} {kind} {prop}" if count else f"property {kind} {prop}"
            )
    out = ("\n".join([*head, "end_header"]) + "\n").encode()
    endian = ">" if fmt == "binary_big_endian" else "<"
    for _, props, records in elements:
        for record in records:
            if fmt == "ascii":
                words = []
                for (_, _, count), value in zip(props, record, strict=True):
                    words += [str(len(value)), *map(repr, value)] if count else [repr(value)]
                out += (" ".join(words) + "\n").encode()
                continue
            for (_, kind, count), value in zip(props, record, strict=True):
                if count:
                    out += np.array(len(value), dtype=endian + CODES[count]).tobytes()
                out += np.array(value, dtype=endian + CODES[kind]).tobytes()
    return out


def square(fmt="ascii", normals=False):
    """Four vertices and one quad face: two triangles."""
    props = [("x", "float", None), ("y", "float", None), ("z", "float", None)]
    vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
    if normals:
        props += [("nx", "float", None), ("ny", "float", None), ("nz", "float", None)]
        vertices = [v + [0.0, 0.0, 1.0] for v in vertices]
    face = ("face", [("vertex_indices", "int", "uchar")], [[[0, 1, 2, 3]]])
    return ply_bytes(fmt, [("vertex", props, vertices), face])


def same(a, b) -> bool:
    """The same arrays, NaN where NaN (a changed byte can make a float NaN in both)."""
    return all(
        np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True)
        and getattr(a, k).shape == getattr(b, k).shape
        for k in ("positions", "normals", "triangles")
    )


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("normals", [False, True])
def test_a_quad_is_fanned_into_two_triangles_in_every_format(fmt, normals):
    ply = parse_ply(square(fmt, normals))
    assert ply.positions.tolist() == [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    assert ply.triangles[:, :, 0].tolist() == [[0, 1, 2], [0, 2, 3]]
    if normals:
        assert ply.normals.tolist() == [[0, 0, 1]] * 4
        assert (ply.triangles[:, :, 1] == ply.triangles[:, :, 0]).all()
    else:
        assert ply.normals.shape == (0, 3) and (ply.triangles[:, :, 1] == -1).all()


# --- any mesh, any layout ----------------------------------------------------------


@st.composite
def meshes(draw):
    """(the format, the elements, the expected positions, normals and polygons)."""
    fmt = draw(st.sampled_from(FORMATS))
    n = draw(st.integers(0, 6))
    real = draw(st.sampled_from(["float", "double", "float64"]))
    coordinate = st.floats(-1e3, 1e3, allow_nan=False, width=32 if real == "float" else 64)
    positions = [[draw(coordinate) for _ in range(3)] for _ in range(n)]
    with_normals = draw(st.booleans())
    props = [(name, real, None) for name in "xyz"]
    records = [list(p) for p in positions]
    if with_normals:
        props += [(name, real, None) for name in ("nx", "ny", "nz")]
        records = [r + list(p) for r, p in zip(records, positions, strict=True)]
    if draw(st.booleans()):  # a property the reader reads past, in some place
        at = draw(st.integers(0, len(props)))
        props.insert(at, ("red", "uchar", None))
        for r in records:
            r.insert(at, draw(st.integers(0, 255)))
    sizes = draw(st.sampled_from(["triangles", "mixed"]))
    polygons = []
    for _ in range(draw(st.integers(0, 5)) if n else 0):
        size = 3 if sizes == "triangles" else draw(st.integers(3, 5))
        polygons.append([draw(st.integers(0, n - 1)) for _ in range(size)])
    index = draw(st.sampled_from(["int", "uint", "int32"]))
    count = draw(st.sampled_from(["uchar", "ushort", "int"]))
    face_props = [("vertex_indices", index, count)]
    face_records = [[p] for p in polygons]
    if draw(st.booleans()):
        face_props.append(("flags", "short", None))
        face_records = [r + [draw(st.integers(-5, 5))] for r in face_records]
    elements = [("vertex", props, records), ("face", face_props, face_records)]
    if draw(st.booleans()):  # an element the reader reads past
        edges = [[draw(st.integers(0, 9)), [1, 2][: draw(st.integers(0, 2))]] for _ in range(2)]
        other = ("edge", [("vertex1", "int", None), ("list", "ushort", "uchar")], edges)
        elements.insert(draw(st.integers(0, 2)), other)
    return fmt, elements, positions, with_normals, polygons


def expected_triangles(polygons, with_normals):
    tris = [[p[0], p[j], p[j + 1]] for p in polygons for j in range(1, len(p) - 1)]
    p = np.array(tris, dtype=np.int64).reshape(-1, 3)
    return np.stack([p, p if with_normals else np.full_like(p, -1)], axis=2)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(meshes())
def test_any_mesh_in_any_layout_reads_as_written_by_both_readers(mesh):
    fmt, elements, positions, with_normals, polygons = mesh
    raw = ply_bytes(fmt, elements)
    fast, records = parse_ply(raw), parse_ply(raw, fast=False)
    assert same(fast, records)
    assert fast.positions.tolist() == [[float(x) for x in p] for p in positions] or not positions
    assert fast.positions.shape == (len(positions), 3)
    assert len(fast.normals) == (len(positions) if with_normals else 0)
    assert np.array_equal(fast.triangles, expected_triangles(polygons, with_normals))


def test_the_usual_files_are_read_by_numpy():
    for fmt in FORMATS:
        raw = square(fmt, normals=True)
        endian, elements, body, lines = parse_header(raw)
        assert _Columns(raw, body, elements, endian, lines).ok, fmt


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(meshes(), st.data())
def test_any_bytes_get_the_records_answer_or_its_error(mesh, data):
    """A file with some bytes changed, cut or added: numpy's reading gives the same
    mesh or the same error as the record-by-record reading, and nothing else."""
    raw = bytearray(ply_bytes(mesh[0], mesh[1]))
    for _ in range(data.draw(st.integers(1, 3))):
        at = data.draw(st.integers(0, len(raw)))
        change = data.draw(st.sampled_from(["set", "cut", "insert"]))
        byte = data.draw(st.sampled_from(b" \n\t-.e0123456789x\x00\x03\xff"))
        if change == "set" and at < len(raw):
            raw[at] = byte
        elif change == "cut":
            del raw[at : at + data.draw(st.integers(1, 8))]
        else:
            raw.insert(at, byte)
    answers = []
    for fast in (True, False):
        try:
            answers.append(parse_ply(bytes(raw), fast=fast))
        except PlyError as e:
            answers.append(str(e))
    if isinstance(answers[0], str) or isinstance(answers[1], str):
        assert answers[0] == answers[1]
    else:
        assert same(*answers)


# --- mistakes ------------------------------------------------------------------------

VERTEX = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
FACE = "element face 1\nproperty list uchar int vertex_indices\n"
BODY = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
FLAGGED = FACE.replace("face 1", "face 2") + "property uchar flags\n"


def ascii_file(header=VERTEX + FACE, body=BODY, fmt="format ascii 1.0\n") -> bytes:
    return f"ply\n{fmt}{header}end_header\n{body}".encode()


@pytest.mark.parametrize(
    "raw, words, line",
    [
        (b"plx\nformat ascii 1.0\nend_header\n", "not a PLY file", 1),
        (b"ply\nformat ascii 1.0\n", "no end_header", 3),
        (ascii_file(fmt=""), "no 'format' line", 8),
        (ascii_file(fmt="format binary_middle_endian 1.0\n"), "unknown format", 2),
        (ascii_file(fmt="format ascii 2.0\n"), "unknown format", 2),
        (ascii_file(header="property float x\n" + VERTEX + FACE), "before any element", 3),
        (ascii_file(header=VERTEX + "property float x\n" + FACE), "named twice", 7),
        (ascii_file(header="element vertex -3\n"), "expected 'element NAME COUNT'", 3),
        (ascii_file(header=VERTEX.replace("float z", "quad z") + FACE), "expected 'property", 6),
        (ascii_file(header=VERTEX + FACE.replace("uchar int", "float int")), "count must", 8),
        (ascii_file(header=VERTEX + "material 3\n" + FACE), "unknown header statement", 7),
        ("ply\nformat ascii 1.0\ncomment é\nend_header\n".encode(), "not ASCII", 3),
        (ascii_file(header=VERTEX.replace("z\n", "w\n") + FACE), "no number 'z'", None),
        (ascii_file(header=FACE, body="3 0 1 2\n"), "no 'vertex' element", None),
        (ascii_file(header=VERTEX + FACE.replace("vertex_indices", "corners")), "no list", None),
        (ascii_file(header=VERTEX + FACE.replace("int vertex", "float vertex")), "integer", None),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "index 3 is outside 0 .. 2", 13),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), "index -1 is outside", 13),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), "face 1 has 2 vertex indices", 13),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n"), "expected an integer", 13),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n"), "out of range for its type", 13),
        (ascii_file(body="0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), "fewer values", 11),
        (ascii_file(body="0 0 0\n1 0 0 0\n0 1 0\n3 0 1 2\n"), "more values", 11),
        (ascii_file(body="0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"), "expected a number, found 'x'", 11),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n"), "ends before face record 1", None),
        (ascii_file(body=BODY + "3 0 1 2\n"), "more records", 14),
        # What numpy's reading of whole elements must not take for a file of one layout:
        (ascii_file(body="0 0 0\n1 0\n0 0 1 0\n3 0 1 2\n"), "fewer values", 11),
        (ascii_file(body="0 0 0\n1 0 0\n0 1 0\n3 0 1 v2\n"), "found 'v2'", 13),
        (ascii_file(VERTEX + FLAGGED, BODY.replace("2\n", "2 0\n") + "4 0 1 2 0\n"), "fewer", 15),
    ],
)
def test_mistakes_are_errors_naming_their_line(raw, words, line):
    for fast in (True, False):
        with pytest.raises(PlyError) as caught:
            parse_ply(raw, fast=fast)
        assert words in caught.value.detail and caught.value.line == line


@pytest.mark.parametrize("fmt", FORMATS[1:])
def test_binary_data_cut_short_or_too_long_is_refused(fmt):
    raw = square(fmt)
    for bad, words in [(raw[:-1], "ends inside face record 1"), (raw + b"\0", "1 bytes after")]:
        for fast in (True, False):
            with pytest.raises(PlyError, match=words):
                parse_ply(bad, fast=fast)


def test_a_huge_count_in_the_header_is_refused_without_reading_it():
    raw = square("binary_little_endian").replace(b"vertex 4", b"vertex 4000000000000")
    with pytest.raises(PlyError, match="ends inside vertex record 6"):
        parse_ply(raw)


def test_read_ply_reads_a_file(tmp_path):
    path = tmp_path / "square.ply"
    path.write_bytes(square("binary_big_endian", normals=True))
    assert same(read_ply(path), parse_ply(square("ascii", normals=True)))
