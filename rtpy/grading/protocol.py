"""The wire between the judge and the process that runs a student's code.

Only plain data crosses it, in a format that cannot carry code or objects: each
message is one frame, a 4-byte big-endian length and that many bytes of JSON. Numbers,
strings, booleans, None, lists and dicts with string keys travel as themselves; a
numpy array travels as {"$npy": base64 of its .npy bytes}, read back with
`allow_pickle=False` and only for numeric and boolean dtypes. A frame longer than
MAX_FRAME, JSON nested deeper than MAX_DEPTH, or anything else the decoder does not
expect is a ProtocolError: the judge treats the child as broken, never as right.

The judge states what shape an answer must have with the schema types at the bottom
(`Float`, `Vec`, `Array`, `List`, `Record`, `Maybe`); `check(schema, value)` returns
the value converted (floats, numpy arrays, namespaces) or raises ProtocolError naming
what was wrong, so that a verdict only ever sees well-formed numbers.
"""

from __future__ import annotations

import base64
import io
import json
import struct
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

MAX_FRAME = 256 * 1024 * 1024  # bytes of one message
REPLY_FRAME = 64 * 1024 * 1024  # bytes of one reply (a probe's largest answer is far smaller)
MAX_VALUES = 2**20  # JSON values of a reply whose form does not bound them
TEXT_SLACK = 10_000  # commas a reply may hold in its text (an exception's message, traceback)
MAX_DEPTH = 32  # nesting of lists and dicts
MAX_TEXT = 500  # characters of a string the judge shows (a student's exception message)
NUMERIC = "biuf"  # the dtype kinds an array may have: bool, int, unsigned, float


class ProtocolError(Exception):
    """A message that breaks the protocol: too long, cut short, or not of the form
    expected."""


# --- encoding ---------------------------------------------------------------------
def _plain(value, depth: int = 0):
    """value as JSON-ready plain data (arrays as {"$npy": ...}); TypeError otherwise."""
    if depth > MAX_DEPTH:
        raise TypeError("nested too deeply")
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int | float) and type(value) in (int, float, bool):
        return value
    if isinstance(value, np.generic) and value.dtype.kind in NUMERIC:
        return value.item()
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in NUMERIC:
            raise TypeError(f"an array of dtype {value.dtype} cannot be sent")
        buffer = io.BytesIO()
        np.save(buffer, np.ascontiguousarray(value), allow_pickle=False)
        return {"$npy": base64.b64encode(buffer.getvalue()).decode("ascii")}
    if isinstance(value, list | tuple):
        return [_plain(v, depth + 1) for v in value]
    if isinstance(value, dict):
        out = {}
        for key, v in value.items():
            if type(key) is not str or key == "$npy":
                raise TypeError(f"dict keys must be strings, got {key!r}")
            out[key] = _plain(v, depth + 1)
        return out
    raise TypeError(f"a {type(value).__name__} is not plain data")


def encode(value) -> bytes:
    """The frame carrying `value` (plain data; TypeError for anything else)."""
    body = json.dumps(_plain(value), separators=(",", ":"), allow_nan=True).encode("utf-8")
    if len(body) > MAX_FRAME:
        raise TypeError(f"a message of {len(body):,} bytes is longer than {MAX_FRAME:,}")
    return struct.pack(">I", len(body)) + body


def _restore(value, depth: int = 0):
    if depth > MAX_DEPTH:
        raise ProtocolError("data nested too deeply")
    if isinstance(value, list):
        return [_restore(v, depth + 1) for v in value]
    if isinstance(value, dict):
        if set(value) == {"$npy"}:
            return _array(value["$npy"])
        return {k: _restore(v, depth + 1) for k, v in value.items()}
    return value


def _array(text) -> np.ndarray:
    if not isinstance(text, str):
        raise ProtocolError("an array that is not base64 text")
    try:
        array = np.load(io.BytesIO(base64.b64decode(text, validate=True)), allow_pickle=False)
    except Exception as err:  # any malformed .npy
        raise ProtocolError(f"an array that cannot be read ({type(err).__name__})") from None
    if not isinstance(array, np.ndarray) or array.dtype.kind not in NUMERIC:
        raise ProtocolError("an array of a dtype that is not numeric")
    if array.dtype.fields is not None or array.ndim > 8:
        raise ProtocolError("an array of a structured dtype or of too many dimensions")
    return array


def decode(body: bytes):
    """The plain data of one frame's body; ProtocolError when it is not valid."""
    try:
        value = json.loads(body.decode("utf-8"))
    except (ValueError, RecursionError) as err:
        raise ProtocolError(f"not valid JSON ({type(err).__name__})") from None
    return _restore(value)


# --- frames on streams -------------------------------------------------------------
def write_frame(stream, frame: bytes) -> None:
    """Write one frame to a binary stream and flush it."""
    stream.write(frame)
    stream.flush()


def _exactly(stream, size: int) -> bytearray:
    data = bytearray(size)
    view, got = memoryview(data), 0
    while got < size:
        n = stream.readinto(view[got:])
        if not n:
            raise ProtocolError("the other side closed the connection")
        got += n
    return data


def read_frame(stream, limit: int = MAX_FRAME, values: int | None = None):
    """The data of the next frame of a binary stream (blocking); ProtocolError when the
    stream ends or the frame is not valid."""
    return read_body(stream, read_size(stream), limit, values)


def read_size(stream) -> int:
    """The size a frame announces (blocking until it comes)."""
    return struct.unpack(">I", _exactly(stream, 4))[0]


def read_body(stream, size: int, limit: int = MAX_FRAME, values: int | None = None):
    """The data of a frame's body of `size` bytes. A frame announcing more than `limit`
    bytes is refused unread; one holding more than `values` commas (JSON values, plus
    text) is refused before it is parsed."""
    if size > limit:
        raise ProtocolError(f"a message of {size:,} bytes announced, at most {limit:,}")
    body = _exactly(stream, size)
    if values is not None and body.count(b",") > values:
        raise ProtocolError(f"a message holding more than the {values:,} values asked for")
    return decode(body)


def most_values(schema: Schema | None, items: int | None) -> int:
    """The commas a reply of this form may hold: its JSON values (`items`: the number
    of cases asked, the length of the answer when it is a list whose form leaves it
    open), plus TEXT_SLACK for text; MAX_VALUES where the form bounds nothing."""
    found = _values(schema, items) if schema is not None else None
    return TEXT_SLACK + (MAX_VALUES if found is None else min(found, MAX_VALUES))


def _values(schema: Schema, items: int | None) -> int | None:
    if isinstance(schema, _Float | _Int | _Bool | _Text):
        return 1
    if isinstance(schema, Array):  # base64 (no comma), or nested lists of the shape
        total = 1
        for n in schema.shape:
            if n is None:
                return None
            total *= n + 1
        return total
    if isinstance(schema, List):  # `items` is the outermost list's length alone
        one, length = _values(schema.item, None), schema.length or items
        return None if one is None or length is None else length * (one + 1)
    if isinstance(schema, Record):
        parts = [_values(s, None) for s in schema.fields.values()]
        return None if None in parts else sum(parts) + len(parts)
    if isinstance(schema, Maybe):
        return _values(schema.item, items)
    return None


# --- what an answer must look like --------------------------------------------------
class Schema:
    """The form of a value in an answer (see check)."""

    def check(self, value, where: str):
        raise NotImplementedError


def _fail(where: str, wanted: str, value) -> ProtocolError:
    shown = type(value).__name__ if not isinstance(value, np.ndarray) else f"array {value.shape}"
    return ProtocolError(f"{where}: expected {wanted}, got {shown}")


class _Float(Schema):
    def check(self, value, where):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _fail(where, "a number", value)
        return float(value)


class _Int(Schema):
    def check(self, value, where):
        if isinstance(value, bool) or not isinstance(value, int):
            raise _fail(where, "a whole number", value)
        return value


class _Bool(Schema):
    def check(self, value, where):
        if not isinstance(value, bool):
            raise _fail(where, "true or false", value)
        return value


class _Text(Schema):
    def check(self, value, where):
        if not isinstance(value, str):
            raise _fail(where, "text", value)
        return printable(value)


Float, Int, Bool, Text = _Float(), _Int(), _Bool(), _Text()


@dataclass(frozen=True)
class Array(Schema):
    """A numeric array converted to `dtype`; `shape` lists each axis's length, None for
    any length (also given as nested lists of numbers)."""

    shape: tuple[int | None, ...]
    dtype: str = "float64"

    def check(self, value, where):
        if isinstance(value, list):
            try:
                value = np.array(value, dtype=np.float64)
            except (ValueError, TypeError):
                raise _fail(where, "an array of numbers", value) from None
        if not isinstance(value, np.ndarray):
            raise _fail(where, "an array", value)
        if value.ndim != len(self.shape) or any(
            want is not None and got != want
            for got, want in zip(value.shape, self.shape, strict=True)
        ):
            raise ProtocolError(f"{where}: expected shape {self.shape}, got {value.shape}")
        if self.dtype == "bool":
            if value.dtype.kind != "b":
                raise ProtocolError(f"{where}: expected true/false values, got {value.dtype}")
            return value.astype(bool)
        return value.astype(self.dtype)


Vec = Array((3,))  # a Vec3 or Color: three numbers


@dataclass(frozen=True)
class List(Schema):
    item: Schema
    length: int | None = None  # exactly this many, when given

    def check(self, value, where):
        if not isinstance(value, list):
            raise _fail(where, "a list", value)
        if self.length is not None and len(value) != self.length:
            raise ProtocolError(f"{where}: expected {self.length} items, got {len(value)}")
        return [self.item.check(v, f"{where}[{k}]") for k, v in enumerate(value)]


class Record(Schema):
    """A dict with exactly these keys, read as a namespace (record.key)."""

    def __init__(self, **fields: Schema) -> None:
        self.fields = fields

    def check(self, value, where):
        if not isinstance(value, dict):
            raise _fail(where, "a record", value)
        if set(value) != set(self.fields):
            raise ProtocolError(f"{where}: expected the fields {sorted(self.fields)}")
        return SimpleNamespace(
            **{k: s.check(value[k], f"{where}.{k}") for k, s in self.fields.items()}
        )


@dataclass(frozen=True)
class Maybe(Schema):
    """None, or a value of `item`."""

    item: Schema

    def check(self, value, where):
        return None if value is None else self.item.check(value, where)


class _Plain(Schema):
    """Plain data of any form (for an answer the verdict inspects itself)."""

    def check(self, value, where):
        return value


Plain = _Plain()


def check(schema: Schema, value, where: str = "the answer"):
    return schema.check(value, where)


def printable(text: str, limit: int = MAX_TEXT) -> str:
    """text without control characters (newlines kept), at most `limit` characters."""
    text = "".join(c if c.isprintable() or c == "\n" else "?" for c in text)
    return text if len(text) <= limit else text[: limit - 3] + "..."
