"""The scenes that ship with rtpy (the repository's scenes/ folder, installed as
the package rtpy.scenes), and turning a command-line scene argument into a file."""

from __future__ import annotations

import difflib
from pathlib import Path

from .scene_file import SceneError

__all__ = ["bundled_dir", "bundled_scenes", "resolve_scene"]


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


def resolve_scene(name_or_path: str) -> Path:
    """The scene file a command-line argument means: an existing file wins; else a
    bundled scene of that name (with or without .toml); else a SceneError."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    names = [p.stem for p in _bundled_files()]
    stem = name_or_path[:-5] if name_or_path.endswith(".toml") else name_or_path
    if stem in names:
        return bundled_dir() / f"{stem}.toml"
    matches = difflib.get_close_matches(stem, names, n=1, cutoff=0.6)
    listed = ", ".join(names) if names else "none"
    raise SceneError(
        f"no scene file '{name_or_path}' and no bundled scene of that name; bundled: {listed}",
        suggestion=matches[0] if matches else None,
    )
