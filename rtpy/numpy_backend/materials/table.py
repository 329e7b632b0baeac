"""MaterialTable: a scene's materials as a few batched kernels, one per material class."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

import numpy as np

from ...materials import OrenNayar
from ...materials.material import Material
from ...texture import Texture
from ..arrays import put_rows
from ..hits import HitBatch
from .fallback import ScalarFallback
from .glossy import GLOSSY_KERNELS
from .kernel import AlbedoKernel, Kernel, ScatterBatch, SpecularRays
from .oren_nayar import OrenNayarKernel
from .simple import SIMPLE_KERNELS

# Material class -> its kernel class, or a function choosing one from the instance
# (Cook-Torrance has one kernel per distribution, so no kernel branches per hit).
KERNELS: dict[type, type[Kernel] | Callable[[Material], type[Kernel]]] = {
    **SIMPLE_KERNELS,
    **GLOSSY_KERNELS,
    OrenNayar: OrenNayarKernel,
}


def kernel_class(material: Material) -> type[Kernel]:
    """The kernel for `material`: by its exact class (a subclass may override anything,
    so it gets the scalar fallback), and the fallback for anything unusual."""
    choose = KERNELS.get(type(material))
    if choose is None:
        return ScalarFallback
    kernel = choose if isinstance(choose, type) else choose(material)
    if issubclass(kernel, AlbedoKernel) and not isinstance(
        getattr(material, "albedo", None), Texture
    ):
        return ScalarFallback  # an albedo replaced by something the scalar code may read
    return kernel


class MaterialTable:
    """Batched twins of a scene's materials; material id = index into `materials`.

    The instances are grouped by kernel (material class), each kernel holding its
    instances' parameters as arrays. A batched call splits the hits by kernel and makes
    one call per kernel present in the batch, so the number of numpy calls depends on
    the number of material classes, not on the number of materials.

    specular  (M,) bool: Material.is_specular per id (delta scattering only)
    emitter   (M,) bool: Material.is_emitter per id
    inert     (M,) bool: no BRDF and no scattering (eval and sample give only zeros)
    """

    def __init__(self, materials: Sequence[Material]) -> None:
        self.materials = list(materials)
        members: dict[type[Kernel], list[int]] = {}
        for i, material in enumerate(self.materials):
            members.setdefault(kernel_class(material), []).append(i)
        n = len(self.materials)
        self.kind = np.zeros(n, dtype=np.intp)  # id -> index into kernels
        self.slot = np.zeros(n, dtype=np.intp)  # id -> position among the kernel's materials
        self.kernels: list[Kernel] = []
        for k, (cls, ids) in enumerate(members.items()):
            self.kernels.append(cls([self.materials[i] for i in ids]))
            self.kind[ids] = k
            self.slot[ids] = np.arange(len(ids))
        self.specular = np.array([bool(m.is_specular) for m in self.materials], dtype=bool)
        self.emitter = np.array([bool(m.is_emitter) for m in self.materials], dtype=bool)
        # Neither a BRDF nor scattering (a DiffuseLight): light arriving there ends.
        self.inert = np.array(
            [not (k.evaluates or k.scatters) for k in (self.kernels[i] for i in self.kind)],
            dtype=bool,
        )

    def _groups(
        self, ids: np.ndarray, hits: HitBatch, flag: str | None = None
    ) -> Iterator[tuple[Kernel, np.ndarray | slice, np.ndarray, HitBatch]]:
        """(kernel, rows, slots, hits of those rows) for every kernel with hits in the
        batch whose `flag` (if given) is set; rows is slice(None) when one kernel has them all."""
        ids = np.asarray(ids, dtype=np.intp)
        slots = self.slot[ids]
        if len(self.kernels) == 1:
            present = [0] if len(ids) else []
            kind = None
        else:
            kind = self.kind[ids]
            counts = np.bincount(kind, minlength=len(self.kernels))
            present = np.flatnonzero(counts).tolist()
        for k in present:
            kernel = self.kernels[k]
            if flag is not None and not getattr(kernel, flag):
                continue
            if len(present) == 1:
                yield kernel, slice(None), slots, hits
            else:
                rows = np.flatnonzero(kind == k)
                yield kernel, rows, slots.take(rows), hits.take(rows)

    def flat_color(self, ids: np.ndarray, hits: HitBatch) -> np.ndarray:
        """(N, 3) as Material.flat_color: the albedo's value, white without one."""
        out = np.ones((len(hits), 3))
        for kernel, rows, slots, part in self._groups(ids, hits):
            out[rows] = kernel.flat_color(slots, part)
        return out

    def emitted(self, ids: np.ndarray, hits: HitBatch) -> np.ndarray:
        """(N, 3) as Material.emitting: radiance emitted back along the arriving rays."""
        out = np.zeros((len(hits), 3))
        for kernel, rows, slots, part in self._groups(ids, hits, "emits"):
            if isinstance(rows, slice):
                return kernel.emitted(slots, part)  # one kernel has all the hits
            put_rows(out, rows, kernel.emitted(slots, part))
        return out

    def eval(
        self, ids: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(f_r (N, 3), pdf (N,)) as BRDF() and pdf() for light directions wi (N, 3)
        leaving the surface (0 for specular materials, as their scalar methods)."""
        f, pdf = np.zeros((len(hits), 3)), np.zeros(len(hits))
        for kernel, rows, slots, part in self._groups(ids, hits, "evaluates"):
            if isinstance(rows, slice):
                return kernel.eval(slots, part, wi)  # one kernel has all the hits
            fk, pdf[rows] = kernel.eval(slots, part, wi.take(rows, axis=0))
            put_rows(f, rows, fk)
        return f, pdf

    def sample(self, ids: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        """One scattering() sample per hit, drawn from `rng`."""
        out = ScatterBatch.absorbed(len(hits))
        for kernel, rows, slots, part in self._groups(ids, hits, "scatters"):
            if isinstance(rows, slice):
                return kernel.sample(slots, part, rng)  # one kernel has all the hits
            out.put(rows, kernel.sample(slots, part, rng))
        return out

    def specular_rays(self, ids: np.ndarray, hits: HitBatch) -> SpecularRays:
        """As Material.specular_rays, for the Whitted integrator: entry k holds every
        hit's k-th ray as (direction (N, 3), weight (N, 3), mask (N,) bool): the
        reflected ray first, then the refracted one where a dielectric has one."""
        n = len(hits)
        entries: SpecularRays = []
        for kernel, rows, slots, part in self._groups(ids, hits, "has_specular_rays"):
            for k, (direction, weight, mask) in enumerate(kernel.specular_rays(slots, part)):
                if k == len(entries):
                    entries.append((np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, bool)))
                entries[k][0][rows] = direction
                entries[k][1][rows] = weight
                entries[k][2][rows] = mask
        return entries
