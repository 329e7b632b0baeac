"""Reading OBJ files with numpy: a million triangles in about a second.

rtpy/io/obj.py reads an OBJ file line by line and word by word, which is readable
and exact but costs about a microsecond a number. This reads the same files as
whole arrays of bytes, for the shapes downloaded models have: `v`, `vn`, `vt` and
`f` statements each with their numbers alone on the line, faces whose corners all
have the same form (v, v/vt, v//vn or v/vt/vn), comment lines and the statements
obj.py ignores. For anything else (a comment after numbers, a vertex weight, mixed
corner forms, an unusual character, and every error) it answers None, and obj.py
reads the text itself, with its messages and line numbers: this is only ever a
faster way to get obj.py's answer.

The shape of every line is checked at once: its bytes are classified (a number's
characters, blanks, slashes, the keyword), runs of one class collapsed, and the
result compared with the shapes allowed ("v d d d", "f d//d d//d d//d", ...). The
numbers are then parsed by numpy.fromstring, which rounds decimals correctly as
float() does (Python's own string-to-double).
"""

from __future__ import annotations

import warnings

import numpy as np

from .obj import IGNORED, ObjMesh

# Byte classes for the shape of a line: a number's characters become "d", blanks " ".
_FLOAT_CLASSES = bytearray(b"x" * 256)
_INT_CLASSES = bytearray(b"x" * 256)
for _c in b"0123456789+-":
    _FLOAT_CLASSES[_c] = _INT_CLASSES[_c] = ord("d")
for _c in b".eE":
    _FLOAT_CLASSES[_c] = ord("d")
for _table in (_FLOAT_CLASSES, _INT_CLASSES):
    for _c in b" \t\r":
        _table[_c] = ord(" ")
    for _c in b"\nvntf/":
        _table[_c] = _c
FLOAT_CLASSES, INT_CLASSES = bytes(_FLOAT_CLASSES), bytes(_INT_CLASSES)
# Characters that split words in str.split() besides " \t\r\n" (obj.py's view of a
# line): with any of them, obj.py reads the file.
SPLITTERS = b"\x0b\x0c\x1c\x1d\x1e\x1f"
WIDE_SPLITTERS = "\x85\u2028\u2029"
# The corner forms: their shape after "f", and (numbers per corner, column of the
# texture coordinate index, column of the normal index).
FORMS = {
    b" d/d/d": (3, 1, 2),
    b" d//d": (2, None, 1),
    b" d/d": (2, 1, None),
    b" d": (1, None, None),
}
V, VN, VT, F, SKIP, OTHER = range(6)
BLANK_LETTERS = bytes.maketrans(b"vntf/", b"     ")
CHUNK = 1 << 20  # bytes of text classified at a time (_shape)


def parse_obj_bytes(raw: bytes) -> ObjMesh | None:
    """The mesh in the bytes of an OBJ file (valid UTF-8), as rtpy.io.obj.parse_obj
    reads them, or None where this reader leaves the file to parse_obj."""
    if any(c in raw for c in SPLITTERS):
        return None
    if b"\r" in raw and raw.count(b"\r") != raw.count(b"\r\n"):
        return None
    if not raw.isascii() and any(c in raw.decode("utf-8") for c in WIDE_SPLITTERS):
        return None
    if not raw:
        return ObjMesh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3, 2), dtype=np.int64))
    buf = np.frombuffer(raw, dtype=np.uint8)
    newline = np.concatenate(  # by pieces, as _shape works
        [np.flatnonzero(buf[i : i + CHUNK] == 10) + i for i in range(0, len(buf), CHUNK)]
    )
    starts = np.concatenate([[0], newline + 1])
    ends = np.concatenate([newline, [len(raw)]])
    kind = _line_kinds(raw, buf, starts, ends)
    if kind is None:
        return None
    lines = [np.flatnonzero(kind == k) for k in (V, VN, VT, F)]
    positions, normals, texcoords = _vertices(raw, starts, ends, lines)
    triangles = _faces(raw, starts, ends, lines)
    if positions is None or normals is None or not texcoords or triangles is None:
        return None
    return ObjMesh(positions, normals, triangles)


def _vertices(raw, starts, ends, lines) -> tuple:
    """(positions or None, normals or None, whether the `vt` lines are readable)."""
    return (
        _vectors(raw, starts, ends, lines[V], b"v d d d\n"),
        _vectors(raw, starts, ends, lines[VN], b"vn d d d\n"),
        _texcoords(raw, starts, ends, lines[VT]),
    )


def _line_kinds(raw: bytes, buf, starts, ends) -> np.ndarray | None:
    """Each line's statement (V, VN, VT, F or SKIP), from its first bytes; the few
    other lines are read in Python: blank, a comment or an ignored statement (SKIP),
    else None (something obj.py must read: a statement after blanks, an unknown one)."""
    length = ends - starts
    last = len(buf) - 1  # (buf is not empty)
    b0, b1, b2 = (  # a line's first three bytes, a newline past its end
        np.where(length > i, buf[np.minimum(starts + i, last)], 10) for i in range(3)
    )
    blank1 = (b1 == 32) | (b1 == 9)
    blank2 = (b2 == 32) | (b2 == 9)
    v = b0 == ord("v")
    kind = np.full(len(starts), OTHER, dtype=np.int8)
    kind[v & blank1] = V
    kind[v & (b1 == ord("n")) & blank2] = VN
    kind[v & (b1 == ord("t")) & blank2] = VT
    kind[(b0 == ord("f")) & blank1] = F
    kind[b0 == ord("#")] = SKIP
    kind[(length == 0) | ((length == 1) & (b0 == 13))] = SKIP
    for i in np.flatnonzero(kind == OTHER).tolist():
        words = raw[starts[i] : ends[i]].decode("utf-8").split("#", 1)[0].split()
        if words and words[0] not in IGNORED:
            return None
        kind[i] = SKIP
    return kind


def _block(raw: bytes, starts, ends, lines: np.ndarray) -> bytes:
    """The text of the given lines, each ending with a newline."""
    if lines.size == 0:
        return b""
    # Runs of consecutive lines are one slice of the text each.
    breaks = np.flatnonzero(np.diff(lines) != 1) + 1
    first = lines[np.concatenate([[0], breaks])]
    last = lines[np.concatenate([breaks - 1, [lines.size - 1]])]
    a, b = starts[first].tolist(), ends[last].tolist()
    # Each run with the newline after it (one slice, not copied again, for one run);
    # the file's last line may have none.
    text = b"".join(raw[i : j + 1] for i, j in zip(a, b, strict=True))
    return text if text.endswith(b"\n") else text + b"\n"


def _shape(block: bytes, classes: bytes) -> bytes:
    """The block's bytes classified, then runs of number characters and of blanks
    each made one "d" or " ", blanks before a newline dropped."""
    # A megabyte of lines at a time: the arrays stay in the processor's cache, which
    # makes it five times faster than the whole block at once.
    pieces, start = [], 0
    while start < len(block):
        end = block.find(b"\n", start + CHUNK) + 1 or len(block)
        cls = np.frombuffer(block[start:end].translate(classes), dtype=np.uint8)
        keep = np.ones(len(cls), dtype=bool)
        same = cls[1:] == cls[:-1]
        keep[1:] = ~(same & ((cls[1:] == ord("d")) | (cls[1:] == 32)))
        pieces.append(cls.compress(keep).tobytes())
        start = end
    return b"".join(pieces).replace(b" \n", b"\n")


def _vectors(raw, starts, ends, lines, shape: bytes) -> np.ndarray | None:
    """(n, 3) numbers of `v` or `vn` lines of exactly three numbers, or None."""
    block = _block(raw, starts, ends, lines)
    if not block:
        return np.zeros((0, 3))
    found = _shape(block, FLOAT_CLASSES)
    if found != shape * len(lines):
        return None
    numbers = read_numbers(block, np.float64)
    if numbers is None or len(numbers) != 3 * len(lines) or not np.isfinite(numbers).all():
        return None
    return numbers.reshape(-1, 3)


def _texcoords(raw, starts, ends, lines) -> bool:
    """`vt` lines of 1 to 3 finite numbers (only counted)."""
    block = _block(raw, starts, ends, lines)
    if not block:
        return True
    found = _shape(block, FLOAT_CLASSES)
    for shape in (b"vt d d d\n", b"vt d d\n", b"vt d\n"):
        found = found.replace(shape, b"")
    numbers = read_numbers(block, np.float64)
    return found == b"" and numbers is not None and bool(np.isfinite(numbers).all())


def read_numbers(block: bytes, dtype) -> np.ndarray | None:
    """Every number of the block, its keywords and slashes read as blanks, parsed by
    numpy as float() and int() parse them (the shape checks allow only the characters
    of numbers); None if numpy cannot read one."""
    text = block.translate(BLANK_LETTERS)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns, or raises, on what it cannot read
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


def _faces(raw, starts, ends, lines) -> np.ndarray | None:
    """The (T, 3, 2) triangles of the `f` lines (fanned as obj.py fans them), their
    indices resolved against the elements defined above each line; None where a face
    is not of the first face's corner form or an index is out of range."""
    f_lines = lines[F]
    if f_lines.size == 0:
        return np.zeros((0, 3, 2), dtype=np.int64)
    block = _block(raw, starts, ends, f_lines)
    found = _shape(block, INT_CLASSES)
    form = next((f for f in FORMS if found.startswith(b"f" + f + b" ")), None)
    form = form or next((f for f in FORMS if found.startswith(b"f" + f + b"\n")), None)
    if form is None:
        return None
    per_corner, vt_col, vn_col = FORMS[form]
    marks = found.replace(form, b"C")
    if marks.translate(None, b"fC\n"):
        return None
    m = np.frombuffer(marks, dtype=np.uint8)
    newline = np.flatnonzero(m == 10)
    line_start = np.concatenate([[0], newline[:-1] + 1])
    if len(newline) != len(f_lines) or not (m[line_start] == ord("f")).all():
        return None
    corners = newline - line_start - 1
    if (corners < 3).any():
        return None
    # Integers too large for int64 come out saturated: out of range where checked.
    numbers = read_numbers(block, np.int64)
    if numbers is None or len(numbers) != per_corner * int(corners.sum()):
        return None
    numbers = numbers.reshape(-1, per_corner)

    def resolve(column, defined_lines) -> bool:
        """Make the column's indices 0-based, in place; False if one is out of range."""
        i = numbers[:, column]
        if defined_lines.size == 0 or defined_lines[-1] < f_lines[0]:
            count = defined_lines.size  # all defined above the first face: one count
        else:
            count = np.repeat(np.searchsorted(defined_lines, f_lines), corners)
        if i.min() > 0:  # no relative indices
            if (i > count).any():
                return False
            i -= 1
            return True
        k = np.where(i > 0, i - 1, count + i)
        if ((i == 0) | (k < 0) | (k >= count)).any():
            return False
        i[:] = k
        return True

    if not resolve(0, lines[V]):
        return None
    if vt_col is not None and not resolve(vt_col, lines[VT]):
        return None
    if vn_col is not None and not resolve(vn_col, lines[VN]):
        return None
    # Each corner's (position, normal or -1), made in the numbers' own array where
    # they are already side by side (v//vn: a million triangles' 48 MB not copied).
    if vn_col is None:
        pairs = np.full((len(numbers), 2), -1, dtype=np.int64)
        pairs[:, 0] = numbers[:, 0]
    elif per_corner == 2:
        pairs = numbers
    else:
        pairs = numbers[:, [0, vn_col]]
    if (corners == 3).all():
        return pairs.reshape(-1, 3, 2)
    # Fan each face of c corners from its first: (0, j, j + 1) for j = 1 .. c - 2.
    first = np.concatenate([[0], np.cumsum(corners)[:-1]])
    tris = corners - 2
    base = np.repeat(first, tris)
    j = np.arange(int(tris.sum())) - np.repeat(np.cumsum(tris) - tris, tris) + 1
    return pairs[np.stack([base, base + j, base + j + 1], axis=1)]
