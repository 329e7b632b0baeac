"""What the scripts that generate bundled scenes share: numbers and vectors written as
TOML, and writing the file into scenes/."""

from __future__ import annotations

from pathlib import Path

SCENES = Path(__file__).resolve().parent.parent / "scenes"

Vec = tuple[float, float, float]


def fmt(x: float) -> str:
    """A number rounded to 6 decimals, without trailing zeros or a negative zero."""
    s = f"{round(float(x), 6):.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def vec(v: Vec) -> str:
    return "[" + ", ".join(fmt(c) for c in v) + "]"


def write_scene(name: str, description: str, text: str) -> None:
    """Write scenes/<name>; the description (the file's first line) is what
    `python -m rtpy scenes` lists, so it must stay short."""
    assert len(description) < 70
    SCENES.mkdir(exist_ok=True)
    path = SCENES / name
    path.write_text(text, encoding="utf-8", newline="\n")
    print(f"wrote {path}")
