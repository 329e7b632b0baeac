"""Tests for rtpy.io.bundled: the scenes that ship with rtpy, found by name."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rtpy.io import bundled
from rtpy.io.bundled import bundled_dir, bundled_scenes, resolve_scene
from rtpy.io.scene_file import SceneError, load_scene

from .scene_text import MINIMAL


def _write_scene(folder: Path, name: str, description: str | None) -> None:
    head = f"# {description}\n" if description is not None else ""
    (folder / f"{name}.toml").write_text(head + MINIMAL, encoding="utf-8")


@pytest.fixture
def fake_bundled(tmp_path, monkeypatch):
    folder = tmp_path / "bundled"
    folder.mkdir()
    _write_scene(folder, "zeta", "Last scene")
    _write_scene(folder, "alpha", "First scene: a sphere")
    _write_scene(folder, "plain", None)
    (folder / "notes.txt").write_text("not a scene")
    monkeypatch.setattr(bundled, "bundled_dir", lambda: folder)
    return folder


def test_bundled_scenes_lists_names_and_descriptions(fake_bundled):
    assert bundled_scenes() == [
        ("alpha", "First scene: a sphere"),
        ("plain", ""),
        ("zeta", "Last scene"),
    ]


def test_resolve_scene(fake_bundled, tmp_path, monkeypatch):
    assert resolve_scene("alpha") == fake_bundled / "alpha.toml"
    assert resolve_scene("alpha.toml") == fake_bundled / "alpha.toml"
    # an existing file wins over a bundled name
    monkeypatch.chdir(tmp_path)
    (tmp_path / "alpha.toml").write_text(MINIMAL, encoding="utf-8")
    assert resolve_scene("alpha.toml") == Path("alpha.toml")
    own = tmp_path / "own.toml"
    own.write_text(MINIMAL, encoding="utf-8")
    assert resolve_scene(str(own)) == own
    with pytest.raises(SceneError) as info:
        resolve_scene("zta")
    msg = str(info.value)
    assert "no scene file 'zta' and no bundled scene of that name" in msg
    assert "bundled: alpha, plain, zeta" in msg
    assert info.value.suggestion == "zeta" and "did you mean 'zeta'?" in msg


def test_bundled_dir_is_the_scenes_folder():
    folder = bundled_dir()
    assert folder.is_dir()
    assert (folder / "__init__.py").exists() or any(folder.glob("*.toml"))


REPO_SCENES = Path(__file__).resolve().parents[2] / "scenes"
BUNDLED_FILES = sorted(REPO_SCENES.glob("*.toml"))


@pytest.mark.skipif(not BUNDLED_FILES, reason="no bundled scenes yet")
def test_real_bundled_scenes_are_listed_with_descriptions():
    names = [name for name, _ in bundled_scenes()]
    assert names == sorted(names)
    if bundled_dir().resolve() == REPO_SCENES:
        assert names == [p.stem for p in BUNDLED_FILES]
    for name, description in bundled_scenes():
        assert description, f"bundled scene {name} has no '# description' first line"
        assert not description.startswith("#")


@pytest.mark.parametrize("path", BUNDLED_FILES, ids=[p.stem for p in BUNDLED_FILES])
def test_every_bundled_scene_loads(path):
    scene = load_scene(path)
    assert scene.objects, f"{path.name} has no objects"
    assert scene.name == path.stem
    assert re.fullmatch(r"#\s*\S.*", path.read_text(encoding="utf-8").splitlines()[0])
