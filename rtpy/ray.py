"""Ray: origin + t * direction."""

from __future__ import annotations

from .vec3 import Vec3, dot

# Rays leaving a surface start a little off it, by this fraction of the hit
# point's magnitude (plus an absolute floor), so that rounding in the hit point
# cannot make a ray hit the surface it leaves ("shadow acne"). The offset scales
# with the coordinates because float64 rounding does too.
SPAWN_RELATIVE_OFFSET = 1e-9
SPAWN_ABSOLUTE_OFFSET = 1e-9


class Ray:
    __slots__ = ("origin", "direction")

    def __init__(self, origin: Vec3, direction: Vec3) -> None:
        self.origin = origin
        self.direction = direction

    def at(self, t: float) -> Vec3:
        return self.origin + self.direction * t

    def __repr__(self) -> str:
        return f"Ray({self.origin!r}, {self.direction!r})"


def offset_scale(p: Vec3) -> float:
    """How far a ray leaving point p must start from the surface (world units)."""
    largest = max(abs(p.x()), abs(p.y()), abs(p.z()))
    return SPAWN_ABSOLUTE_OFFSET + SPAWN_RELATIVE_OFFSET * largest


def spawn_ray(point: Vec3, normal: Vec3, direction: Vec3) -> Ray:
    """A ray leaving a surface at `point` toward `direction`.

    `normal` is the surface normal (either side). The origin is pushed off the
    surface to the side `direction` goes to, so the new ray cannot re-hit the
    surface it starts on; it works for reflected and refracted rays alike.
    """
    eps = offset_scale(point)
    if dot(direction, normal) < 0.0:
        eps = -eps
    return Ray(point + normal * eps, direction)
