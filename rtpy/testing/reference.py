"""Reference images that renders are measured against (`rtpy bench`).

A Reference is the expected image of an unbiased estimator at a given max_depth,
with the variance of its own pixels and the mask of pixels it holds for:

- analytic_reference: an rtpy.testing.analytic_scenes scene's closed form (variance 0);
- rendered_reference: for any other scene, made once by rtpy at high spp with
  the most efficient integrator (numpy backend, "path" with next-event
  estimation and MIS, the scene's max_depth) as REFERENCE_RENDERS independent
  renders of spp / REFERENCE_RENDERS each; the image is their mean and its
  per-pixel variance is estimated from their spread. It is cached on disk
  (`reference_dir()`, default ~/.cache/rtpy/references) as an .npz with a
  .json of its settings, and the scene file's SHA-256: a cached reference whose
  scene file has changed since is refused (StaleReference) and get_reference
  makes it again.

Errors measured against a noisy reference include its noise: E[(I - R)^2] =
E[(I - E I)^2] + var(R) for independent I and R, so bench subtracts the mean of
`variance` from the squared error (`noise_floor`).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..camera import Camera
from ..io.image import atomic_write
from .analytic_scenes import AnalyticScene

REFERENCE_RENDERS = 4
DEFAULT_REFERENCE_SPP = 1024


@dataclass
class Reference:
    """image (H, W, 3) linear radiance; variance (H, W, 3) of each of its values;
    mask (H, W) of the pixels it holds for; exact: known in closed form;
    source: how it was made; settings: what it was made with."""

    image: np.ndarray
    variance: np.ndarray
    mask: np.ndarray
    exact: bool
    source: str
    settings: dict = field(default_factory=dict)

    @property
    def noise_floor(self) -> float:
        """Mean variance of the reference's values over the mask: the part of a
        measured mean squared error that is the reference's own noise."""
        return float(self.variance[self.mask].mean()) if self.mask.any() else 0.0


class StaleReference(Exception):
    """A cached reference that does not match its scene file or settings."""


def analytic_reference(scene: AnalyticScene, camera: Camera, max_depth: int) -> Reference:
    image, mask = scene.exact(camera, max_depth)
    return Reference(
        image=image,
        variance=np.zeros_like(image),
        mask=mask,
        exact=True,
        source=f"closed form ({scene.name})",
        settings={"width": camera.width, "height": camera.height, "max_depth": max_depth},
    )


def reference_dir() -> Path:
    """Where rendered references are cached: $RTPY_CACHE/references, else
    $XDG_CACHE_HOME/rtpy/references, else ~/.cache/rtpy/references."""
    if os.environ.get("RTPY_CACHE"):
        return Path(os.environ["RTPY_CACHE"]) / "references"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "rtpy" / "references"


def file_sha256(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _cache_paths(cache: Path, scene_path: Path, width: int, max_depth: int) -> tuple[Path, Path]:
    stem = f"{scene_path.stem}-w{width}-d{max_depth}"
    return cache / f"{stem}.npz", cache / f"{stem}.json"


def load_reference(
    scene_path: str | Path, width: int, max_depth: int, spp: int, cache: Path
) -> Reference | None:
    """The cached reference for this scene file, width and max_depth, made with at
    least `spp` samples per pixel; None if there is none; StaleReference if the
    scene file changed since it was made (or the cache entry is unreadable)."""
    scene_path = Path(scene_path)
    npz, meta_path = _cache_paths(cache, scene_path, width, max_depth)
    if not (npz.is_file() and meta_path.is_file()):
        return None
    try:
        meta = json.loads(meta_path.read_text())
        data = np.load(npz)
        image, variance = data["image"], data["variance"]
    except (OSError, ValueError, KeyError) as err:
        raise StaleReference(f"{npz}: unreadable ({err})") from None
    digest = file_sha256(scene_path)
    if meta.get("scene_sha256") != digest:
        raise StaleReference(
            f"{npz}: made from a different version of {scene_path} "
            f"(sha256 {str(meta.get('scene_sha256'))[:12]}..., now {digest[:12]}...)"
        )
    if meta.get("spp", 0) < spp:
        raise StaleReference(f"{npz}: made with {meta.get('spp')} spp, {spp} asked for")
    return Reference(
        image=image,
        variance=variance,
        mask=np.ones(image.shape[:2], dtype=bool),
        exact=False,
        source=meta.get("source", "rendered"),
        settings=meta,
    )


def render_reference(
    scene_path: str | Path, width: int, max_depth: int, spp: int, seed: int = 1_000_003
) -> tuple[np.ndarray, np.ndarray, dict]:
    """(image, variance of the image, settings) by REFERENCE_RENDERS independent
    numpy-backend renders with path tracing, next-event estimation and MIS."""
    from ..engine.render_request import render
    from ..io.bundled import resolve_scene
    from ..io.scene_file import load_scene

    scene = load_scene(resolve_scene(str(scene_path)))
    per = max(1, -(-spp // REFERENCE_RENDERS))
    start = time.perf_counter()
    images = np.stack(
        [
            render(
                scene,
                width=width,
                spp=per,
                integrator="path",
                nee=True,
                mis=True,
                max_depth=max_depth,
                seed=seed + k,
                backend="numpy",
            ).linear
            for k in range(REFERENCE_RENDERS)
        ]
    )
    seconds = time.perf_counter() - start
    variance = images.var(axis=0, ddof=1) / REFERENCE_RENDERS
    settings = {
        "scene": str(scene_path),
        "scene_sha256": file_sha256(scene_path),
        "width": width,
        "height": images.shape[1],
        "max_depth": max_depth,
        "spp": per * REFERENCE_RENDERS,
        "renders": REFERENCE_RENDERS,
        "seeds": [seed + k for k in range(REFERENCE_RENDERS)],
        "integrator": "path",
        "nee": True,
        "mis": True,
        "backend": "numpy",
        "seconds": round(seconds, 2),
        "made": time.strftime("%Y-%m-%d %H:%M:%S"),
        "source": f"rtpy numpy path+MIS, {per * REFERENCE_RENDERS} spp",
    }
    return images.mean(axis=0), variance, settings


def _write_bytes(path: Path, write) -> None:
    """Call write(file) on `path` opened for binary writing, atomically (atomic_write)."""

    def write_file(tmp: Path) -> None:
        with tmp.open("wb") as f:
            write(f)

    atomic_write(path, write_file)


def get_reference(
    scene_path: str | Path,
    width: int,
    max_depth: int,
    spp: int = DEFAULT_REFERENCE_SPP,
    cache: Path | None = None,
    log=print,
) -> Reference:
    """The cached reference if it is still valid, else a new one (rendered, cached)."""
    cache = reference_dir() if cache is None else Path(cache)
    try:
        ref = load_reference(scene_path, width, max_depth, spp, cache)
        if ref is not None:
            return ref
    except StaleReference as err:
        log(f"rtpy bench: refusing the cached reference: {err}; making it again")
    log(
        f"rtpy bench: making a reference for {scene_path} ({width} px wide, depth {max_depth}, "
        f"{spp} spp, numpy path+MIS); cached in {cache}"
    )
    image, variance, settings = render_reference(scene_path, width, max_depth, spp)
    cache.mkdir(parents=True, exist_ok=True)
    npz, meta_path = _cache_paths(cache, Path(scene_path), width, max_depth)
    _write_bytes(npz, lambda f: np.savez(f, image=image, variance=variance))
    _write_bytes(meta_path, lambda f: f.write(json.dumps(settings, indent=1).encode()))
    return Reference(
        image=image,
        variance=variance,
        mask=np.ones(image.shape[:2], dtype=bool),
        exact=False,
        source=settings["source"],
        settings=settings,
    )
