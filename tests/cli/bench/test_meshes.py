"""Tests for rtpy.cli.bench.meshes: the UV spheres of the scene-size bench are closed,
wound outward, at least as large as asked, and read back as written."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.cli.bench.meshes import uv_sphere, write_obj, write_ply, write_scene
from rtpy.io.obj import read_obj
from rtpy.io.ply import parse_ply, read_ply


@pytest.mark.parametrize("triangles", [10, 1000, 20_000])
def test_a_uv_sphere_is_closed_and_wound_outward(triangles):
    positions, faces = uv_sphere(triangles)
    assert triangles <= len(faces) <= 1.2 * triangles + 16
    assert np.allclose(np.linalg.norm(positions, axis=1), 1.0)
    # closed: every edge is met once in each direction
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    forward = {tuple(e) for e in edges.tolist()}
    assert len(forward) == len(edges) and forward == {(b, a) for a, b in forward}
    a, b, c = (positions[faces[:, i]] for i in range(3))
    outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c)
    assert (outward > 0).all()


def test_the_obj_file_and_scene_read_back(tmp_path):
    positions, faces = uv_sphere(200)
    write_obj(tmp_path / "s.obj", positions, faces)
    obj = read_obj(tmp_path / "s.obj")
    assert np.allclose(obj.positions, positions, atol=1e-6)
    assert np.array_equal(obj.triangles[:, :, 0], faces)
    assert np.array_equal(obj.triangles[:, :, 1], faces)  # v//vn: the vertex's normal
    scene = rtpy.load_scene(write_scene(tmp_path, 200))
    assert len(scene.objects[1]) == len(faces)


def test_the_ply_file_and_scene_read_back(tmp_path):
    positions, faces = uv_sphere(200)
    write_ply(tmp_path / "s.ply", positions, faces)
    ply = read_ply(tmp_path / "s.ply")
    assert np.array_equal(ply.positions, positions.astype(np.float32))
    assert np.array_equal(ply.normals, positions.astype(np.float32))
    assert np.array_equal(ply.triangles[:, :, 0], faces)
    assert np.array_equal(ply.triangles[:, :, 1], faces)  # each vertex its normal
    # the same columns the record-by-record reader (the definition) finds
    assert np.array_equal(parse_ply((tmp_path / "s.ply").read_bytes(), fast=False).triangles,
                          ply.triangles)  # fmt: skip
    scene_file = write_scene(tmp_path, 200, ".ply")
    assert scene_file.name == "sphere_200_ply.toml"
    scene = rtpy.load_scene(scene_file)
    assert len(scene.objects[1]) == len(faces)
