"""Reading PLY files (Stanford's polygon format): the positions, normals and faces of
a triangle mesh, in ASCII or binary.

    ply = read_ply("dragon.ply")      # an ObjMesh, as read_obj gives

A PLY file is a header of text, one statement a line, then the records of its
elements in that order:

    ply
    format binary_little_endian 1.0   (or ascii 1.0, binary_big_endian 1.0)
    comment made by a scanner         (comment and obj_info lines are skipped)
    element vertex 8                  (an element and its number of records)
    property float x                  (a property of the element above it)
    property list uchar int vertex_indices
    end_header

Read are the `vertex` element's x, y and z (required) and nx, ny and nz (vertex
normals, when all three are there), and the `face` element's list `vertex_indices`
(or `vertex_index`): the 0-based indices of a polygon's vertices, fanned from its
first into triangles as OBJ faces are. Every other element and property is read
past. In ASCII a record is one line, its values read as written (as float64); in
binary they are the header's types (char, uchar, short, ushort, int, uint, float,
double, or int8 ... float64). Anything else raises PlyError naming the line (of the
header, or of an ASCII record) or the record.

parse_ply reads a record at a time in Python, and is the reader's definition. Whole
elements whose records all have one layout (every list of a property the same
length, as in a mesh of triangles) are read by numpy at once (_Columns), which gives
the same arrays a hundred times faster or leaves the file to the records.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..engine.user_files import read_bytes
from ..mesh import Mesh, Transform
from . import obj_arrays
from .obj import MAX_MESH_BYTES, ObjMesh

__all__ = ["PlyError", "mesh_from_ply", "parse_ply", "read_ply"]

TYPES = {  # the header's type names -> struct and numpy codes
    **dict.fromkeys(("char", "int8"), "b"),
    **dict.fromkeys(("uchar", "uint8"), "B"),
    **dict.fromkeys(("short", "int16"), "h"),
    **dict.fromkeys(("ushort", "uint16"), "H"),
    **dict.fromkeys(("int", "int32"), "i"),
    **dict.fromkeys(("uint", "uint32"), "I"),
    **dict.fromkeys(("float", "float32"), "f"),
    **dict.fromkeys(("double", "float64"), "d"),
}
INTEGERS = "bBhHiI"
FORMATS = {"ascii": None, "binary_little_endian": "<", "binary_big_endian": ">"}
INDICES = ("vertex_indices", "vertex_index")
NUMBER_CHARACTERS = b"0123456789+-.eE \t\n\r\x0b\x0c"


class PlyError(ValueError):
    """A PLY file that cannot be read: detail says what is wrong, line (1-based)
    where, when it is about one line. str(error) is "detail (line N)"."""

    def __init__(self, detail: str, line: int | None = None) -> None:
        self.detail, self.line = detail, line
        super().__init__(detail if line is None else f"{detail} (line {line})")


@dataclass
class Property:
    name: str
    type: str  # a struct code (TYPES)
    count_type: str | None = None  # a list's count type; None for one value


@dataclass
class Element:
    name: str
    count: int
    properties: list[Property]


def read_ply(path: str | Path) -> ObjMesh:
    """The mesh in a PLY file. OSError when it cannot be read (a FIFO or a device is
    refused: rtpy.engine.user_files), PlyError when its contents cannot."""
    return parse_ply(read_bytes(path, MAX_MESH_BYTES))


def mesh_from_ply(path: str | Path, material, transform: Transform | None = None) -> Mesh:
    """The rtpy.Mesh of a PLY file, placed by transform (read_ply's PlyError names
    what it cannot read)."""
    ply = read_ply(path)
    return Mesh(ply.positions, ply.normals, ply.triangles, material, transform)


def parse_ply(raw: bytes, fast: bool = True) -> ObjMesh:
    """The mesh in the bytes of a PLY file; fast=False reads every record in Python
    (the definition, which the fast reading is tested against)."""
    endian, elements, body, lines = parse_header(raw)
    columns = _Columns(raw, body, elements, endian, lines) if fast else None
    if columns is None or not columns.ok:
        columns = _Records(raw, body, elements, endian, lines)
    return _mesh(elements, columns)


def parse_header(raw: bytes) -> tuple[str | None, list[Element], int, int]:
    """(the byte order: "<", ">" or None for ASCII, the elements, the offset of the
    first record, the number of header lines)."""
    endian, elements, pos, number = "", [], 0, 0
    while True:
        end = raw.find(b"\n", pos)
        if end < 0:
            raise PlyError("the header has no end_header line", number + 1)
        number += 1
        try:
            words = raw[pos:end].decode("ascii").split()
        except UnicodeDecodeError:
            raise PlyError("the header is not ASCII text", number) from None
        pos = end + 1
        if number == 1:
            if words != ["ply"]:
                raise PlyError("not a PLY file: the first line is not 'ply'", 1)
            continue
        head = words[0] if words else ""
        if head == "end_header" and len(words) == 1:
            break
        if head in ("comment", "obj_info"):
            continue
        if head == "format":
            if endian != "" or elements:
                raise PlyError("'format' must come once, before the elements", number)
            if len(words) != 3 or words[1] not in FORMATS or words[2] != "1.0":
                raise PlyError(f"unknown format {' '.join(words[1:])!r}", number)
            endian = FORMATS[words[1]]
        elif head == "element":
            if len(words) != 3 or not words[2].isdigit() or not words[2].isascii():
                raise PlyError("expected 'element NAME COUNT'", number)
            elements.append(Element(words[1], int(words[2]), []))
        elif head == "property":
            if not elements:
                raise PlyError("a property before any element", number)
            prop = _property(words, number)
            if any(p.name == prop.name for p in elements[-1].properties):
                raise PlyError(f"property {prop.name!r} is named twice", number)
            elements[-1].properties.append(prop)
        else:
            raise PlyError(f"unknown header statement {' '.join(words)!r}", number)
    if endian == "":
        raise PlyError("the header has no 'format' line", number)
    return endian, elements, pos, number


def _property(words: list[str], number: int) -> Property:
    if len(words) == 3 and words[1] in TYPES:
        return Property(words[2], TYPES[words[1]])
    if len(words) == 5 and words[1] == "list" and words[2] in TYPES and words[3] in TYPES:
        if TYPES[words[2]] not in INTEGERS:
            raise PlyError(f"a list's count must be an integer type, not {words[2]!r}", number)
        return Property(words[4], TYPES[words[3]], TYPES[words[2]])
    raise PlyError("expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'", number)


def _record_line(lines: int, elements: list[Element], element: str, k: int) -> int:
    """The line of record k (0-based) of an element, in an ASCII file."""
    before = 0
    for e in elements:
        if e.name == element:
            return lines + before + k + 1
        before += e.count
    raise AssertionError(element)


class _Records:
    """Every record read in Python: values[element][property] is the list of its
    values (one number, or a list of numbers, a record)."""

    def __init__(self, raw: bytes, body: int, elements: list[Element], endian, lines: int):
        self.values: dict[str, dict[str, list]] = {}
        self.ascii, self.lines = endian is None, lines
        if self.ascii:
            self._ascii(raw[body:].split(b"\n"), elements)
        else:
            self._binary(raw, body, elements, endian)

    def _ascii(self, text: list[bytes], elements: list[Element]) -> None:
        number = 0
        for e in elements:
            values = self.values[e.name] = {p.name: [] for p in e.properties}
            for k in range(e.count):
                if number >= len(text) or (number == len(text) - 1 and not text[number]):
                    raise PlyError(f"the file ends before {e.name} record {k + 1}")
                words, at = text[number].split(), 0
                number += 1
                line = self.lines + number
                for p in e.properties:
                    if p.count_type is None:
                        values[p.name].append(_word(words, at, p.type, e, line))
                        at += 1
                        continue
                    n = _word(words, at, p.count_type, e, line)
                    if n < 0:
                        raise PlyError(f"{e.name} {p.name}: a list of {n} values", line)
                    items = [_word(words, at + 1 + i, p.type, e, line) for i in range(n)]
                    values[p.name].append(items)
                    at += 1 + n
                if at != len(words):
                    raise PlyError(f"{e.name} record {k + 1}: more values than properties", line)
        for rest in text[number:]:
            number += 1
            if rest.strip():
                raise PlyError("more records than the header's elements count", self.lines + number)

    def _binary(self, raw: bytes, pos: int, elements: list[Element], endian: str) -> None:
        for e in elements:
            values = self.values[e.name] = {p.name: [] for p in e.properties}
            for k in range(e.count):
                try:
                    for p in e.properties:
                        if p.count_type is None:
                            (v,) = struct.unpack_from(endian + p.type, raw, pos)
                            pos += struct.calcsize(p.type)
                            values[p.name].append(v)
                            continue
                        (n,) = struct.unpack_from(endian + p.count_type, raw, pos)
                        pos += struct.calcsize(p.count_type)
                        if n < 0:
                            raise PlyError(f"{e.name} record {k + 1}: {p.name} has {n} values")
                        items = struct.unpack_from(f"{endian}{n}{p.type}", raw, pos)
                        pos += n * struct.calcsize(p.type)
                        values[p.name].append(list(items))
                except struct.error:
                    raise PlyError(f"the file ends inside {e.name} record {k + 1}") from None
        if pos != len(raw):
            raise PlyError(f"{len(raw) - pos} bytes after the last element's records")

    def column(self, element: str, name: str):
        return self.values[element][name]

    def line(self, elements: list[Element], element: str, k: int) -> int | None:
        return _record_line(self.lines, elements, element, k) if self.ascii else None


def _word(words: list[bytes], at: int, code: str, e: Element, line: int) -> int | float:
    if at >= len(words):
        raise PlyError(f"{e.name} record: fewer values than properties", line)
    w = words[at]
    try:
        if code not in INTEGERS:
            return float(w)
        value = int(w)
    except ValueError:
        kind = "an integer" if code in INTEGERS else "a number"
        raise PlyError(
            f"{e.name}: expected {kind}, found {w.decode(errors='replace')!r}", line
        ) from None
    low, high = _range(code)
    if not low <= value <= high:
        raise PlyError(f"{e.name}: {value} is out of range for its type", line)
    return value


def _range(code: str) -> tuple[int, int]:
    info = np.iinfo(np.dtype(code))
    return int(info.min), int(info.max)


class _Columns:
    """Every element read by numpy, where each of its records has one layout: a
    list property's length is that of the first record's list. ok is False where
    some record differs, or anything is unusual: _Records then reads the file."""

    def __init__(self, raw: bytes, body: int, elements: list[Element], endian, lines: int):
        self.values: dict[str, dict[str, np.ndarray]] = {}
        self.lines, self.ascii = lines, endian is None
        self.ok = self._read(raw, body, elements, endian)

    def _read(self, raw, pos, elements, endian) -> bool:
        if self.ascii:
            text = raw[pos:]
            ends = np.flatnonzero(np.frombuffer(text, dtype=np.uint8) == 10)
            start = 0
            for e in elements:
                if len(ends) < start + e.count:
                    return False
                block = text[
                    (0 if start == 0 else int(ends[start - 1]) + 1) : (
                        int(ends[start + e.count - 1]) + 1 if e.count else 0
                    )
                ]
                if not self._ascii_element(e, block):
                    return False
                start += e.count
            rest = text[int(ends[start - 1]) + 1 :] if start else text
            return not rest.strip()
        for e in elements:
            layout = _layout(raw, pos, e, endian)
            if layout is None:
                return False
            dtype, lists = layout
            if len(raw) - pos < dtype.itemsize * e.count:
                return False
            rows = np.frombuffer(raw, dtype=dtype, count=e.count, offset=pos)
            pos += dtype.itemsize * e.count
            if any((rows[f"{name} count"] != n).any() for name, n in lists.items()):
                return False
            self.values[e.name] = {p.name: rows[p.name] for p in e.properties}
        return pos == len(raw)

    def _ascii_element(self, e: Element, block: bytes) -> bool:
        if e.count == 0:
            self.values[e.name] = {
                p.name: np.zeros((0, 0) if p.count_type else 0) for p in e.properties
            }
            return True
        if block.translate(None, NUMBER_CHARACTERS):  # a word numpy might misread
            return False
        numbers = obj_arrays.read_numbers(block, np.float64)
        if numbers is None:
            return False
        width = _words_per_line(block, e.count)
        if width is None or numbers.size != width * e.count:
            return False
        rows, at, out = numbers.reshape(e.count, width), 0, {}
        for p in e.properties:
            if at >= width:
                return False
            if p.count_type is not None:
                n = rows[0, at]
                if not (rows[:, at] == n).all() or not 0 <= n <= width - at - 1:
                    return False
                if not _fits(rows[:, at], p.count_type):
                    return False
                values = rows[:, at + 1 : at + 1 + int(n)]
                at += 1 + int(n)
            else:
                values = rows[:, at]
                at += 1
            if p.type in INTEGERS:
                if not _fits(values, p.type):
                    return False
                values = values.astype(np.int64)
            out[p.name] = values
        self.values[e.name] = out
        return at == width

    def column(self, element: str, name: str):
        return self.values[element][name]

    def line(self, elements: list[Element], element: str, k: int) -> int | None:
        return _record_line(self.lines, elements, element, k) if self.ascii else None


def _fits(values: np.ndarray, code: str) -> bool:
    """Whole numbers in the range of the integer type (floats read from ASCII)."""
    low, high = _range(code)
    return bool(((values == np.floor(values)) & (values >= low) & (values <= high)).all())


def _words_per_line(block: bytes, count: int) -> int | None:
    """The number of words on each of the block's lines, when all have the same."""
    b = np.frombuffer(block, dtype=np.uint8)
    blank = (b == 32) | ((b >= 9) & (b <= 13))
    starts = np.flatnonzero(~blank & np.concatenate([[True], blank[:-1]]))
    newline = np.flatnonzero(b == 10)
    per_line = np.bincount(np.searchsorted(newline, starts), minlength=count)
    if len(per_line) != count or not (per_line == per_line[0]).all():
        return None
    return int(per_line[0])


def _layout(raw: bytes, pos: int, e: Element, endian: str):
    """(the numpy record type of the element's records, each list's length) as the
    first record has them; None where a record cannot be read at pos."""
    fields, lists = [], {}
    for p in e.properties:
        if p.count_type is None:
            fields.append((p.name, endian + p.type))
            pos += struct.calcsize(p.type)
            continue
        if e.count == 0:
            n = 0
        else:
            try:
                (n,) = struct.unpack_from(endian + p.count_type, raw, pos)
            except struct.error:
                return None
        if n < 0 or n * struct.calcsize(p.type) > len(raw) - pos:
            return None  # (_Records says where the file ends)
        fields.append((f"{p.name} count", endian + p.count_type))
        fields.append((p.name, endian + p.type, (n,)))
        lists[p.name] = n
        pos += struct.calcsize(p.count_type) + n * struct.calcsize(p.type)
    return np.dtype(fields), lists


def _check_finite(array: np.ndarray, names: str, read, elements: list[Element]) -> None:
    """PlyError naming the first vertex record whose `names` are not all finite."""
    bad = np.flatnonzero(~np.isfinite(array).all(axis=1))
    if bad.size:
        k = int(bad[0])
        values = " ".join(repr(float(v)) for v in array[k])
        raise PlyError(
            f"vertex {k + 1}: expected finite numbers for {names}, found {values}",
            read.line(elements, "vertex", k),
        )


def _mesh(elements: list[Element], read) -> ObjMesh:
    """The ObjMesh of the vertex and face elements' values (_Records or _Columns)."""
    found = {e.name: e for e in elements}
    vertex = found.get("vertex")
    if vertex is None:
        raise PlyError("the file has no 'vertex' element")
    props = {p.name: p for p in vertex.properties}
    for name in ("x", "y", "z"):
        if name not in props or props[name].count_type is not None:
            raise PlyError(f"the vertex element has no number {name!r}")
    positions = np.stack(
        [np.asarray(read.column("vertex", n), dtype=np.float64).reshape(-1) for n in "xyz"], 1
    ).reshape(-1, 3)
    normals = np.zeros((0, 3))
    if all(n in props and props[n].count_type is None for n in ("nx", "ny", "nz")):
        normals = np.stack(
            [
                np.asarray(read.column("vertex", n), dtype=np.float64).reshape(-1)
                for n in ("nx", "ny", "nz")
            ],
            1,
        ).reshape(-1, 3)
    for array, names in ((positions, "x, y, z"), (normals, "nx, ny, nz")):
        _check_finite(array, names, read, elements)
    face = found.get("face")
    if face is None or face.count == 0:
        return ObjMesh(positions, normals, np.zeros((0, 3, 2), dtype=np.int64))
    names = [p.name for p in face.properties if p.count_type is not None and p.name in INDICES]
    if not names:
        raise PlyError("the face element has no list 'vertex_indices'")
    if next(p for p in face.properties if p.name == names[0]).type not in INTEGERS:
        raise PlyError("the face element's vertex_indices must be of an integer type")
    lists = read.column("face", names[0])
    count = len(positions)
    if isinstance(lists, np.ndarray):
        polygons = lists.astype(np.int64).reshape(face.count, -1)
        sizes = np.full(face.count, polygons.shape[1])
    else:
        sizes = np.array([len(f) for f in lists], dtype=np.int64)
        polygons = None
    small = np.flatnonzero(sizes < 3)
    if small.size:
        k = int(small[0])
        raise PlyError(
            f"face {k + 1} has {int(sizes[k])} vertex indices, at least 3 are needed",
            read.line(elements, "face", k),
        )
    if polygons is not None:
        flat, first = polygons.reshape(-1), np.arange(face.count) * polygons.shape[1]
    else:
        flat = np.fromiter((i for f in lists for i in f), dtype=np.int64, count=int(sizes.sum()))
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    bad = np.flatnonzero((flat < 0) | (flat >= count))
    if bad.size:
        k = int(np.searchsorted(first, bad[0], side="right") - 1)
        raise PlyError(
            f"face {k + 1}: vertex index {int(flat[bad[0]])} is outside 0 .. {count - 1}",
            read.line(elements, "face", k),
        )
    if polygons is not None and polygons.shape[1] == 3:
        p = polygons
        n = p if len(normals) else np.full_like(p, -1)
        return ObjMesh(positions, normals, np.stack([p, n], axis=2))
    # Fan each polygon of c vertices from its first: (0, j, j + 1) for j = 1 .. c - 2.
    tris = sizes - 2
    base = np.repeat(first, tris)
    j = np.arange(int(tris.sum())) - np.repeat(np.cumsum(tris) - tris, tris) + 1
    p = flat[np.stack([base, base + j, base + j + 1], axis=1)]
    n = p if len(normals) else np.full_like(p, -1)
    return ObjMesh(positions, normals, np.stack([p, n], axis=2))
