"""The local test setup of the material checks, and draws of scattering() in it.

A flat surface at the origin with normal (0, 0, 1) and tangent (1, 0, 0). The
incoming ray arrives from incident angle theta (and azimuth phi), that is
ray_in.direction = -(sin t cos p, sin t sin p, cos t), so the viewer sits at
wo = (sin t cos p, sin t sin p, cos t). In this frame the local and world
coordinates are the same.

The normal faces the viewer, as hit.normal always does. Seen from outside (the
default) the hit is on the front face; seen from inside (inside=True) on the back
face: the viewer is in the material (inside glass), the geometric outside below.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..hit_info import HitInfo
from ..materials.material import Material
from ..ray import Ray
from ..sampling import make_generator, use_generator
from ..vec3 import Color, Vec3

__all__ = [
    "ABSORBED",
    "SCATTERED",
    "SPECULAR",
    "Samples",
    "brdf_between",
    "draw_samples",
    "incident_ray",
    "light_ray",
    "local_direction",
    "local_hit",
    "view_ray",
]

NORMAL = Vec3(0.0, 0.0, 1.0)
TANGENT = Vec3(1.0, 0.0, 0.0)
ORIGIN = Vec3(0.0, 0.0, 0.0)
TWO_PI = 2.0 * math.pi

# Tags that keep the random streams of the different checks apart.
SAMPLING, RECIPROCITY, NON_NEGATIVE = 1, 2, 3


# --- the local test setup ------------------------------------------------------------------


def local_direction(theta_deg: float, phi_deg: float = 0.0) -> Vec3:
    """The unit vector at polar angle theta from the normal (0, 0, 1), azimuth phi from x."""
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    s = math.sin(t)
    return Vec3(s * math.cos(p), s * math.sin(p), math.cos(t))


def local_hit(material: Material | None = None, inside: bool = False) -> HitInfo:
    """A hit on the flat test surface: point at the origin, normal (0, 0, 1),
    tangent (1, 0, 0), surface coordinates (0.5, 0.5); the front face, or with
    inside=True the back face (the viewer inside the material)."""
    hit = HitInfo(ORIGIN, NORMAL, 1.0, not inside, material, None, 0.5, 0.5)
    hit.tangent = TANGENT
    return hit


def view_ray(wo: Vec3) -> Ray:
    """The ray arriving at the origin from the viewer in unit direction wo (direction -wo)."""
    return Ray(wo, Vec3(-wo.e0, -wo.e1, -wo.e2))


def light_ray(wi: Vec3) -> Ray:
    """The ray leaving the origin toward the light in unit direction wi."""
    return Ray(ORIGIN, wi)


def incident_ray(theta_deg: float, phi_deg: float = 0.0) -> Ray:
    """The incoming ray of the test setup: direction -(sin t cos p, sin t sin p, cos t)."""
    return view_ray(local_direction(theta_deg, phi_deg))


def turned_over(v: Vec3) -> Vec3:
    """v in the test setup turned over (half a turn about the tangent x): (x, -y, -z)."""
    return Vec3(v.e0, -v.e1, -v.e2)


def brdf_between(material: Material, wo: Vec3, wi: Vec3, inside: bool = False) -> Color:
    """material.BRDF for the viewer in unit direction wo and the light in unit direction
    wi, on either side of the test surface (inside: the side above is the inside). A
    viewer below the surface faces the other face: the setup is turned over, so that
    the normal faces the viewer as always."""
    if wo.e2 >= 0.0:
        return material.BRDF(view_ray(wo), light_ray(wi), local_hit(material, inside))
    hit = local_hit(material, not inside)
    return material.BRDF(view_ray(turned_over(wo)), light_ray(turned_over(wi)), hit)


# --- sampling the material ------------------------------------------------------------------

SCATTERED, ABSORBED, SPECULAR = 0, 1, 2


@dataclass
class Samples:
    """n draws of scattering() for one incident direction of the test setup.

    directions (n, 3), weights (n, 3) and pdfs (n,) are NaN where status is not
    SCATTERED; status is SCATTERED, ABSORBED (scattering returned None) or
    SPECULAR (a delta bounce, ScatterInfo.is_specular). inside: the viewer was
    inside the material (the hit on the back face).
    """

    incident_deg: float
    phi_deg: float
    directions: np.ndarray
    weights: np.ndarray
    pdfs: np.ndarray
    status: np.ndarray
    seconds: float
    inside: bool = False

    @property
    def n(self) -> int:
        return len(self.status)

    @property
    def scattered(self) -> np.ndarray:
        return self.status == SCATTERED

    @property
    def transmitted(self) -> np.ndarray:
        """The scattered samples that went through the surface (below it)."""
        return self.scattered & (self.directions[:, 2] < 0.0)


def sampling_generator(
    seed: int, tag: int, incident_deg: float, phi_deg: float, inside: bool = False
):
    key = (seed, tag, round(incident_deg * 1e6), round(phi_deg * 1e6))
    return make_generator(*key, 1) if inside else make_generator(*key)


def draw_samples(
    material: Material,
    incident_deg: float,
    n: int = 100_000,
    *,
    inside: bool = False,
    seed: int = 0,
    phi_deg: float = 0.0,
) -> Samples:
    """Call material.scattering() n times for the incoming ray of the test setup,
    under a generator fixed by (seed, incident angle, phi, side)."""
    return scatter_draws(material, incident_deg, n, seed, phi_deg, inside, SAMPLING)


def scatter_draws(
    material: Material,
    incident_deg: float,
    n: int,
    seed: int,
    phi_deg: float,
    inside: bool,
    tag: int,
) -> Samples:
    """n draws of material.scattering() under sampling_generator(seed, tag, ...)."""
    ray_in = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material, inside)
    nan = math.nan
    none_row = (nan, nan, nan, nan, nan, nan, nan)
    rows, status = [], []
    scatter = material.scattering
    start = time.perf_counter()
    with use_generator(sampling_generator(seed, tag, incident_deg, phi_deg, inside)):
        for _ in range(n):
            s = scatter(ray_in, hit)
            if s is None:
                rows.append(none_row)
                status.append(ABSORBED)
            elif s.is_specular:
                rows.append(none_row)
                status.append(SPECULAR)
            else:
                d, a = s.scattered_ray.direction, s.attenuation
                rows.append((d.e0, d.e1, d.e2, a.e0, a.e1, a.e2, s.pdf))
                status.append(SCATTERED)
    seconds = time.perf_counter() - start
    table = np.array(rows, dtype=float).reshape(n, 7)
    return Samples(
        incident_deg,
        phi_deg,
        table[:, 0:3],
        table[:, 3:6],
        table[:, 6],
        np.array(status, dtype=np.int8),
        seconds,
        inside,
    )


def get_samples(subject, incident_deg, n, seed, phi_deg, samples, inside=False) -> Samples:
    """The given samples (checked to be of this setup), or n draws of the subject's."""
    if samples is None:
        return subject.draw(incident_deg, n, seed=seed, phi_deg=phi_deg, inside=inside)
    if (samples.incident_deg, samples.phi_deg, samples.inside) != (incident_deg, phi_deg, inside):
        raise ValueError("the samples were drawn for another incident direction")
    return samples


# --- numbers in messages ---------------------------------------------------------------------


def close(a: float, b: float, rel_tol: float) -> bool:
    """Equal to rel_tol, or both below 1e-3 * rel_tol (1e-12 for rel_tol = 1e-9)."""
    return math.isclose(a, b, rel_tol=rel_tol, abs_tol=1e-3 * rel_tol)


def vector_text(v: Sequence[float]) -> str:
    """(x, y, z) with 6 significant digits."""
    return "(" + ", ".join(f"{x:.6g}" for x in v) + ")"


def color_text(v: Sequence[float], spec: str = ".6g") -> str:
    """(r, g, b); a grey colour (three equal numbers) as one number."""
    v = tuple(v)
    if len(v) == 3 and v[0] == v[1] == v[2]:
        return format(v[0], spec)
    return "(" + ", ".join(format(x, spec) for x in v) + ")"
