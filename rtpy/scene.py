"""Scene: the objects, the lights and what rays see when they escape."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ._checks import checked, string
from .bvh import BVH
from .camera import Camera
from .environment import Environment
from .hit_info import HitInfo
from .hittable import Hittable
from .interval import Interval
from .light import AreaLight, Light, PointLight
from .mesh import Mesh
from .ray import Ray
from .render_settings import SETTINGS, RenderSettings
from .vec3 import Color


class Scene:
    """Objects, point lights and the background.

    Every object whose material emits (a DiffuseLight) is also an area light;
    `lights` lists the point lights and then those area lights, the set that
    integrators sample. The scene keeps no per-ray state: find_intersection and
    find_occlusion are pure queries.

    With bvh_min_objects objects or more, the queries walk a bounding volume
    hierarchy (rtpy.bvh) instead of testing every object. It is built on the first
    query and rebuilt when `objects` no longer equals the list it was built from
    (Scene.add_object, or any change to the list). Its answers are exactly those of
    testing every object in list order, what the scene does below
    bvh_min_objects objects.

    background  radiance of rays that escape (a constant environment)
    sky         True: the RTIOW blue-white gradient instead of `background`
    environment an rtpy.environment.Environment (radiance by direction) that
                replaces both; Python API only
    camera, settings  what a scene file gave (None for scenes built in code)
    files       the files a scene file read: itself, its images and OBJ meshes (the
                paths an output must not overwrite); empty for scenes built in code
    """

    def __init__(
        self,
        objects: list[Hittable] | None = None,
        point_lights: list[PointLight] | None = None,
        background: Color = Color(0.0, 0.0, 0.0),
        sky: bool = False,
        camera: Camera | None = None,
        settings: RenderSettings | None = None,
        name: str = "scene",
        environment: Environment | None = None,
    ) -> None:
        self.objects: list[Hittable] = _items("objects", objects, Hittable)
        self.point_lights: list[PointLight] = _items("point_lights", point_lights, Light)
        self.background = SETTINGS["background"].check(background)
        self.sky = SETTINGS["sky"].check(sky)
        self.camera = _optional("camera", camera, Camera)
        self.settings = _optional("settings", settings, RenderSettings)
        self.name = checked("name", string, name)
        self.environment = _optional("environment", environment, Environment)
        self.files: tuple[Path, ...] = ()
        self.area_lights: list[AreaLight] = []
        self.lights: list[Light] = []
        self.update_lights()
        self._bvh: BVH | None = None
        self._bvh_objects: list[Hittable] = []  # a copy of `objects` when _bvh was built

    # Below this many objects the queries test every object (the loop of week 4's
    # exercise), from it on they walk the BVH. The BVH pays from about 8 objects
    # (measured on the first n objects of rtiow_cover and on the bundled scenes);
    # 10 keeps the loop in use for the scenes of the weekly exercises. 0: always
    # use the BVH.
    bvh_min_objects: int = 10

    def add_object(self, obj: Hittable) -> None:
        self.objects.append(obj)
        self.update_lights()

    def add_light(self, light: PointLight) -> None:
        self.point_lights.append(light)
        self.update_lights()

    def update_lights(self) -> None:
        """Rebuild the light lists; call it after changing objects or point_lights.
        An emitting Mesh is refused: a light is one shape, so an emitting mesh goes
        into the scene as its triangles (Scene([*mesh.triangles]))."""
        for k, o in enumerate(self.objects):
            if isinstance(o, Mesh) and getattr(o.material, "is_emitter", False):
                raise ValueError(
                    f"objects[{k}]: a Mesh whose material emits must be added as its "
                    "triangles, each an area light: Scene([*mesh.triangles, ...])"
                )
        self.area_lights = [
            AreaLight(o) for o in self.objects if getattr(o.material, "is_emitter", False)
        ]
        self.lights = [*self.point_lights, *self.area_lights]

    def bvh(self) -> BVH:
        """The BVH over the current objects, built again if they changed since the
        last call."""
        if self._bvh is None or self._bvh_objects != self.objects:
            self._bvh = BVH(self.objects)
            self._bvh_objects = list(self.objects)
        return self._bvh

    def find_intersection(self, ray: Ray, interval: Interval) -> HitInfo | None:
        """The closest hit with t in (interval.min, interval.max), or None. Of
        objects hit at the same t, the one earliest in `objects` wins."""
        if len(self.objects) >= self.bvh_min_objects:
            return self.bvh().find_intersection(ray, interval)  # the same hit, sooner
        if not self.objects:
            return None  # the sky alone (week 3's scenes, before this method is written)
        # BEGIN SOLUTION week04: the closest hit over all objects (earliest object wins ties)
        # Every object in list order. An object replaces the closest so far only
        # when it is strictly closer, so on equal t the earlier one stays.
        closest_t = interval.max
        closest_obj = None
        t_min = interval.min
        for obj in self.objects:
            t = obj.hit_t(ray, t_min, closest_t)
            if t is not None:
                closest_t = t
                closest_obj = obj
        if closest_obj is None:
            return None
        return closest_obj.hit_info(ray, closest_t)
        # END SOLUTION

    def find_occlusion(self, ray: Ray, interval: Interval, ignore: Hittable | None = None) -> bool:
        """True if anything (glass included) lies on the ray with t in the interval.
        `ignore` is an object not to test (a light, for a shadow ray sent to a point
        on it)."""
        t_min, t_max = interval.min, interval.max
        if len(self.objects) >= self.bvh_min_objects:
            return self.bvh().any_hit(ray, t_min, t_max, ignore)
        # BEGIN SOLUTION week05: is anything on the shadow ray inside the interval?
        for obj in self.objects:
            if obj is not ignore and obj.hit_t(ray, t_min, t_max) is not None:
                return True
        return False
        # END SOLUTION

    def background_radiance(self, direction) -> Color:
        """Radiance arriving along a ray that escapes with this direction."""
        if self.environment is not None:
            return self.environment.radiance(direction)
        if not self.sky:
            return self.background
        # RTIOW's sky: white at the horizon to light blue overhead, by the
        # direction's y component.
        a = 0.5 * (direction.y() / direction.length() + 1.0)
        return Color(1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)


def _items(name: str, items: Any, kind: type) -> list:
    """A list of the items (None: empty), or TypeError naming the parameter."""
    items = list(items or [])
    for k, item in enumerate(items):
        if not isinstance(item, kind):
            found = type(item).__name__
            raise TypeError(f"{name}[{k}]: expected a {kind.__name__}, found a {found}")
    return items


def _optional(name: str, value: Any, kind: type) -> Any:
    """value, None or a kind, or TypeError naming the parameter."""
    if value is not None and not isinstance(value, kind):
        found = type(value).__name__
        raise TypeError(f"{name}: expected a {kind.__name__} or None, found a {found}")
    return value
