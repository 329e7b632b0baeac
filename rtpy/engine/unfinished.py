"""A render that reaches a task not written yet: which task, and what renders now.

In a week's assignment repository every method a student still has to write raises
the NotImplementedError of its stub (rtpy.grading.assignment writes them):

    week08 task: PathIntegrator.compute_scattering: path loop: ... (task 8.4,
    rtpy/integrators/path.py; see assignments/week08/README.md)

A render that reaches one, in this process or in a worker (where it comes back as
the same exception), stops with one line made here: the task's number, the method
and its file, and the integrators that render the same scene now, found by rendering
a few pixels of it with each of them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..render_settings import INTEGRATOR_NAMES

if TYPE_CHECKING:
    from ..camera import Camera
    from ..render_settings import RenderSettings
    from ..scene import Scene
    from .renderer import Renderer

__all__ = [
    "Unfinished",
    "find_unfinished",
    "stub_message",
    "what_renders_now",
    "working_integrators",
]

STUB = re.compile(
    r"^week(?P<week>\d\d) task: (?P<function>[\w.]+)"
    r"(?:.*\((?:task (?P<task>\d+\.\d+), )?(?P<file>[\w./-]+\.py); see )?",
    re.DOTALL,
)
# The integrators a message suggests first: the most complete image first.
PREFERRED = ("path", "direct", "whitted", "shading", "jittered", "center")
PROBE_WIDTH = 24  # pixels across of a probe render (one sample each)


@dataclass(frozen=True)
class Unfinished:
    """A stub reached: its week ("08"), task number ("8.4", None when the stub does
    not say), method ("PathIntegrator.compute_scattering") and file (or None)."""

    week: str
    task: str | None
    function: str
    file: str | None

    def describe(self) -> str:
        task = f"task {self.task}" if self.task else f"a week-{self.week} task"
        where = f" in {self.file}" if self.file else ""
        return f"{task} is not written yet: {self.function}{where} raised NotImplementedError"


def find_unfinished(err: BaseException | None) -> Unfinished | None:
    """The stub that raised err (or an exception err comes from), else None."""
    seen = set()
    while err is not None and id(err) not in seen:
        seen.add(id(err))
        if isinstance(err, NotImplementedError) and err.args:
            m = STUB.match(str(err.args[0]))
            if m:
                return Unfinished(m["week"], m["task"], m["function"], m["file"])
        err = err.__cause__ or err.__context__
    return None


def renders_with(integrator: str, scene: Scene, camera: Camera, settings: RenderSettings) -> bool:
    """Does a few pixels' render of the scene with `integrator` finish (scalar
    backend, this process, one sample per pixel)?"""
    from .renderer import Renderer

    try:
        small = camera.with_width(min(camera.width, PROBE_WIDTH))
        probe = settings.with_overrides(integrator=integrator, spp=1, time_limit=0.0)
        Renderer(scene, small, probe).render()
    except Exception:  # a stub, or anything else: it does not render now
        return False
    return True


def working_integrators(
    scene: Scene, camera: Camera, settings: RenderSettings, failed: str | None = None
) -> list[str]:
    """The integrators (but `failed`) that render the scene now, PREFERRED first."""
    names = [n for n in INTEGRATOR_NAMES if n != failed]
    names.sort(key=lambda n: PREFERRED.index(n) if n in PREFERRED else len(PREFERRED) - 2)
    return [n for n in names if renders_with(n, scene, camera, settings)]


def renders_now(integrators: list[str], option: str) -> str:
    """What a message says renders now: `option` formats the first integrator's name
    ("--integrator {}"), the others follow as names."""
    if not integrators:
        return "nothing renders this scene before it is written"
    first, *rest = integrators
    also = f" (or {', '.join(rest)})" if rest else ""
    return f"this scene renders now with {option.format(first)}{also}"


def stub_message(err: BaseException, renderer: Renderer | None = None, option: str = "{!r}"):
    """The one line of a render stopped by a stub (None when err is no stub's): the
    task and what renders now, the integrators found by `renderer`'s scene, camera
    and settings (none before the render was made), each written as `option` formats
    it ("--integrator {}")."""
    unfinished = find_unfinished(err)
    if unfinished is None:
        return None
    if renderer is None:
        return f"{unfinished.describe()}; nothing renders before it is written"
    return f"{unfinished.describe()}; {what_renders_now(renderer, option)}"


def what_renders_now(renderer: Renderer, option: str) -> str:
    """What renders the scene of `renderer` now, the integrator it failed with aside."""
    r = renderer
    return renders_now(
        working_integrators(r.scene, r.camera, r.settings, r.settings.integrator), option
    )
