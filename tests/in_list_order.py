"""A scene's queries answered without its BVH, to compare the two."""

from __future__ import annotations

import copy
import math

from rtpy.scene import Scene


def in_list_order(scene: Scene) -> Scene:
    """A shallow copy of `scene` that tests every object in list order (the loop of
    Scene.find_intersection) however many objects it has."""
    listed = copy.copy(scene)
    listed.bvh_min_objects = math.inf
    return listed
