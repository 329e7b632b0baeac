"""The scenes that ship with rtpy (the repository's scenes/ folder, installed as
the package rtpy.scenes), and turning a command-line scene argument into a file."""

from __future__ import annotations

import difflib
from pathlib import Path

from .scene_file import SceneError

__all__ = ["bundled_dir", "bundled_scenes", "is_path", "resolve_scene"]


def bundled_dir() -> Path:
    """The folder that holds the bundled *.toml scene files."""
    try:
        from importlib.resources import files

        folder = files("rtpy.scenes")
        path = Path(str(folder))
        if path.is_dir():
            return path
    except (ImportError, TypeError, ValueError):
        pass
    # A source checkout (or an editable install that does not map rtpy.scenes).
    return Path(__file__).resolve().parents[2] / "scenes"


def _description(path: Path) -> str:
    """The first line of the file when it is a comment, without the '# '."""
    try:
        with path.open(encoding="utf-8") as f:
            first = f.readline().strip()
    except (OSError, UnicodeDecodeError):
        return ""
    if not first.startswith("#"):
        return ""
    return first.lstrip("#").strip()


def _bundled_files() -> list[Path]:
    folder = bundled_dir()
    if not folder.is_dir():
        return []
    return sorted((p for p in folder.glob("*.toml") if p.is_file()), key=lambda p: p.stem)


def bundled_scenes() -> list[tuple[str, str]]:
    """(name, description) of every bundled scene, sorted by name."""
    return [(p.stem, _description(p)) for p in _bundled_files()]


def is_path(argument: str) -> bool:
    """Does a scene argument name a file (a suffix or a folder in it), not a bundled
    scene? Such an argument never means a bundled scene."""
    return bool(Path(argument).suffix) or any(sep in argument for sep in ("/", "\\"))


def _nearby(path: Path) -> list[str]:
    """The scene files beside a missing path, as the path would name them."""
    folder = path.parent
    try:
        found = sorted(p.name for p in folder.glob("*.toml") if p.is_file())
    except OSError:
        return []
    return [str(folder / name) if str(folder) != "." else name for name in found]


def resolve_scene(name_or_path: str) -> Path:
    """The scene file a command-line argument means: an existing file; else, for a
    bare name (no suffix, no folder), the bundled scene of that name; else a
    SceneError saying what is missing, with the closest bundled name or nearby file
    (a bundled week scene also by its short name: "phong" -> "week08_phong")."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    names = [p.stem for p in _bundled_files()]
    if not is_path(name_or_path) and name_or_path in names:
        return bundled_dir() / f"{name_or_path}.toml"
    stem = path.stem if is_path(name_or_path) else name_or_path
    short = {name.partition("_")[2]: name for name in names if name.startswith("week")}
    if stem in names or stem in short:
        suggestion = stem if stem in names else short[stem]
    else:
        nearby = _nearby(path) if is_path(name_or_path) else []
        candidates = {**{n: n for n in names}, **short, **{Path(f).stem: f for f in nearby}}
        matches = difflib.get_close_matches(stem, list(candidates), n=1, cutoff=0.6)
        suggestion = candidates[matches[0]] if matches else None
    listed = ", ".join(names) if names else "none"
    what = f"no scene file '{name_or_path}'"
    if is_path(name_or_path):
        what += " (a path, never a bundled scene)"
    else:
        what += " and no bundled scene of that name"
    raise SceneError(f"{what}; bundled: {listed}", suggestion=suggestion)
