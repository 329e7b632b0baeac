"""Scene-file text for the tests: a valid scene, a TOML writer for parsed scene
files (inline forms only), hypothesis strategies of the values a scene file can
hold, and loading text with a check of the error it raises."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import strategies as st

from rtpy.io.scene_file import SceneError, load_scene_text
from rtpy.scene import Scene

# A valid scene: one red ball.
MINIMAL = """\
[materials.red]
type = "lambertian"
albedo = [0.5, 0.1, 0.1]

[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "red"
"""


def toml_value(v) -> str:
    """A TOML literal for a Python value (inline forms only)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(data: dict) -> str:
    lines = []
    for name, value in data.items():
        if isinstance(value, dict) and all(isinstance(x, dict) for x in value.values()) and value:
            for sub, table in value.items():
                lines.append(f"[{json.dumps(name)}.{json.dumps(sub)}]")
                lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in table.items()]
        elif isinstance(value, dict):
            lines.append(f"[{json.dumps(name)}]")
            lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in value.items()]
        elif isinstance(value, list) and value and all(isinstance(x, dict) for x in value):
            for table in value:
                lines.append(f"[[{json.dumps(name)}]]")
                lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in table.items()]
        else:
            lines.insert(0, f"{json.dumps(name)} = {toml_value(value)}")
    return "\n".join(lines) + "\n"


SCALARS = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, 1, -1, 2, 3, 16384, 16385, 10**6, 10**6 + 1]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 0.5, 1.0, 1.5, 179.99, 180.0, 1e-300, 1e300]),
    st.text(alphabet=st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=8),
    st.sampled_from(["16:9", "1:0", "0:1", "path", "sphere", "red", "board", "image", "x"]),
)
VALUES = st.one_of(
    SCALARS,
    st.lists(SCALARS, max_size=4),
    st.lists(
        st.floats(allow_nan=False, allow_infinity=False, min_value=-10, max_value=10),
        min_size=3,
        max_size=3,
    ),
    st.lists(st.sampled_from([0, 1, 0.0, 1.0, 0.5]), min_size=3, max_size=3),
    st.dictionaries(st.sampled_from(["type", "a", "x"]), SCALARS, max_size=2),
)


FILE = Path("some/dir/test_scene.toml")  # where messages say the text comes from


def load(text: str, path: Path = FILE) -> Scene:
    return load_scene_text(text, path)


def error_of(text: str, path: Path = FILE) -> SceneError:
    with pytest.raises(SceneError) as info:
        load_scene_text(text, path)
    return info.value


def assert_names(err: SceneError, table: str, key: str | None, suggestion: str | None = None):
    """The message names the file, the table and the key (and the suggestion)."""
    msg = str(err)
    assert str(FILE) in msg
    assert err.file == str(FILE)
    assert err.table == table
    assert table in msg
    if key is not None:
        assert err.key == key
        assert f"{table} {key}:" in msg
    if suggestion is not None:
        assert err.suggestion == suggestion
        assert f"did you mean '{suggestion}'?" in msg
    # one message, one line
    assert "\n" not in msg


def line_of(text: str, needle: str, occurrence: int = 1) -> int:
    hits = [i + 1 for i, line in enumerate(text.splitlines()) if line.strip().startswith(needle)]
    return hits[occurrence - 1]
