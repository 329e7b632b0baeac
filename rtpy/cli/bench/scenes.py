"""What `rtpy bench` measures: the integrator variants, and the scenes with the
references they are measured against (an analytic scene's exact image, or a
rendered reference of a scene file)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...camera import Camera
from ...scene import Scene
from ...testing.analytic_scenes import ANALYTIC_SCENES, analytic_scene
from ...testing.reference import DEFAULT_REFERENCE_SPP, Reference, analytic_reference, get_reference

# Integrator variants: render settings on top of the scene's own.
VARIANTS: dict[str, dict] = {
    "path-brdf": {"integrator": "path", "nee": False},  # BRDF sampling only
    "path-nee": {"integrator": "path", "nee": True, "mis": False},  # light sampling only
    "path-mis": {"integrator": "path", "nee": True, "mis": True},  # both, power heuristic
    "direct": {"integrator": "direct", "nee": True, "mis": True},  # one bounce (depth 2)
}
# The lecture's stop criteria, path-mis otherwise, measured only when asked for: a depth
# cap alone (path-cap3 shows the energy it loses: its bias against the scene's depth),
# the cap at the scene's depth without roulette, and the lecture's fixed p_RR (noisier
# than path-mis, whose roulette is throughput-based).
STOP_VARIANTS: dict[str, dict] = {
    "path-cap3": {"integrator": "path", "max_depth": 3, "russian_roulette": 0},
    "path-no-rr": {"integrator": "path", "russian_roulette": 0},
    "path-fixed-rr": {"integrator": "path", "roulette": "fixed"},
}
ALL_VARIANTS: dict[str, dict] = {**VARIANTS, **STOP_VARIANTS}
BACKENDS = ("numpy", "scalar")


@dataclass
class BenchScene:
    """A scene to measure: what to render and how to get its reference."""

    name: str
    scene: Scene
    camera: Camera
    max_depth: int
    russian_roulette: int
    reference_for: object  # callable(max_depth) -> Reference


def load_bench_scene(
    name: str,
    width: int | None,
    cache: Path | None = None,
    reference_spp: int = DEFAULT_REFERENCE_SPP,
    log=print,
) -> BenchScene:
    """An analytic scene by name, or a scene file / bundled scene (rendered reference)."""
    if name in ANALYTIC_SCENES:
        a = analytic_scene(name)
        camera = a.camera.with_width(width) if width else a.camera
        return BenchScene(
            name,
            a.scene,
            camera,
            a.settings.max_depth,
            a.settings.russian_roulette,
            lambda depth: analytic_reference(a, camera, depth),
        )
    from ... import load_scene
    from ...io.bundled import resolve_scene

    path = resolve_scene(name)
    scene = load_scene(path)
    camera = scene.camera.with_width(width) if width else scene.camera
    settings = scene.settings

    def reference_for(depth: int) -> Reference:
        return get_reference(path, camera.width, depth, reference_spp, cache, log=log)

    return BenchScene(
        path.stem, scene, camera, settings.max_depth, settings.russian_roulette, reference_for
    )


def effective_depth(variant: str, max_depth: int) -> int:
    """The max_depth whose image the variant estimates ("direct" is depth 2)."""
    return 2 if ALL_VARIANTS[variant]["integrator"] == "direct" else max_depth
