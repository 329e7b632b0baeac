"""Tests for rtpy.io.mesh_cache: a large mesh is built once and read back, a changed
file or transform is built again, and the cache never stops a render."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from rtpy.cli.bench.meshes import uv_sphere, write_obj
from rtpy.io import mesh_cache
from rtpy.io.mesh_cache import cache_folder, load_mesh
from rtpy.materials import Lambertian
from rtpy.mesh import Transform
from rtpy.ray import Ray
from rtpy.vec3 import Vec3

MAT = Lambertian()


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache of its own, keeping meshes of 100 faces and more."""
    monkeypatch.setenv("RTPY_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("RTPY_MESH_CACHE", raising=False)
    monkeypatch.setattr(mesh_cache, "MIN_FACES", 100)
    return tmp_path / "cache" / "meshes"


def sphere_file(tmp_path, triangles=200):
    path = tmp_path / f"sphere{triangles}.obj"
    write_obj(path, *uv_sphere(triangles))
    return path


def entries(cache) -> list:
    if not cache.exists():
        return []
    return sorted(p for p in cache.iterdir() if not p.name.startswith("."))


def same_mesh(a, b) -> None:
    for name in ("vertices", "normals", "faces", "face_normals"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    for name in ("lo", "hi", "child", "count", "axis", "order"):
        assert np.array_equal(getattr(a.tree, name), getattr(b.tree, name))
    ray = Ray(Vec3(0.1, 0.2, 5.0), Vec3(0.0, 0.0, -1.0))
    assert a.hit_t(ray, 0.0, math.inf) == b.hit_t(ray, 0.0, math.inf)
    assert a.skipped == b.skipped


def test_a_large_mesh_is_built_once_and_read_back(tmp_path, cache, monkeypatch):
    path = sphere_file(tmp_path)
    built, faces = load_mesh(path, MAT, Transform())
    assert len(entries(cache)) == 1 and faces == len(built)

    def no_reading(path, material, transform):
        raise AssertionError("read again")

    monkeypatch.setattr(mesh_cache, "mesh_from_obj", no_reading)
    again, faces_again = load_mesh(path, MAT, Transform())
    same_mesh(again, built)
    assert faces_again == faces and again.material is MAT


def test_small_meshes_are_not_kept(tmp_path, cache):
    load_mesh(sphere_file(tmp_path, 50), MAT, Transform())
    assert entries(cache) == []


def test_a_changed_file_or_transform_is_built_again(tmp_path, cache):
    path = sphere_file(tmp_path)
    load_mesh(path, MAT, Transform())
    placed, _ = load_mesh(path, MAT, Transform(scale=Vec3(2, 2, 2)))
    assert len(entries(cache)) == 2 and placed.vertices.max() == pytest.approx(2.0)
    write_obj(path, *uv_sphere(300))  # another mesh in the same file
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    changed, faces = load_mesh(path, MAT, Transform())
    assert faces == len(uv_sphere(300)[1]) and len(entries(cache)) == 3


def test_the_cache_can_be_turned_off(tmp_path, cache, monkeypatch):
    monkeypatch.setenv("RTPY_MESH_CACHE", "0")
    assert cache_folder() is None
    load_mesh(sphere_file(tmp_path), MAT, Transform())
    assert entries(cache) == []


def test_a_damaged_entry_is_built_again(tmp_path, cache):
    path = sphere_file(tmp_path)
    built, _ = load_mesh(path, MAT, Transform())
    (entry,) = entries(cache)
    (entry / "order.npy").write_bytes(b"not an array")
    again, _ = load_mesh(path, MAT, Transform())
    same_mesh(again, built)


def huge_header(path) -> None:
    """Rewrite the .npy file at path with a header declaring 10^12 float64."""
    header = {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}
    with open(path, "wb") as f:
        np.lib.format.write_array_header_1_0(f, header)


DAMAGES = {
    "an emptied array file": lambda entry: (entry / "vertices.npy").write_bytes(b""),
    "a header declaring a huge shape": lambda entry: huge_header(entry / "faces.npy"),
    "a header declaring a few more bytes": lambda entry: np.save(
        entry / "order.npy", np.load(entry / "order.npy")[:-1]
    ),
    "metadata that is a list": lambda entry: (entry / "meta.json").write_text("[1, 2]"),
    "metadata with a string count": lambda entry: (entry / "meta.json").write_text(
        '{"faces": "200", "skipped": 0}'
    ),
    "metadata without its keys": lambda entry: (entry / "meta.json").write_text("{}"),
    "faces naming vertices that are not there": lambda entry: np.save(
        entry / "faces.npy", np.load(entry / "faces.npy") + 10**6
    ),
    "metadata nested deeper than Python recurses": lambda entry: (entry / "meta.json").write_text(
        "[" * 20000 + "]" * 20000
    ),
    "a vertex that is not a number": lambda entry: np.save(
        entry / "vertices.npy", np.load(entry / "vertices.npy") * np.nan
    ),
    "a tree node whose children are not there": lambda entry: np.save(
        entry / "child.npy", np.load(entry / "child.npy") + 10**6
    ),
    "index arrays of floats": lambda entry: np.save(
        entry / "faces.npy", np.load(entry / "faces.npy").astype(float)
    ),
    "an array file that is a FIFO": lambda entry: (
        (entry / "lo.npy").unlink(),
        os.mkfifo(entry / "lo.npy"),
    ),
}


@pytest.mark.parametrize("damage", DAMAGES)
def test_every_kind_of_damaged_entry_is_built_again(tmp_path, cache, damage):
    if damage.endswith("FIFO") and not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this system")
    path = sphere_file(tmp_path)
    built, faces = load_mesh(path, MAT, Transform())
    (entry,) = entries(cache)
    DAMAGES[damage](entry)
    again, faces_again = load_mesh(path, MAT, Transform())
    same_mesh(again, built)
    assert faces_again == faces


def test_a_cache_that_cannot_be_written_does_not_stop_the_render(tmp_path, monkeypatch):
    blocked = tmp_path / "file"
    blocked.write_text("a file where the cache folder would be")
    monkeypatch.setenv("RTPY_CACHE", str(blocked))
    monkeypatch.setattr(mesh_cache, "MIN_FACES", 100)
    mesh, _ = load_mesh(sphere_file(tmp_path), MAT, Transform())
    assert len(mesh) > 100


def test_the_least_recently_used_entries_go_first(tmp_path, cache, monkeypatch):
    first = sphere_file(tmp_path, 200)
    load_mesh(first, MAT, Transform())
    (entry,) = entries(cache)
    size = sum(f.stat().st_size for f in entry.iterdir())
    monkeypatch.setattr(mesh_cache, "MAX_BYTES", int(2.5 * size))
    load_mesh(first, MAT, Transform(scale=Vec3(2, 2, 2)))
    os.utime(entry / "meta.json", (1, 1))  # the first entry: used long ago
    load_mesh(first, MAT, Transform(scale=Vec3(3, 3, 3)))
    kept = entries(cache)
    assert len(kept) == 2 and entry not in kept
