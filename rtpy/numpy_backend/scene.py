"""BatchScene: a scene prepared for batches of rays, the twin of rtpy/scene.py.

The objects are split by kind into primitive sets (SphereSet, QuadSet, TriangleSet,
and a ScalarSet for shapes without a batched twin); find_intersection and
find_occlusion ask every set and keep the closest answer. The materials become a
MaterialTable, the lights a LightTable, and what escaping rays see is the scalar
Scene's background_radiance, for many directions at once.

Work the scene does not need is skipped: hits carry (u, v) only when a texture reads
them and tangents only when a material has a shading frame.
"""

from __future__ import annotations

import math

import numpy as np

from ..mesh import Mesh, SmoothTriangle
from ..quad import Quad
from ..scene import Scene
from ..sphere import Sphere
from ..triangle import Triangle
from .arrays import dot, rows, scale
from .hit_info import HitBatch, unused
from .hittable import PrimitiveSet, ScalarSet
from .light import LightTable
from .materials import MaterialTable
from .onb import tangent_of
from .quad import QuadSet
from .sphere import SphereSet
from .triangle import MeshSet, TriangleSet
from .vec3 import row

INF = math.inf
SPHERE, QUAD, TRIANGLE, OTHER = 0, 1, 2, 3  # the sets' kinds; each Mesh is a set of its own
# Exact types: a subclass may override hit_t (tests do), so it goes to the ScalarSet.
KINDS = {Sphere: SPHERE, Quad: QUAD, Triangle: TRIANGLE, SmoothTriangle: TRIANGLE}
SETS = (SphereSet, QuadSet, TriangleSet, ScalarSet)


class BatchScene:
    """A Scene's objects as primitive sets, its materials as a MaterialTable and its
    lights as a LightTable.

    The queries answer with primitive indices: every object is one primitive, except
    a Mesh, whose triangles are primitives first[i] .. first[i] + len(mesh) - 1 (in
    the objects' order, so ties go as if its triangles were in the list in its
    place). Primitive p is primitive local[p] of sets[kind[p]]: sets 0-3 are the
    spheres, quads, triangles and shapes without a batched twin, then one MeshSet per
    mesh, which reads the mesh's arrays and tree as they came from the parent.
    material_id[p] is its material's index in materials.materials (the distinct
    materials in first-use order). need_uv and need_tangent say what the hits of a
    batch must carry (else those fields are unused() zeros); smooth, that some
    triangles shade with interpolated vertex normals.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.objects = list(scene.objects)
        n = len(self.objects)
        groups: list[list[int]] = [[], [], [], []]
        meshes: list[int] = []
        obj_kind = np.empty(n, dtype=np.int32)
        obj_local = np.zeros(n, dtype=np.int32)
        size = np.ones(n, dtype=np.int64)
        for i, obj in enumerate(self.objects):
            if type(obj) is Mesh:
                obj_kind[i] = len(SETS) + len(meshes)
                size[i] = len(obj)
                meshes.append(i)
                continue
            kind = KINDS.get(type(obj), OTHER)
            obj_kind[i] = kind
            obj_local[i] = len(groups[kind])
            groups[kind].append(i)
        self.first = np.concatenate([[0], np.cumsum(size)[:-1]]).astype(np.int64)
        self.kind = np.repeat(obj_kind, size)
        # local: the objects' positions in their sets, then 0, 1, ... along each mesh
        self.local = np.repeat(obj_local, size)
        self.members = [self.first.take(g).astype(np.int32) for g in groups]
        for i in meshes:
            along = np.arange(size[i], dtype=np.int32)
            self.local[self.first[i] : self.first[i] + size[i]] = along
            self.members.append(along + np.int32(self.first[i]))
        self.sets: list[PrimitiveSet | None] = [
            SETS[kd]([self.objects[i] for i in g]) if g else None for kd, g in enumerate(groups)
        ]
        # a mesh with no triangles (all degenerate) is a set of none: no set
        self.sets.extend(MeshSet(self.objects[i]) if size[i] else None for i in meshes)
        distinct: list = []
        ids: dict[int, int] = {}
        obj_material = np.empty(n, dtype=np.int32)
        for i, obj in enumerate(self.objects):
            key = id(obj.material)
            if key not in ids:
                ids[key] = len(distinct)
                distinct.append(obj.material)
            obj_material[i] = ids[key]
        self.material_id = np.repeat(obj_material, size)
        self.materials = MaterialTable(distinct)
        self.need_uv = self.materials.reads_uv
        triangles = self.sets[TRIANGLE]
        self.smooth = (triangles is not None and bool(triangles.smooth.any())) or any(
            bool((self.objects[i].face_normals[:, 0] >= 0).any()) for i in meshes
        )
        self.need_tangent = self.materials.reads_tangent
        self.lights = LightTable(self)
        self.background_color = row(scene.background)

    # --- queries ------------------------------------------------------------------
    def _order(self) -> list[int]:
        # Brute-force sets first: their hits give the BVH traversals a t_max to prune with.
        return sorted(
            (kd for kd, s in enumerate(self.sets) if s is not None),
            key=lambda kd: (self.sets[kd].bvh is not None, kd == OTHER),
        )

    def find_intersection(
        self, o: np.ndarray, d: np.ndarray, t_max: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Scene.find_intersection(ray, FORWARD) for rays (o, d): (primitive index (N,),
        -1 for a miss; t (N,)) of each ray's closest hit with 0 < t < t_max (default inf)."""
        n = len(o)
        t_best = np.full(n, INF) if t_max is None else np.array(t_max, dtype=np.float64)
        obj = np.full(n, -1, dtype=np.int64)
        order = self._order()
        if len(order) == 1:  # one kind of primitive: its answer as it is
            t, k = self.sets[order[0]].closest_hit(o, d, 0.0, t_best)
            return np.where(k >= 0, self.members[order[0]].take(k), -1), t
        for kd in order:
            t, k = self.sets[kd].closest_hit(o, d, 0.0, t_best)
            hit = k >= 0
            t_best[hit] = t[hit]
            obj[hit] = self.members[kd][k[hit]]
        return obj, t_best

    def find_occlusion(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_max: np.ndarray,
        ignore: np.ndarray | None = None,
    ) -> np.ndarray:
        """Scene.find_occlusion(ray, Interval(0, t_max), ignore=...) for rays (o, d):
        (N,) bool, something (glass included) lies on the ray with 0 < t < t_max;
        ignore: per ray, a primitive index not to test (-1: none)."""
        blocked = np.zeros(len(o), dtype=bool)
        for kd in self._order():
            live = np.flatnonzero(~blocked)
            if live.size == 0:
                break
            local_ignore = None
            if ignore is not None:
                ig = ignore[live]
                local_ignore = np.where((ig >= 0) & (self.kind[ig] == kd), self.local[ig], -1)
                if not (local_ignore >= 0).any():
                    local_ignore = None
            prims = self.sets[kd]
            if live.size == len(o):  # no gathers
                _, k = prims.closest_hit(o, d, 0.0, t_max, any_hit=True, ignore=local_ignore)
                blocked = k >= 0
                continue
            _, k = prims.closest_hit(
                rows(o, live), rows(d, live), 0.0, t_max[live], any_hit=True, ignore=local_ignore
            )
            blocked[live[k >= 0]] = True
        return blocked

    def background_radiance(self, d: np.ndarray) -> np.ndarray:
        """Scene.background_radiance for (N, 3) directions d: the scene's environment
        (rtpy.environment) when it has one, else RTIOW's sky gradient by the
        direction's y component, else the constant background."""
        scene = self.scene
        if scene.environment is not None:
            return scene.environment.radiance_array(d)
        if not scene.sky:
            return np.broadcast_to(self.background_color, d.shape)
        a = 0.5 * (d[:, 1] / np.sqrt(dot(d, d)) + 1.0)
        return np.stack([1.0 - 0.5 * a, 1.0 - 0.3 * a, np.ones_like(a)], axis=1)

    # --- hit records --------------------------------------------------------------
    def _groups(self, obj: np.ndarray) -> tuple[np.ndarray, list[tuple[int, np.ndarray | slice]]]:
        """(local indices, [(kind, positions in obj)]) with a slice for a single kind."""
        kinds = self.kind[obj]
        local = self.local[obj]
        present = [kd for kd, s in enumerate(self.sets) if s is not None]
        if len(present) == 1:
            return local, [(present[0], slice(None))]
        groups = [(kd, np.flatnonzero(kinds == kd)) for kd in present]
        return local, [(kd, i) for kd, i in groups if i.size]

    def hit_batch(self, obj: np.ndarray, o: np.ndarray, d: np.ndarray, t: np.ndarray) -> HitBatch:
        """The HitBatch of rays (o, d) hitting objects obj at t (all hits, obj >= 0):
        Hittable.hit_info for many hits."""
        local, groups = self._groups(obj)
        if len(groups) == 1:
            kd, _ = groups[0]
            point, geo = self.sets[kd].geometric(local, o, d, t)
        else:
            n = len(obj)
            point, geo = np.empty((n, 3)), np.empty((n, 3))
            for kd, i in groups:
                point[i], geo[i] = self.sets[kd].geometric(local[i], o[i], d[i], t[i])
        return self.hits_at(obj, point, geo, d, t, (local, groups))

    def hits_at(
        self,
        obj: np.ndarray,
        point: np.ndarray,
        geo: np.ndarray,
        d: np.ndarray,
        t: np.ndarray,
        grouped=None,
    ) -> HitBatch:
        """The HitBatch of rays with directions d reaching `point` (geometric normal
        `geo`) on objects obj after distance t."""
        n = len(obj)
        local, groups = grouped if grouped is not None else self._groups(obj)
        front = dot(geo, d) < 0.0
        shading = geo
        if self.smooth:
            shading = np.empty((n, 3))
            for kd, i in groups:
                shading[i] = self.sets[kd].shading_normal(local[i], point[i], geo[i])
        normal = scale(shading, np.where(front, 1.0, -1.0))
        if self.need_uv:
            u, v = np.empty(n), np.empty(n)
            for kd, i in groups:
                u[i], v[i] = self.sets[kd].surface_uv(local[i], point[i])
        else:
            u = v = unused(n)
        if self.need_tangent:
            tangent = np.empty((n, 3))
            valid = np.empty(n, dtype=bool)
            for kd, i in groups:
                tangent[i], valid[i] = self.sets[kd].surface_tangent(local[i], point[i])
            if not valid.all():
                bad = ~valid
                tangent[bad] = tangent_of(normal[bad])
        else:
            tangent = unused(n, 3)
        return HitBatch(point, normal, -d, t, front, u, v, tangent)

    def set_of(self, obj: np.ndarray) -> list[tuple[PrimitiveSet, np.ndarray, np.ndarray | slice]]:
        """[(set, local indices, positions in obj)] grouping objects by kind; the
        positions are slice(None) when all objects are of one kind."""
        kinds = self.kind[obj]
        if len(kinds) and (kinds == kinds[0]).all():
            return [(self.sets[kinds[0]], self.local[obj], slice(None))]
        out = []
        for kd in range(len(self.sets)):
            i = np.flatnonzero(kinds == kd)
            if i.size:
                out.append((self.sets[kd], self.local[obj[i]], i))
        return out
