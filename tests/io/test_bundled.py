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
    monkeypatch.chdir(tmp_path)
    assert resolve_scene("alpha") == fake_bundled / "alpha.toml"
    # an existing file wins over a bundled name
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


@pytest.mark.parametrize("argument", ["alpha.toml", "./alpha", "sub/alpha.toml", "sub\\alpha"])
def test_a_path_is_never_a_bundled_scene(fake_bundled, tmp_path, monkeypatch, argument):
    """A missing file is refused (the bundled scene of its name only suggested), so a
    render never overwrites the output of one's own scene with a bundled one's."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError) as info:
        resolve_scene(argument)
    assert str(info.value).startswith(f"no scene file '{argument}' (a path, never a bundled")
    assert info.value.suggestion == "alpha"


def test_a_misspelt_path_is_offered_the_file_beside_it(fake_bundled, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "my_room.toml").write_text(MINIMAL, encoding="utf-8")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "glass_balls.toml").write_text(MINIMAL, encoding="utf-8")
    with pytest.raises(SceneError) as info:
        resolve_scene("my_rom.toml")
    assert info.value.suggestion == "my_room.toml"
    with pytest.raises(SceneError) as info:
        resolve_scene("sub/glass_ball.toml")
    assert info.value.suggestion == str(Path("sub") / "glass_balls.toml")


def test_a_week_scene_is_suggested_by_its_short_name(fake_bundled, tmp_path, monkeypatch):
    _write_scene(fake_bundled, "week08_phong", "Week 8: Phong balls")
    monkeypatch.chdir(tmp_path)
    for argument in ("phong", "phong.toml", "phnog"):
        with pytest.raises(SceneError) as info:
            resolve_scene(argument)
        assert info.value.suggestion == "week08_phong", argument


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
