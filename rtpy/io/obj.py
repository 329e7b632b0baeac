"""Reading Wavefront OBJ files: the positions, normals and faces of a triangle mesh.

    obj = read_obj("teapot.obj")
    obj.positions[obj.triangles[0, 0, 0]]   # the first corner of the first triangle

The statements read are `v x y z [w]`, `vn x y z`, `vt u [v [w]]` (counted, so
face indices that name texture coordinates are checked) and `f` with corners
written `v`, `v/vt`, `v//vn` or `v/vt/vn`. Indices start at 1; a negative index
counts back from the last element defined before the face (-1 is the last). A
polygon of n corners becomes n - 2 triangles fanned from its first corner.
Grouping, smoothing-group and material statements (o, g, s, usemtl, mtllib) and
the other OBJ statements that do not define faces (l, p, vp, ...) are ignored.
Anything else, or a statement that cannot be read, raises ObjError with the line.

parse_obj below is the reader's definition, line by line. read_obj hands the bytes
of a file to rtpy/io/obj_arrays.py first, which reads the usual shapes of files
with numpy, about a hundred times faster, and gives the same answer or leaves the
file to parse_obj.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..engine.user_files import read_bytes
from ..mesh import Mesh, Transform

__all__ = ["ObjError", "ObjMesh", "mesh_from_obj", "parse_obj", "read_obj"]

# Statements that define nothing this reader uses; they are skipped.
IGNORED = frozenset(
    ("o", "g", "s", "usemtl", "mtllib", "l", "p", "vp", "cstype", "deg", "bmat", "step")
    + ("curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con")
    + ("mg", "bevel", "c_interp", "d_interp", "lod", "maplib", "usemap", "shadow_obj")
    + ("trace_obj", "ctech", "stech", "call", "csh")
)

# The largest mesh file read (OBJ or PLY): a hundred million triangles and more.
MAX_MESH_BYTES = 4 << 30

# A corner: (position index, normal index or None), both 0-based.
Corner = tuple[int, int | None]


class ObjError(ValueError):
    """An OBJ file that cannot be read: detail says what is wrong, line (1-based)
    where, when it is about one line. str(error) is "detail (line N)"."""

    def __init__(self, detail: str, line: int | None = None) -> None:
        self.detail, self.line = detail, line
        super().__init__(detail if line is None else f"{detail} (line {line})")


@dataclass
class ObjMesh:
    """The geometry of an OBJ file, as numpy arrays.

    positions  (P, 3) float64: the vertex positions (x, y, z), in file order
    normals    (Q, 3) float64: the vertex normals (x, y, z) as written (not normalized)
    triangles  (T, 3, 2) int64: each triangle's three corners (position index,
               normal index or -1 for none), 0-based, in the winding order of the file
    """

    positions: Any
    normals: Any
    triangles: Any


def _numbers(words: list[str], least: int, most: int, what: str, line: int) -> list[float]:
    if not least <= len(words) <= most:
        count = str(least) if least == most else f"{least} to {most}"
        found = " ".join(words) or "nothing"
        raise ObjError(f"expected {count} numbers after '{what}', found {found!r}", line)
    try:
        values = [float(w) for w in words]
    except ValueError:
        raise ObjError(
            f"expected numbers after '{what}', found {' '.join(words)!r}", line
        ) from None
    if not all(math.isfinite(x) for x in values):
        raise ObjError(f"expected finite numbers after '{what}', found {' '.join(words)!r}", line)
    return values


def _index(word: str, count: int, what: str, line: int) -> int:
    """The 0-based index an OBJ index (1-based, or negative from the end) names."""
    try:
        i = int(word)
    except ValueError:
        raise ObjError(f"expected an integer {what} index, found {word!r}", line) from None
    k = i - 1 if i > 0 else count + i
    if i == 0 or not 0 <= k < count:
        plural = "vertices" if what == "vertex" else f"{what}s"
        raise ObjError(f"{what} index {i} is out of range ({count} {plural} defined so far)", line)
    return k


def _face(words: list[str], obj: _Lists, n_texcoords: int, line: int) -> list[Corner]:
    if len(words) < 3:
        raise ObjError(f"a face needs at least 3 corners, found {len(words)}", line)
    corners: list[Corner] = []
    for word in words:
        parts = word.split("/")
        if len(parts) > 3 or parts[0] == "":
            raise ObjError(f"expected a corner v, v/vt, v//vn or v/vt/vn, found {word!r}", line)
        p = _index(parts[0], len(obj.positions), "vertex", line)
        if len(parts) > 1 and parts[1] != "":
            _index(parts[1], n_texcoords, "texture coordinate", line)
        n = None
        if len(parts) == 3 and parts[2] != "":
            n = _index(parts[2], len(obj.normals), "normal", line)
        corners.append((p, n))
    return corners


class _Lists:
    """ObjMesh's contents while parse_obj reads them: lists of tuples."""

    def __init__(self) -> None:
        self.positions: list[tuple[float, float, float]] = []
        self.normals: list[tuple[float, float, float]] = []
        self.triangles: list[tuple[Corner, Corner, Corner]] = []


def parse_obj(text: str) -> ObjMesh:
    """The mesh in the text of an OBJ file; ObjError on a line it cannot read."""
    obj = _Lists()
    n_texcoords = 0
    # Lines end at \n, \r\n or \r only: str.splitlines would also end them at a form
    # feed or a vertical tab, which a comment may hold.
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    for number, raw in enumerate(lines, start=1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        head, rest = words[0], words[1:]
        if head == "v":
            x, y, z, *w = _numbers(rest, 3, 4, "v", number)
            if w and w[0] == 0.0:
                raise ObjError("a vertex with weight w = 0 has no position", number)
            scale = 1.0 / w[0] if w else 1.0
            obj.positions.append((x * scale, y * scale, z * scale))
        elif head == "vn":
            x, y, z = _numbers(rest, 3, 3, "vn", number)
            obj.normals.append((x, y, z))
        elif head == "vt":
            _numbers(rest, 1, 3, "vt", number)
            n_texcoords += 1
        elif head == "f":
            corners = _face(rest, obj, n_texcoords, number)
            first = corners[0]
            for b, c in zip(corners[1:-1], corners[2:], strict=True):
                obj.triangles.append((first, b, c))
        elif head not in IGNORED:
            raise ObjError(f"unknown statement {head!r}", number)
    import numpy as np

    corners = [[(p, -1 if n is None else n) for p, n in tri] for tri in obj.triangles]
    return ObjMesh(
        np.array(obj.positions, dtype=np.float64).reshape(-1, 3),
        np.array(obj.normals, dtype=np.float64).reshape(-1, 3),
        np.array(corners, dtype=np.int64).reshape(-1, 3, 2),
    )


def read_obj(path: str | Path) -> ObjMesh:
    """The mesh in an OBJ file (UTF-8 or ASCII). OSError when it cannot be read (a
    FIFO or a device is refused: rtpy.engine.user_files), ObjError when its text cannot."""
    raw = read_bytes(path, MAX_MESH_BYTES)
    if not raw.isascii():
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as e:
            line = raw[: e.start].count(b"\n") + 1
            raise ObjError(f"not UTF-8 text (byte {e.start})", line) from None
    from .obj_arrays import parse_obj_bytes

    obj = parse_obj_bytes(raw)
    return obj if obj is not None else parse_obj(raw.decode("utf-8"))


def mesh_from_obj(path: str | Path, material, transform: Transform | None = None) -> Mesh:
    """The rtpy.Mesh of an OBJ file, placed by transform (read_obj, whose ObjError
    names the line it cannot read).

        mesh = rtpy.mesh_from_obj("teapot.obj", Lambertian(), Transform(scale=Vec3(0.5, 0.5, 0.5)))
    """
    obj = read_obj(path)
    return Mesh(obj.positions, obj.normals, obj.triangles, material, transform)
