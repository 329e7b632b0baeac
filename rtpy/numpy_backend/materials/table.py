"""MaterialTable: a scene's materials as a few batched kernels, one per material class."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

import numpy as np

from ...materials.material import Material
from ...texture import Texture
from ..arrays import put_rows
from ..hit_info import HitBatch
from ..scatter_info import ScatterBatch, SpecularRays
from .blinn_phong import BlinnPhongKernel
from .cook_torrance import cook_torrance_kernel
from .dielectric import DielectricKernel
from .diffuse_light import DiffuseLightKernel
from .fallback import ScalarFallback
from .lambertian import GlowingLambertianKernel, LambertianKernel
from .material import AlbedoKernel, Kernel
from .metal import MetalKernel
from .mirror import MirrorKernel
from .oren_nayar import OrenNayarKernel
from .phong import PhongKernel
from .rough_dielectric import rough_dielectric_kernel
from .ward import WardKernel

KernelChoice = type[Kernel] | Callable[[Material], type[Kernel]]

# The kernels by the qualified name of the material class they compute (class_name):
# its kernel class, or a function choosing one from the instance (Cook-Torrance and
# the rough dielectric have one kernel per distribution, so no kernel branches per
# hit). Names, not classes, so that a class this backend does not import has a twin:
# the closed-form scenes' GlowingLambertian lives in rtpy.testing, above this backend.
KERNELS: dict[str, KernelChoice] = {
    "rtpy.materials.lambertian.Lambertian": LambertianKernel,
    "rtpy.testing.analytic_scenes.GlowingLambertian": GlowingLambertianKernel,
    "rtpy.materials.mirror.Mirror": MirrorKernel,
    "rtpy.materials.metal.Metal": MetalKernel,
    "rtpy.materials.dielectric.Dielectric": DielectricKernel,
    "rtpy.materials.rough_dielectric.RoughDielectric": rough_dielectric_kernel,
    "rtpy.materials.diffuse_light.DiffuseLight": DiffuseLightKernel,
    "rtpy.materials.phong.Phong": PhongKernel,
    "rtpy.materials.blinn_phong.BlinnPhong": BlinnPhongKernel,
    "rtpy.materials.cook_torrance.CookTorrance": cook_torrance_kernel,
    "rtpy.materials.ward.Ward": WardKernel,
    "rtpy.materials.oren_nayar.OrenNayar": OrenNayarKernel,
}


def class_name(cls: type) -> str:
    """A class's qualified name, "module.Class": what KERNELS is keyed by."""
    return f"{cls.__module__}.{cls.__qualname__}"


def kernel_class(material: Material) -> type[Kernel]:
    """The kernel for `material`: the one registered for its own class (a subclass
    may override anything, so it gets the scalar fallback), and the fallback for
    anything unusual."""
    choose = KERNELS.get(class_name(type(material)))
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
    the number of material classes, not on the number of materials. The methods are
    the scalar Material's (see material.py), with a material id per hit.

    is_specular  (M,) bool: Material.is_specular per id (delta scattering only)
    is_emitter   (M,) bool: Material.is_emitter per id
    inert        (M,) bool: no BRDF and no scattering (light arriving there ends)
    reads_uv, reads_tangent  whether any material reads a hit's (u, v) or tangent
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
        self.is_specular = np.array([bool(m.is_specular) for m in self.materials], dtype=bool)
        self.is_emitter = np.array([bool(m.is_emitter) for m in self.materials], dtype=bool)
        self.inert = np.array(
            [not (k.has_brdf or k.scatters) for k in (self.kernels[i] for i in self.kind)],
            dtype=bool,
        )
        self.reads_uv = any(k.reads_uv for k in self.kernels)
        self.reads_tangent = any(k.reads_tangent for k in self.kernels)

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

    def _colors(self, method: str, flag: str | None, fill: float, ids, hits, *args) -> np.ndarray:
        """(N, 3) of the kernels' `method`, `fill` for the hits of kernels without `flag`."""
        out = np.full((len(hits), 3), fill)
        for kernel, rows, slots, part in self._groups(ids, hits, flag):
            if isinstance(rows, slice):
                return getattr(kernel, method)(slots, part, *args)  # one kernel has all the hits
            value = getattr(kernel, method)(slots, part, *(a.take(rows, axis=0) for a in args))
            put_rows(out, rows, value)
        return out

    def flat_color(self, ids: np.ndarray, hits: HitBatch) -> np.ndarray:
        """(N, 3) as Material.flat_color: the albedo's value, white without one."""
        return self._colors("flat_color", None, 1.0, ids, hits)

    def emitting(self, ids: np.ndarray, hits: HitBatch) -> np.ndarray:
        """(N, 3) as Material.emitting: radiance emitted back along the arriving rays."""
        return self._colors("emitting", "emits", 0.0, ids, hits)

    def BRDF(self, ids: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        """(N, 3) as Material.BRDF: f_r for light directions wi (N, 3) leaving the
        surface (0 for specular materials, as their scalar methods)."""
        return self._colors("BRDF", "has_brdf", 0.0, ids, hits, wi)

    def pdf(self, ids: np.ndarray, hits: HitBatch, wi: np.ndarray) -> np.ndarray:
        """(N,) as Material.pdf: the density with which scattering() picks wi."""
        pdf = np.zeros(len(hits))
        for kernel, rows, slots, part in self._groups(ids, hits, "has_brdf"):
            if isinstance(rows, slice):
                return kernel.pdf(slots, part, wi)  # one kernel has all the hits
            pdf[rows] = kernel.pdf(slots, part, wi.take(rows, axis=0))
        return pdf

    def BRDF_and_pdf(
        self, ids: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(BRDF(), pdf()) at once, as light sampling needs them."""
        f, pdf = np.zeros((len(hits), 3)), np.zeros(len(hits))
        for kernel, rows, slots, part in self._groups(ids, hits, "has_brdf"):
            if isinstance(rows, slice):
                return kernel.BRDF_and_pdf(slots, part, wi)  # one kernel has all the hits
            fk, pdf[rows] = kernel.BRDF_and_pdf(slots, part, wi.take(rows, axis=0))
            put_rows(f, rows, fk)
        return f, pdf

    def scattering(self, ids: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        """One Material.scattering sample per hit, drawn from `rng`."""
        out = ScatterBatch.absorbed(len(hits))
        for kernel, rows, slots, part in self._groups(ids, hits, "scatters"):
            if isinstance(rows, slice):
                return kernel.scattering(slots, part, rng)  # one kernel has all the hits
            out.put(rows, kernel.scattering(slots, part, rng))
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
