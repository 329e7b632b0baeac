"""The state of a stopped render, kept so that it can be continued (resume).

A render with a checkpoint keeps in one file (the command line: OUT.png.resume.npz
beside -o OUT.png) the sums and sample counts of its whole passes and of the units
of the pass in progress that are finished, and what they were rendered from: the
rtpy version, the options that change the sums (the render settings but gamma and
the time limit, the image size, the backend) and a digest of the scene (its pickle,
with the camera, and the plugins' source files). The file is an .npz of three
arrays, `sums` (height, width, 4: r, g, b sums and each pixel's count, of the whole
passes), `current` (the rows from `first_row` on that hold units of the pass in
progress, each pixel's sums, count and pass: rtpy.engine.pixel_sums) and `key` (that
description, as JSON, with first_row), written atomically
(rtpy.engine.files): as units finish, at most every CHECKPOINT_SECONDS, and when the
render stops (Ctrl-C, SIGTERM, its time limit). A crash loses what came after the
last write.

Continued (--resume, rtpy.render(resume=True)), the render starts from there and
renders only the units it does not hold; the plan and every unit's random numbers
depend on the seed and the options only (rtpy.engine.plan), so the finished image is bit
for bit the one an uninterrupted render gives. A file that is not such a state, or
was saved by another rtpy, with other options or for another scene, is refused with
one line saying which (ResumeError), before anything is rendered or written.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..bvh import Tree
from .files import StrPath, atomic_write
from .plugins import PLUGINS
from .user_files import read_arrays, read_bytes
from .version import version

if TYPE_CHECKING:
    from .backend import Backend
    from .plan import Plan

__all__ = ["CHECKPOINT_SECONDS", "FORMAT", "Checkpoint", "ResumeError", "state_path"]

CHECKPOINT_SECONDS = 30.0  # about the most a crash loses
FORMAT = 2  # of the state file, and of the scene digest that keys it
# Settings that do not change the sums: the display transform, when to stop.
NOT_IN_THE_SUMS = ("gamma", "time_limit")


class ResumeError(ValueError):
    """A saved render that cannot be continued: the message says why, in one line."""


STATE_SUFFIX = ".resume.npz"
NAME_MAX = 255  # bytes in a file's name, on the usual file systems


def state_path(output: StrPath) -> Path:
    """Where the command line keeps the state of a render to `output`: beside it,
    OUT.png.resume.npz; for a name too long for that (a legal name of up to NAME_MAX
    bytes), its first bytes and a digest of the whole, so that it fits and is the
    same for the same output."""
    output = Path(output)
    name = output.name + STATE_SUFFIX
    if len(os.fsencode(name)) <= NAME_MAX:
        return output.with_name(name)
    digest = "." + hashlib.sha256(os.fsencode(output.name)).hexdigest()[:16]
    keep = output.name
    while len(os.fsencode(keep + digest + STATE_SUFFIX)) > NAME_MAX:
        keep = keep[:-1]
    return output.with_name(keep + digest + STATE_SUFFIX)


class Checkpoint:
    """The state file of one render by `backend` (its scene, camera and settings),
    at `path`. The scene's digest is taken now, before any unit is rendered."""

    def __init__(self, path: StrPath, backend: Backend) -> None:
        self.path = Path(path)
        self.options = _options(backend)
        self.scene = _digest(backend)

    def key(self) -> dict:
        return {"format": FORMAT, "rtpy": version(), "options": self.options, "scene": self.scene}

    def save(self, total: np.ndarray, current: np.ndarray) -> None:
        """Write the whole passes `total` and the units of the pass in progress
        `current` (rtpy.engine.pixel_sums) with this render's key."""
        rows = np.flatnonzero(current[:, :, 3].any(axis=1))  # those the units hold
        first, last = (int(rows[0]), int(rows[-1]) + 1) if rows.size else (0, 0)
        key = np.array(json.dumps({**self.key(), "first_row": first}))

        def write(tmp: Path) -> None:
            with open(tmp, "wb") as f:  # a file object: savez would add ".npz" to a name
                np.savez(f, sums=total, current=current[first:last], key=key)

        atomic_write(self.path, write)

    def load(self, plan: Plan) -> tuple[np.ndarray, np.ndarray] | None:
        """(total, current) saved for this render, None if there is no file;
        ResumeError if the file holds another render or none."""
        if not self.path.exists():
            return None
        key, sums, rows = self._read(plan)
        if not isinstance(key, dict) or key.get("format") != FORMAT:
            raise self._error("not a saved render of this kind (its format differs)")
        if key.get("rtpy") != version():
            raise self._error(f"saved by rtpy {key.get('rtpy')}, this is rtpy {version()}")
        saved = key.get("options") if isinstance(key.get("options"), dict) else {}
        for name, value in self.options.items():
            if saved.get(name) != value:
                raise self._error(f"saved with {name} = {saved.get(name)!r}, not {value!r}")
        if key.get("scene") != self.scene:
            raise self._error("saved for another scene (the scene, its files or plugins changed)")
        first = key.get("first_row")
        if rows.ndim != 3:
            raise self._error(f"its current are {rows.dtype} of {rows.ndim} dimensions, not 3")
        if not (isinstance(first, int) and 0 <= first <= plan.height - len(rows)):
            raise self._error(f"its first row {first!r} does not fit the image")
        current = np.zeros((plan.height, plan.width, 5))
        for name, array, shape in (
            ("sums", sums, (plan.height, plan.width, 4)),
            ("current", rows, (len(rows), plan.width, 5)),
        ):
            if array.shape != shape or array.dtype != np.float64:
                raise self._error(f"its {name} are {array.dtype} {array.shape}, not {shape}")
            if not (np.isfinite(array).all() and (array >= 0.0).all()):
                raise self._error(f"its {name} are not finite and non-negative")
        current[first : first + len(rows)] = rows
        counts = sums[..., 3]
        samples = int(counts.flat[0])
        if not ((counts == samples).all() and plan.passes_holding(samples) is not None):
            raise self._error("its sample counts are not those of whole passes")
        return sums, current

    def _read(self, plan: Plan) -> tuple[object, np.ndarray, np.ndarray]:
        """(key, sums, current) as the file holds them, read through
        rtpy.engine.user_files (a regular file; no array larger than the image's
        sums, whatever its header declares); ResumeError for anything else."""
        most = plan.height * plan.width * 5 * 8 + (1 << 20)
        try:
            arrays = read_arrays(self.path, ("key", "sums", "current"), most)
            key = json.loads(str(arrays["key"])) if arrays["key"].ndim == 0 else None
        except OSError as err:
            raise self._error(f"cannot be read: {err.strerror or err}") from None
        except (ValueError, RecursionError) as err:
            raise self._error(f"not a saved render ({err})") from None
        return key, arrays["sums"], arrays["current"]

    def remove(self) -> None:
        """Delete the file (the render it holds is finished and written)."""
        try:
            self.path.unlink(missing_ok=True)
        except OSError:
            pass  # left behind: a later render replaces it

    def _error(self, why: str) -> ResumeError:
        return ResumeError(f"{self.path}: {why}")


def _options(backend: Backend) -> dict:
    """The options that change a render's sums, as JSON values."""
    settings, camera, scene = backend.settings, backend.camera, backend.scene
    options = {
        f.name: getattr(settings, f.name) for f in fields(settings) if f.name not in NOT_IN_THE_SUMS
    }
    options.update(
        width=camera.width,
        height=camera.height,
        backend=backend.name,
        background=scene.background.tolist(),
        sky=scene.sky,
    )
    return json.loads(json.dumps(options))


class _Hasher:
    """A file that hashes what is written to it (pickle.dump's target)."""

    def __init__(self) -> None:
        self.sha = hashlib.sha256()

    def write(self, data) -> int:
        self.sha.update(data)
        return len(data)

    def hash_buffer(self, buffer: pickle.PickleBuffer) -> bool:
        """Hash an array's memory where it lies (pickle's buffer_callback): False,
        so pickle writes only a mark of it into the stream."""
        self.write(buffer.raw())
        return False


class _ScenePickler(pickle.Pickler):
    """Pickles a scene for its digest with every BVH tree left out: a tree is made
    from primitives that are pickled themselves, and does not change the image (the
    closest hit is the same through any tree). A million-triangle mesh's tree is
    half its bytes."""

    def reducer_override(self, obj):
        if isinstance(obj, Tree):
            return str, ("a tree",)
        return NotImplemented


def _digest(backend: Backend) -> str:
    """sha256 of the scene (its public attributes: not the caches it builds while
    rendering; not its trees, _ScenePickler), the camera, and the plugins' source
    files. Arrays are hashed in place, not copied into the pickle."""
    scene = backend.scene
    public = {k: v for k, v in sorted(vars(scene).items()) if not k.startswith("_")}
    hasher = _Hasher()
    try:
        pickler = _ScenePickler(hasher, protocol=5, buffer_callback=hasher.hash_buffer)
        pickler.dump((public, backend.camera))
    except (pickle.PicklingError, AttributeError, TypeError) as err:
        raise ResumeError(
            f"checkpoint: the scene cannot be saved with the render ({type(err).__name__}: "
            f"{err}); its classes must be importable by name"
        ) from None
    for name, path in PLUGINS.items():
        hasher.write(name.encode())
        hasher.write(read_bytes(path))
    return hasher.sha.hexdigest()
