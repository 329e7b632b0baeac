"""Rays leaving surfaces, many at once: the batched rtpy.ray.

A batch of rays is two (N, 3) arrays, origins and unit directions; a point on a ray
is origin + t direction (arrays.axpy). Rays that leave a surface start a little off
it, exactly as rtpy.ray.spawn_ray places them.
"""

from __future__ import annotations

import numpy as np

from ..ray import SPAWN_ABSOLUTE_OFFSET, SPAWN_RELATIVE_OFFSET
from .arrays import axpy, dot, max3


def offset_scale(p: np.ndarray) -> np.ndarray:
    """rtpy.ray.offset_scale for (N, 3) points: how far a ray leaving p starts off it."""
    return SPAWN_ABSOLUTE_OFFSET + SPAWN_RELATIVE_OFFSET * max3(np.abs(p))


def ray_columns(o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rays (o, d) as columns: (4, N) homogeneous origins (x, y, z, 1) and (3, N)
    directions, the layout of QuadSet.pair_t's matrix products."""
    oh = np.empty((4, len(o)))
    oh[:3] = o.T
    oh[3] = 1.0
    return oh, np.ascontiguousarray(d.T)


def spawn_origins(
    point: np.ndarray,
    normal: np.ndarray,
    direction: np.ndarray,
    offset: np.ndarray | None = None,
    cos: np.ndarray | None = None,
) -> np.ndarray:
    """Origins of rtpy.ray.spawn_ray(point, normal, direction) for (N, 3) arrays: the
    point pushed off the surface along the normal to the side the direction goes.
    offset, cos: offset_scale(point) and dot(direction, normal), when the caller has them."""
    eps = offset_scale(point) if offset is None else offset.copy()
    below = (dot(direction, normal) if cos is None else cos) < 0.0
    np.negative(eps, out=eps, where=below)
    return axpy(eps, normal, point)
