"""HitInfo: what a ray learns where it hits a surface."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .vec3 import Vec3

if TYPE_CHECKING:
    from .hittable import Hittable
    from .materials.material import Material
    from .onb import ONB


class HitInfo:
    """The closest hit of a ray.

    point       world position of the hit
    normal      unit normal on the side the ray came from (dot(normal, ray.direction) <= 0)
    t           ray parameter of the hit
    front_face  True when the ray hit the side the geometric normal points to
                (the outside of a sphere, the u x v side of a quad)
    material    the object's material
    u, v        surface coordinates in [0, 1]; computed on first access, because only
                textures that need them should pay for them
    tangent     unit vector in the surface along increasing u, perpendicular to the
                normal (the first axis of anisotropic materials' frame); computed
                on first access
    frame       the shading frame ONB.from_normal_tangent(normal, tangent): z along
                the normal, x along the tangent; computed on first access and shared
                by the BRDF(), pdf() and scattering() calls at this hit
    obj         the object that was hit
    """

    __slots__ = (
        "point",
        "normal",
        "t",
        "front_face",
        "material",
        "obj",
        "_u",
        "_v",
        "_tangent",
        "_frame",
    )

    def __init__(
        self,
        point: Vec3,
        normal: Vec3,
        t: float,
        front_face: bool,
        material: Material,
        obj: Hittable | None = None,
        u: float | None = None,
        v: float | None = None,
    ) -> None:
        self.point = point
        self.normal = normal
        self.t = t
        self.front_face = front_face
        self.material, self.obj = material, obj
        self._u, self._v = u, v  # None: computed on first access, as are these two
        self._tangent = self._frame = None

    def _compute_uv(self) -> None:
        if self.obj is None:
            self._u, self._v = 0.0, 0.0
        else:
            self._u, self._v = self.obj.surface_uv(self)

    @property
    def u(self) -> float:
        if self._u is None:
            self._compute_uv()
        return self._u

    @property
    def v(self) -> float:
        if self._v is None:
            self._compute_uv()
        return self._v

    @property
    def tangent(self) -> Vec3:
        if self._tangent is None:
            self._tangent = self.obj.surface_tangent(self) if self.obj is not None else None
            if self._tangent is None:
                from .onb import ONB

                self._tangent = ONB(self.normal).u
        return self._tangent

    @tangent.setter
    def tangent(self, value: Vec3) -> None:
        self._tangent = value
        self._frame = None

    @property
    def frame(self) -> ONB:
        if self._frame is None:
            from .onb import ONB

            self._frame = ONB.from_normal_tangent(self.normal, self.tangent)
        return self._frame

    def __repr__(self) -> str:
        return (
            f"HitInfo(t={self.t!r}, point={self.point!r}, normal={self.normal!r}, "
            f"front_face={self.front_face!r})"
        )
