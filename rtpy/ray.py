"""Ray: origin + t * direction."""

from __future__ import annotations

from .vec3 import Vec3

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
        o, d = self.origin, self.direction
        return Vec3(o.e0 + t * d.e0, o.e1 + t * d.e1, o.e2 + t * d.e2)

    def __repr__(self) -> str:
        return f"Ray({self.origin!r}, {self.direction!r})"


def offset_scale(p: Vec3) -> float:
    """How far a ray leaving point p must start from the surface (world units)."""
    # The largest |coordinate|, compared by hand: the builtin max() costs more.
    m, y, z = abs(p.e0), abs(p.e1), abs(p.e2)
    m = y if y > m else m
    m = z if z > m else m
    return SPAWN_ABSOLUTE_OFFSET + SPAWN_RELATIVE_OFFSET * m


def spawn_ray(point: Vec3, normal: Vec3, direction: Vec3) -> Ray:
    """A ray leaving a surface at `point` toward `direction`.

    `normal` is the surface normal (either side). The origin is pushed off the
    surface to the side `direction` goes to, so the new ray cannot re-hit the
    surface it starts on; it works for reflected and refracted rays alike.
    """
    eps = offset_scale(point)
    if direction.e0 * normal.e0 + direction.e1 * normal.e1 + direction.e2 * normal.e2 < 0.0:
        eps = -eps
    origin = Vec3(
        point.e0 + eps * normal.e0, point.e1 + eps * normal.e1, point.e2 + eps * normal.e2
    )
    return Ray(origin, direction)
