"""The meshes of the scene-size bench (scripts/bench_scene_size.py, docs/performance.md):
a UV sphere of about n triangles with its vertex normals, written as an OBJ file or
as a binary PLY file (the form downloaded scans come in), on a ground sphere under
the sky. Made on the fly, never committed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def uv_sphere(triangles: int) -> tuple[np.ndarray, np.ndarray]:
    """(positions (P, 3), faces (T, 3) 0-based) of the unit sphere cut into s slices
    around y and s // 2 stacks, s the smallest count giving at least `triangles`
    triangles (2 s (stacks - 1) of them), wound counterclockwise seen from outside."""
    slices = 3
    while 2 * slices * (max(2, slices // 2) - 1) < triangles:
        slices += 1
    stacks = max(2, slices // 2)
    theta = np.linspace(0.0, np.pi, stacks + 1)[1:-1]  # the rings between the poles
    phi = np.linspace(0.0, 2.0 * np.pi, slices, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1)
    positions = np.concatenate([[[0.0, 1.0, 0.0]], ring.reshape(-1, 3), [[0.0, -1.0, 0.0]]])
    j = np.arange(slices)
    jn = (j + 1) % slices
    south = len(positions) - 1

    def at(i, k):  # vertex k of ring i
        return 1 + i * slices + k

    caps = [
        np.stack([np.zeros(slices, dtype=np.int64), at(0, jn), at(0, j)], 1),
        np.stack([np.full(slices, south), at(stacks - 2, j), at(stacks - 2, jn)], 1),
    ]
    bands = []
    for i in range(stacks - 2):
        a, b, c, d = at(i, j), at(i, jn), at(i + 1, j), at(i + 1, jn)
        bands += [np.stack([a, b, d], 1), np.stack([a, d, c], 1)]
    return positions, np.concatenate([caps[0], *bands, caps[1]])


def write_obj(path: Path, positions: np.ndarray, faces: np.ndarray) -> None:
    """An OBJ file of the positions, their normals (the unit sphere's: the positions)
    and the faces, corners written v//vn."""
    v = "v {:.7g} {:.7g} {:.7g}\n".format
    vn = "vn {:.7g} {:.7g} {:.7g}\n".format
    f = "f {0}//{0} {1}//{1} {2}//{2}\n".format
    xyz = positions.T.tolist()
    with open(path, "w") as out:
        out.write(f"# a UV sphere of {len(faces)} triangles (rtpy/cli/bench/meshes.py)\n")
        out.write("".join(map(v, *xyz)))
        out.write("".join(map(vn, *xyz)))
        out.write("".join(map(f, *(faces + 1).T.tolist())))


def write_ply(path: Path, positions: np.ndarray, faces: np.ndarray) -> None:
    """A binary little-endian PLY file of the positions and their normals (the
    positions), as float32, and the faces as lists of three int32 indices."""
    vertex = np.empty(len(positions), dtype="<f4, <f4, <f4, <f4, <f4, <f4")
    for i, column in enumerate(np.concatenate([positions, positions], axis=1).T):
        vertex[f"f{i}"] = column
    face = np.empty(len(faces), dtype=[("n", "u1"), ("v", "<i4", 3)])
    face["n"], face["v"] = 3, faces
    header = [
        "ply",
        "format binary_little_endian 1.0",
        f"comment a UV sphere of {len(faces)} triangles (rtpy/cli/bench/meshes.py)",
        f"element vertex {len(positions)}",
        *(f"property float {name}" for name in ("x", "y", "z", "nx", "ny", "nz")),
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    with open(path, "wb") as out:
        out.write(("\n".join(header) + "\n").encode())
        out.write(vertex.tobytes())
        out.write(face.tobytes())


SCENE = """\
# A UV sphere of {triangles} triangles read from {mesh}, on a ground sphere, under the sky
[camera]
look_from = [0, 1.2, 4]
look_at = [0, 0.2, 0]
vfov = 30
aspect_ratio = 1.7777777777777777
width = 128

[render]
sky = true
max_depth = 4
spp = 16

[materials.ground]
type = "lambertian"
albedo = [0.5, 0.5, 0.5]

[materials.model]
type = "lambertian"
albedo = [0.8, 0.3, 0.2]

[[objects]]
type = "sphere"
center = [0, -1000, 0]
radius = 999
material = "ground"

[[objects]]
type = "mesh"
path = "{mesh}"
material = "model"
"""


def write_scene(folder: Path, triangles: int, suffix: str = ".obj") -> Path:
    """The scene file (and its mesh file, .obj or .ply by suffix) of a sphere of about
    `triangles` triangles in `folder`; its name says the size and the mesh file's
    form (sphere_1000.toml, sphere_1000_ply.toml)."""
    positions, faces = uv_sphere(triangles)
    mesh = folder / f"sphere_{triangles}{suffix}"
    {".obj": write_obj, ".ply": write_ply}[suffix](mesh, positions, faces)
    name = f"sphere_{triangles}" if suffix == ".obj" else f"sphere_{triangles}_ply"
    scene = folder / f"{name}.toml"
    scene.write_text(SCENE.format(triangles=len(faces), mesh=mesh.name))
    return scene
