"""Triangle meshes: SmoothTriangle (a triangle with vertex normals), Transform (scale,
rotate, translate) and Mesh, which turns a mesh's vertices and faces into triangles.

A mesh is not one object in the scene: its triangles are, each on its own, so both
backends put them in their BVHs with the other shapes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .hit_info import HitInfo
from .io.values import ANGLE, checked, checked_point, checked_scales, checked_vector, point
from .ray import Ray
from .triangle import Triangle
from .vec3 import Vec3, dot, unit_vector

__all__ = ["Mesh", "SmoothTriangle", "Transform"]


class SmoothTriangle(Triangle):
    """A Triangle shaded with the normals given at its vertices (Phong shading).

    At a hit with barycentric weights (1 - u - v, u, v) of a, b, c the shading
    normal is normalize((1 - u - v) na + u nb + v nc), turned to the side of the
    geometric normal when it points away from it. HitInfo.normal is that shading
    normal on the side the ray came from. Intersection, front_face (which side
    was hit, which side emits) and the light-sampling densities keep the geometric
    normal `normal`. Rays leaving the surface are pushed off it along hit.normal
    (ray.spawn_ray), as on every shape; a direction between the two planes may
    then meet the triangle again from behind, the usual price of shading normals.
    """

    def __init__(self, a: Vec3, b: Vec3, c: Vec3, normals: Sequence[Vec3], material) -> None:
        super().__init__(a, b, c, material)
        na, nb, nc = normals
        for name, n in zip(("na", "nb", "nc"), normals, strict=True):
            if not _usable(n):
                raise ValueError(f"vertex normal {name} must be a finite non-zero vector")
        self.na, self.nb, self.nc = unit_vector(na), unit_vector(nb), unit_vector(nc)

    def shading_normal(self, u: float, v: float) -> Vec3:
        """The interpolated unit normal at barycentric weights u (of b), v (of c),
        on the front side (dot with `normal` >= 0)."""
        n = self.na * (1.0 - u - v) + self.nb * u + self.nc * v
        length = n.length()
        if not length > 0.0:
            return self.normal
        n = n / length
        return -n if dot(n, self.normal) < 0.0 else n

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        point = ray.at(t)
        hit = HitInfo(point, self.normal, t, True, self.material, self)
        u, v = self.surface_uv(hit)
        n = self.shading_normal(u, v)
        front_face = dot(self.normal, ray.direction) < 0.0
        return HitInfo(point, n if front_face else -n, t, front_face, self.material, self, u, v)

    def direction_pdf(self, p: Vec3, hit: HitInfo) -> float:
        flat = HitInfo(hit.point, self.normal, hit.t, hit.front_face, self.material, self)
        return super().direction_pdf(p, flat)


class Transform:
    """p -> R (S p) + translate: S scales along x, y, z; R rotates by rotate[0] degrees
    about the x axis, then rotate[1] about y, then rotate[2] about z (fixed axes,
    right-handed: counterclockwise looking down the axis toward the origin)."""

    def __init__(
        self,
        translate: Vec3 = Vec3(0.0, 0.0, 0.0),
        rotate: Vec3 = Vec3(0.0, 0.0, 0.0),
        scale: Vec3 = Vec3(1.0, 1.0, 1.0),
    ) -> None:
        self.translate = checked_point("translate", translate)
        self.scale = checked_scales("scale", scale)
        rotate = checked_vector("rotate", rotate, ANGLE)
        rows = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        for axis, degrees in enumerate(rotate):
            rows = _matmul(_rotation(axis, math.radians(degrees)), rows)
        self.rows = [Vec3(*r) for r in rows]  # the rows of R

    def point(self, p: Vec3) -> Vec3:
        s = self.scale
        q = Vec3(p.x() * s.x(), p.y() * s.y(), p.z() * s.z())
        return Vec3(*(dot(r, q) for r in self.rows)) + self.translate

    def normal(self, n: Vec3) -> Vec3:
        """A normal carried along (the inverse transpose: R S^-1 n), not normalized."""
        s = self.scale
        q = Vec3(n.x() / s.x(), n.y() / s.y(), n.z() / s.z())
        return Vec3(*(dot(r, q) for r in self.rows))


def _rotation(axis: int, angle: float) -> list[list[float]]:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [k for k in range(3) if k != axis]  # the plane rotated: y-z, z-x or x-y
    if axis == 1:
        i, j = j, i  # about y, z turns toward x
    m = [[1.0 if r == k else 0.0 for k in range(3)] for r in range(3)]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def _matmul(a: list[list[float]], b: list[list[float]]) -> list[list[float]]:
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def _usable(n: Vec3) -> bool:
    length = n.length()
    return math.isfinite(length) and length > 0.0


class Mesh:
    """The triangles of a mesh, placed by a transform.

        mesh = Mesh.from_obj("teapot.obj", Lambertian(), Transform(scale=Vec3(0.5, 0.5, 0.5)))
        scene = Scene([*mesh.triangles, ...])

    positions  vertex positions; normals: vertex normals (may be empty)
    triangles  triples of corners (position index, normal index or None), as
               rtpy.io.obj.ObjMesh.triangles
    A triangle whose three corners have non-zero normals is a SmoothTriangle, else
    a flat Triangle. Faces that are degenerate after the transform (collinear corners) are
    left out and counted in `skipped`; `triangles` holds the rest.
    """

    def __init__(
        self,
        positions: Sequence[tuple[float, float, float]],
        normals: Sequence[tuple[float, float, float]],
        triangles: Sequence[tuple[tuple[int, int | None], ...]],
        material,
        transform: Transform | None = None,
    ) -> None:
        transform = transform or Transform()
        points = [transform.point(Vec3(*p)) for p in positions]
        for k, p in enumerate(points):
            checked(f"vertex {k + 1} (after the transform)", point, p.tolist())
        shading = [transform.normal(Vec3(*n)) for n in normals]
        self.triangles: list[Triangle] = []
        self.skipped = 0
        for corners in triangles:
            a, b, c = (points[p] for p, _ in corners)
            ns = [shading[n] for _, n in corners if n is not None]
            try:
                if len(ns) == 3 and all(_usable(n) for n in ns):
                    tri = SmoothTriangle(a, b, c, ns, material)
                else:
                    tri = Triangle(a, b, c, material)
            except ValueError:
                self.skipped += 1
                continue
            self.triangles.append(tri)

    @classmethod
    def from_obj(cls, path, material, transform: Transform | None = None) -> Mesh:
        """The mesh of a Wavefront OBJ file (rtpy.io.obj.read_obj, whose ObjError
        names the line it cannot read)."""
        from .io.obj import read_obj

        obj = read_obj(path)
        return cls(obj.positions, obj.normals, obj.triangles, material, transform)
