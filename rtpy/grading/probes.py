"""Probes: what a grader asks the student's code to compute, run where that code runs.

A grader is two halves. Its **probe** is a function here or in the week's
`assignments/weekNN/probes.py`: it takes plain data (numbers, lists, arrays), builds
rtpy objects from them, calls the student's methods and returns plain data. Its
**verdict** is the pytest test in `assignments/weekNN/test_weekNN.py` (or hidden/),
run by the judge, which calls the probe by name and decides from what comes back:

    @probe(returns=List(Record(t=Maybe(Float))))       # in probes.py: runs in the child
    def sphere_hit_t(cases):
        return [{"t": Sphere(vec(c["center"]), c["radius"], M).hit_t(...)} for c in cases]

    def test_sphere_hit_t(probe):                       # in test_week04.py: the judge
        got = probe.sphere_hit_t(cases=cases)
        assert ..., "Sphere.hit_t (rtpy/sphere.py): ..."

Probes are public (they ship to students): they say what is called, never with which
inputs nor what is expected. `returns` is the answer's form (rtpy.grading.protocol):
the judge checks every answer against it before a verdict sees it (and, for a List
form and an input called `cases`, that there is one answer per case). A probe that
renders is registered with renders=True, so that a failed render can point to the
component graders that failed.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from .protocol import Array, Bool, List, Schema, Vec

__all__ = [
    "GIVEN_ANSWERS",
    "MATERIALS",
    "PROBES",
    "SCENES",
    "Probe",
    "color",
    "floats",
    "given_code_unused",
    "make_material",
    "probe",
    "scene_builder",
    "vec",
]


@dataclass(frozen=True)
class Probe:
    name: str
    function: Callable
    returns: Schema
    renders: bool = False


PROBES: dict[str, Probe] = {}
SCENES: dict[str, Callable] = {}  # name -> function(**params) -> Scene, for render probes
MATERIALS: dict[str, type] = {}  # extra material classes a probe may build by name


def probe(returns: Schema, renders: bool = False):
    """Register the decorated function as the probe of its name."""

    def register(function: Callable) -> Callable:
        name = function.__name__
        known = PROBES.get(name)
        if known is not None and _folder(known.function) != _folder(function):
            raise ValueError(f"two probes are called {name!r}")  # in two weeks' probes
        PROBES[name] = Probe(name, function, returns, renders)
        return function

    return register


def _folder(function: Callable) -> str:
    """The name of the folder of a function's file (a week's folder, or grading): a
    copy of the same week loaded again replaces its probes."""
    from pathlib import Path

    return Path(function.__code__.co_filename).parent.name


def scene_builder(function: Callable) -> Callable:
    """Register a function that builds a scene (from plain parameters) by its name."""
    known = SCENES.get(function.__name__)
    if known is not None and _folder(known) != _folder(function):
        raise ValueError(f"two scene builders are called {function.__name__!r}")
    SCENES[function.__name__] = function
    return function


def load_probes(paths) -> dict[str, Probe]:
    """PROBES, after importing the probe modules at `paths` (once each)."""
    import hashlib
    import importlib.util
    import sys
    from pathlib import Path

    for path in paths:
        path = Path(path).resolve()
        name = "rtpy_probes_" + hashlib.sha1(str(path).encode()).hexdigest()[:12]
        if name in sys.modules:
            continue
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return PROBES


# --- between plain data and rtpy objects ---------------------------------------------
def vec(values):
    """A Vec3 from three numbers."""
    from ..vec3 import Vec3

    x, y, z = (float(v) for v in values)
    return Vec3(x, y, z)


def color(values):
    """A Color from three numbers."""
    from ..vec3 import Color

    r, g, b = (float(v) for v in values)
    return Color(r, g, b)


def floats(v) -> list[float]:
    """A Vec3 or Color (or any three numbers) as three floats."""
    x, y, z = v
    return [float(x), float(y), float(z)]


COLOR_PARAMETERS = {"albedo", "f0", "emit", "le", "color"}


def make_material(spec: dict):
    """The material of a spec {"type": class name in rtpy.materials (or MATERIALS),
    parameter: value, ...}; colours are given as three numbers."""
    import rtpy.materials as materials

    params = dict(spec)
    name = params.pop("type")
    cls = MATERIALS.get(name) or getattr(materials, name, None)
    if not isinstance(cls, type):
        raise ValueError(f"no material class {name!r}")
    for key in COLOR_PARAMETERS & set(params):
        params[key] = color(params[key])
    return cls(**params)


# --- a task is answered by the student's code -----------------------------------------
class GivenCodeUsed(Exception):
    """A task's method ran given code that answers the task for it."""


def _code_files(module_name: str) -> set[str]:
    """The file names the code objects of a module's functions carry."""
    import importlib
    import inspect

    module = importlib.import_module(module_name)
    files = {module.__file__}
    for value in vars(module).values():
        if getattr(value, "__module__", None) != module_name:
            continue  # imported there, not given there
        members = vars(value).values() if inspect.isclass(value) else [value]
        for member in members:
            code = getattr(inspect.unwrap(getattr(member, "__func__", member)), "__code__", None)
            if code is not None:
                files.add(code.co_filename)
    return files


@contextlib.contextmanager
def given_code_unused(modules: tuple[str, ...], task: str) -> Iterator[None]:
    """Run the block watching the given modules' code (rtpy.bvh for a shadow ray, the
    Oren-Nayar model for Lambertian): GivenCodeUsed after the block if any of their
    functions ran. task: what is graded, "Class.method (file)", for the message.

    The watch is a profile function (sys.setprofile): it sees a call however the
    function was reached (an attribute, a reference kept at import, a subclass)."""
    owners = {file: name for name in modules for file in _code_files(name)}
    used: list[str] = []

    def watch(frame, event, arg) -> None:
        if event == "call" and not used:
            module = owners.get(frame.f_code.co_filename)
            if module is not None:
                used.append(f"{module}.{frame.f_code.co_qualname}")

    previous = sys.getprofile()
    sys.setprofile(watch)
    try:
        yield
    finally:
        sys.setprofile(previous)
    if used:
        raise GivenCodeUsed(
            f"{task} called {used[0]}: that given code answers the task, so it does not "
            "count. Write the task's code yourself (the task's text says what it needs)"
        )


# Material type -> the given modules whose code answers its task (a special case of it).
GIVEN_ANSWERS: dict[str, tuple[tuple[str, ...], str]] = {
    "Lambertian": (
        ("rtpy.materials.oren_nayar",),
        "Lambertian (rtpy/materials/lambertian.py)",
    ),
}


def _material_watch(spec: dict):
    """The watch of given code for the material of a spec (none for most)."""
    given = GIVEN_ANSWERS.get(spec.get("type"))
    return given_code_unused(*given) if given else contextlib.nullcontext()


# --- probes every week may use ---------------------------------------------------------
@probe(returns=Array((None, None, None, 3)), renders=True)
def render(scene: str, seeds: list, settings: dict, params: dict | None = None):
    """(R, H, W, 3) linear renders of SCENES[scene](**params), one per seed, with the
    scalar backend in this process."""
    import rtpy

    built = SCENES[scene](**(params or {}))
    images = [
        rtpy.render(built, seed=int(s), quiet=True, workers=1, **settings).linear for s in seeds
    ]
    return np.stack(images)


@probe(returns=Bool)
def material_is_specular(material: dict):
    return bool(make_material(material).is_specular)


SAMPLES = Array((None, 8))  # per draw: direction (3), weight (3), pdf, status


@probe(returns=SAMPLES)
def material_draw(
    material: dict, incident_deg: float, n: int, seed: int, phi_deg: float, inside: bool, tag: int
):
    """n draws of scattering() in the test setup of rtpy.testing (see its subject.py)."""
    from ..testing.subject import LocalMaterial

    with _material_watch(material):
        s = LocalMaterial(make_material(material)).draw(
            float(incident_deg), int(n), seed=int(seed), phi_deg=float(phi_deg),
            inside=bool(inside), tag=int(tag),
        )  # fmt: skip
    return np.column_stack([s.directions, s.weights, s.pdfs, s.status.astype(float)])


@probe(returns=Array((None, 3)))
def material_brdf(material: dict, wo, wi, inside: bool):
    from ..testing.subject import LocalMaterial

    m = LocalMaterial(make_material(material))
    with _material_watch(material):
        f = m.brdf(np.asarray(wo), np.asarray(wi), inside=bool(inside))
    return np.asarray(f, dtype=float)


@probe(returns=Array((None,)))
def material_pdf(material: dict, wo, wi, inside: bool):
    from ..testing.subject import LocalMaterial

    m = LocalMaterial(make_material(material))
    with _material_watch(material):
        p = m.pdf(np.asarray(wo), np.asarray(wi), inside=bool(inside))
    return np.asarray(p, dtype=float)


@probe(returns=List(Vec))
def radiance(scene: str, rays: list, settings: dict, params: dict | None = None, seed: int = 0):
    """integrator.compute_scattering(ray, scene) for each ray [origin, direction], the
    integrator the settings name (RenderSettings), rtpy's generator seeded with seed."""
    from ..integrators import make_integrator
    from ..ray import Ray
    from ..render_settings import RenderSettings
    from ..sampling import make_generator, use_generator

    built = SCENES[scene](**(params or {}))
    integrator = make_integrator(RenderSettings(**settings))
    with use_generator(make_generator(int(seed))):
        return [floats(integrator.compute_scattering(Ray(vec(o), vec(d)), built)) for o, d in rays]


@probe(returns=Bool)
def import_everything():
    """Import every module of rtpy (a task file that fails to import is found here)."""
    import importlib
    import pkgutil

    import rtpy

    for module in pkgutil.walk_packages(rtpy.__path__, "rtpy."):
        if not module.name.endswith("__main__"):
            importlib.import_module(module.name)
    return True
