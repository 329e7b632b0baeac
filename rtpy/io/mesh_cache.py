"""Large meshes built once: a scene file's mesh, read, placed and given its tree, is
kept on disk and read back by the next render of the same file and transform.

Reading a million-triangle OBJ file and building its tree take a few seconds; reading
the arrays back takes a few hundredths: a render of the 1M-triangle scene took 0.74 s
once cached against 1.09 s from PLY and 1.55 s from OBJ (docs/performance.md#scene-size).
A mesh of at least MIN_FACES faces is kept in $RTPY_CACHE/meshes, else
$XDG_CACHE_HOME/rtpy/meshes, else ~/.cache/rtpy/meshes, one folder of .npy files per
entry. An entry is found by the OBJ file's resolved path, size and modification time (as
Python checks its .pyc files against their source), the transform, the rtpy version and
FORMAT, so a changed file or transform is read and built again. RTPY_MESH_CACHE=0 turns
the cache off. The cache never stops a render: an entry that cannot be written is not
written, one that cannot be read is built again, and the oldest entries are removed
beyond MAX_BYTES.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from ..bvh import Tree
from ..engine.user_files import load_npy, read_text
from ..mesh import Mesh, Transform
from .obj import mesh_from_obj
from .ply import mesh_from_ply

FORMAT = 1
MIN_FACES = 50_000
MAX_BYTES = 2 << 30
ARRAYS = ("vertices", "normals", "faces", "face_normals")
TREE = ("lo", "hi", "child", "count", "axis", "order")


def cache_folder() -> Path | None:
    """Where meshes are kept, or None when RTPY_MESH_CACHE=0."""
    if os.environ.get("RTPY_MESH_CACHE", "1") == "0":
        return None
    if os.environ.get("RTPY_CACHE"):
        return Path(os.environ["RTPY_CACHE"]) / "meshes"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "rtpy" / "meshes"


def load_mesh(path: Path, material, transform: Transform) -> tuple[Mesh, int]:
    """(the mesh of the OBJ or PLY file at path, the number of faces the file has):
    from the cache when it has it, else read (rtpy.io.obj.mesh_from_obj, or
    rtpy.io.ply.mesh_from_ply for a name ending in .ply, with their errors), built,
    and kept when it is large."""
    folder = cache_folder()
    entry = None if folder is None else folder / _key(path, transform)
    if entry is not None and entry.is_dir():
        found = _read(entry, material)
        if found is not None:
            return found
    read = mesh_from_ply if path.suffix.lower() == ".ply" else mesh_from_obj
    mesh = read(path, material, transform)
    faces = len(mesh) + mesh.skipped  # the file's, the degenerate ones too
    if entry is not None and len(mesh) >= MIN_FACES:
        _write(entry, mesh, faces)
    return mesh, faces


def _key(path: Path, transform: Transform) -> str:
    from ..engine.version import version

    stat = path.stat()
    parts = [
        FORMAT,
        version(),
        str(path.resolve()),
        stat.st_size,
        stat.st_mtime_ns,
        [v.tolist() for v in (transform.translate, transform.scale, *transform.rows)],
    ]
    return hashlib.sha256(json.dumps(parts).encode()).hexdigest()[:32]


def _read(entry: Path, material) -> tuple[Mesh, int] | None:
    """The entry's mesh and face count; None when it is missing or damaged (an array
    file emptied or with a header that lies, metadata of another shape), read through
    rtpy.engine.user_files so that nothing it declares is allocated unchecked."""
    try:
        meta = json.loads(read_text(entry / "meta.json", limit=1 << 16))
        faces, skipped = meta["faces"], meta["skipped"]
        arrays = {name: load_npy(entry / f"{name}.npy") for name in ARRAYS + TREE}
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return None  # removed or damaged meanwhile: built again
    if not (type(faces) is int and type(skipped) is int and _consistent(arrays)):
        return None
    mesh = Mesh.from_arrays(
        material,
        *(arrays[name] for name in ARRAYS),
        Tree(*(arrays[name] for name in TREE)),
        skipped,
    )
    os.utime(entry / "meta.json")  # used: the last to go when the cache is pruned
    return mesh, faces


def _consistent(a: dict[str, np.ndarray]) -> bool:
    """The arrays have the shapes and kinds _write saves, finite points, and indices
    within bounds, the tree's too (a damaged entry that still reads as arrays is built
    again rather than crash the render)."""
    points = ("vertices", "normals", "lo", "hi")
    for name, array in a.items():
        rows = name in points or name in ("faces", "face_normals")
        if array.ndim != (2 if rows else 1) or (rows and array.shape[1] != 3):
            return False
        if name in points and not (array.dtype.kind == "f" and np.isfinite(array).all()):
            return False
        if name not in points and array.dtype.kind not in "iu":
            return False
    nodes, faces = len(a["count"]), len(a["faces"])
    if not (nodes and all(len(a[n]) == nodes for n in ("lo", "hi", "child", "axis"))):
        return False
    child, count = a["child"].astype(np.int64), a["count"].astype(np.int64)
    inner = count == 0  # children child and child + 1; a leaf: order[child : child + count]
    return (
        len(a["face_normals"]) == faces
        and len(a["order"]) == faces
        and _within(a["faces"], len(a["vertices"]))
        and _within(a["face_normals"], len(a["normals"]), lowest=-1)
        and _within(a["order"], faces)
        and _within(a["axis"], 3)
        and _within(child[inner], nodes - 1)
        and _within(child[~inner], faces + 1)
        and _within((child + count)[~inner], faces + 1)
    )


def _within(indices: np.ndarray, count: int, lowest: int = 0) -> bool:
    return not indices.size or (int(indices.min()) >= lowest and int(indices.max()) < count)


def _write(entry: Path, mesh: Mesh, faces: int) -> None:
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        temporary = Path(tempfile.mkdtemp(dir=entry.parent, prefix=".writing-"))
    except OSError:
        return
    try:
        for name in ARRAYS:
            np.save(temporary / f"{name}.npy", getattr(mesh, name))
        for name in TREE:
            np.save(temporary / f"{name}.npy", getattr(mesh.tree, name))
        meta = {"faces": faces, "skipped": mesh.skipped}
        (temporary / "meta.json").write_text(json.dumps(meta))
        os.replace(temporary, entry)  # whole, or not at all (another process was first)
    except OSError:
        pass
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
    _prune(entry.parent)


def _prune(folder: Path) -> None:
    """Remove the least recently used entries while the cache holds more than MAX_BYTES."""
    entries = []
    for entry in folder.iterdir():
        try:
            size = sum(f.stat().st_size for f in entry.iterdir())
            entries.append(((entry / "meta.json").stat().st_mtime, size, entry))
        except OSError:
            continue
    total = sum(size for _, size, _ in entries)
    for _, size, entry in sorted(entries):
        if total <= MAX_BYTES:
            break
        shutil.rmtree(entry, ignore_errors=True)
        total -= size
