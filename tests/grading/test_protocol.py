"""The wire between the judge and the student's process (rtpy.grading.protocol): plain
data round-trips; code, objects, oversize and malformed messages are refused; answers
are checked against their form before a verdict sees them."""

from __future__ import annotations

import base64
import io
import json
import pickle
import struct

import numpy as np
import pytest

from rtpy.grading import protocol as p


def roundtrip(value):
    frame = p.encode(value)
    (size,) = struct.unpack(">I", frame[:4])
    assert size == len(frame) - 4
    return p.read_frame(io.BytesIO(frame))


def test_plain_data_and_numeric_arrays_round_trip_exactly():
    a = np.random.default_rng(1).normal(size=(4, 3))
    got = roundtrip({"x": 1.5, "n": None, "ok": True, "list": [1, "two", [3.0]], "a": a})
    assert got["x"] == 1.5 and got["n"] is None and got["ok"] is True
    assert got["list"] == [1, "two", [3.0]]
    assert got["a"].dtype == np.float64 and np.array_equal(got["a"], a)  # bit for bit
    assert np.isnan(roundtrip(float("nan")))


@pytest.mark.parametrize(
    "value", [object(), {1: 2}, np.array(["text"]), np.array([object()]), {"$npy": "x"}, b"raw"]
)
def test_what_is_not_plain_data_cannot_be_sent(value):
    with pytest.raises(TypeError):
        p.encode(value)


def frame_of(body: bytes) -> io.BytesIO:
    return io.BytesIO(struct.pack(">I", len(body)) + body)


def npy_of(array: np.ndarray, allow_pickle: bool = False) -> str:
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=allow_pickle)
    return base64.b64encode(buffer.getvalue()).decode()


def npy_lying_about_its_shape() -> str:
    """A .npy whose header declares 10**12 float64 and holds 8 bytes."""
    raw = base64.b64decode(npy_of(np.zeros(1)))
    return base64.b64encode(raw.replace(b"(1,)", b"(1000000000000,)")).decode()


@pytest.mark.parametrize(
    "body",
    [
        b"not json",
        b"[" * 100 + b"]" * 100,  # nested past MAX_DEPTH
        json.dumps({"$npy": npy_of(np.array([object()], dtype=object), True)}).encode(),
        json.dumps({"$npy": base64.b64encode(pickle.dumps(print)).decode()}).encode(),
        json.dumps({"$npy": npy_of(np.array(["abc"]))}).encode(),
        json.dumps({"$npy": "!!!not base64"}).encode(),
        json.dumps({"$npy": npy_lying_about_its_shape()}).encode(),
    ],
)
def test_malformed_or_code_carrying_messages_are_refused(body):
    with pytest.raises(p.ProtocolError):
        p.read_frame(frame_of(body))


def test_a_frame_announcing_more_than_the_limit_is_refused_unread():
    stream = io.BytesIO(struct.pack(">I", p.MAX_FRAME + 1))
    with pytest.raises(p.ProtocolError, match="announced"):
        p.read_frame(stream)
    with pytest.raises(p.ProtocolError, match="closed"):
        p.read_frame(io.BytesIO(struct.pack(">I", 10) + b"{}"))  # cut short


def test_answers_are_checked_against_their_form():
    form = p.List(p.Maybe(p.Record(t=p.Float, n=p.Vec, ok=p.Bool)))
    got = p.check(form, [None, {"t": 2, "n": [0, 0, 1], "ok": False}])
    assert got[0] is None and got[1].t == 2.0 and isinstance(got[1].t, float)
    assert got[1].n.tolist() == [0.0, 0.0, 1.0]
    for wrong, what in [
        ([{"t": "2", "n": [0, 0, 1], "ok": False}], r"\[0\]\.t: expected a number"),
        ([{"t": True, "n": [0, 0, 1], "ok": False}], "expected a number"),  # bool is no number
        ([{"t": 2, "n": [0, 1], "ok": False}], r"expected shape \(3,\)"),
        ([{"t": 2, "n": [0, 0, 1]}], "expected the fields"),
        ({"t": 2}, "expected a list"),
        ([{"t": 2, "n": [0, 0, 1], "ok": 1}], "expected true or false"),
    ]:
        with pytest.raises(p.ProtocolError, match=what):
            p.check(form, wrong)
    assert p.check(p.Array((None, 2)), np.zeros((5, 2), dtype=np.int32)).dtype == np.float64
    with pytest.raises(p.ProtocolError):
        p.check(p.Array((None, 2)), np.zeros((5, 3)))


def test_text_shown_to_students_is_bounded_and_printable():
    text = p.check(p.Text, "a\x1b[2Jb" + "x" * 2000)
    assert len(text) == p.MAX_TEXT and "\x1b" not in text and text.endswith("...")


def test_a_reply_is_read_only_up_to_what_its_form_allows():
    """A reply with more values than the form asked for (for that many cases) is
    refused before it is parsed; one within it is read."""
    form = p.List(p.Maybe(p.Record(t=p.Float, n=p.Vec)))
    answer = [{"t": 1.5, "n": [0.0, 0.0, 1.0]}] * 50
    values = p.most_values(form, 50)
    assert p.read_frame(io.BytesIO(p.encode(answer)), values=values) == answer
    assert p.read_frame(io.BytesIO(p.encode(answer * 20)), values=p.most_values(form, 1000))
    with pytest.raises(p.ProtocolError, match="values asked for"):
        p.read_frame(io.BytesIO(p.encode(answer * 1000)), values=values)
    assert p.most_values(p.Float, None) == p.TEXT_SLACK + 1
    assert p.most_values(p.List(p.Float), None) == p.TEXT_SLACK + p.MAX_VALUES  # open
    with pytest.raises(p.ProtocolError, match="announced"):
        p.read_frame(io.BytesIO(p.encode(answer)), limit=100)


def test_only_the_answer_itself_is_as_long_as_the_cases():
    """An inner list of open length (samples of each case) is not bounded by the number
    of cases: 2 cases of 5000 samples each are read."""
    form = p.List(p.List(p.Vec))
    answer = [[[0.0, 0.0, 1.0]] * 5000] * 2
    got = p.read_frame(io.BytesIO(p.encode(answer)), values=p.most_values(form, 2))
    assert len(got) == 2 and len(got[0]) == 5000
