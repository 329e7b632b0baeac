"""Materials for the tests of rtpy.testing: a correct narrow lobe, a correct material
that transmits, and Lambertians with one planted mistake each (every check must catch
the one meant for it)."""

from __future__ import annotations

import math

from rtpy.materials import Lambertian, Material, Phong
from rtpy.onb import ONB
from rtpy.ray import spawn_ray
from rtpy.sampling import generator
from rtpy.scatter_info import ScatterInfo
from rtpy.vec3 import BLACK, Color, Vec3, dot

INV_PI = 1.0 / math.pi


class PhongLobe(Phong):
    """A correct narrow lobe: f = kd albedo / pi + ks (n+2)/(2 pi) cos^n(alpha), alpha the
    angle between wi and the mirror direction of wo, sampled exactly (pdf (n+1)/(2 pi)
    cos^n(alpha)); samples below the surface are absorbed."""

    def __init__(self, exponent: float, kd: float = 0.0, ks: float = 1.0) -> None:
        super().__init__(Color(0.9, 0.6, 0.3), kd, ks, exponent)


class OverNormalised(Lambertian):
    """pdf() 10 % too large."""

    def pdf(self, ray_view, ray_light, hit):
        return 1.1 * super().pdf(ray_view, ray_light, hit)


class UniformSampler(Lambertian):
    """Samples the hemisphere uniformly but pdf() still says cos / pi."""

    def scattering(self, ray_in, hit):
        r = generator().random
        z, phi = r(), 2.0 * math.pi * r()
        s = math.sqrt(1.0 - z * z)
        d = Vec3(s * math.cos(phi), s * math.sin(phi), z)
        return ScatterInfo(
            spawn_ray(hit.point, hit.normal, d), self.albedo.value(hit) * z, z / math.pi
        )


class SecretAbsorber(Lambertian):
    """Absorbs 2 % of the samples, but pdf() still integrates to 1."""

    def scattering(self, ray_in, hit):
        if generator().random() < 0.02:
            return None
        return super().scattering(ray_in, hit)


class HalfSampler(Lambertian):
    """Only ever scatters to x > 0 (absorbs the rest), and pdf() says so: consistent
    sampling, but the BRDF is albedo / pi on the whole hemisphere."""

    def scattering(self, ray_in, hit):
        s = super().scattering(ray_in, hit)
        return s if s.scattered_ray.direction.e0 > 0.0 else None

    def pdf(self, ray_view, ray_light, hit):
        return super().pdf(ray_view, ray_light, hit) if ray_light.direction.e0 > 0.0 else 0.0


class ForgetsPdf(Lambertian):
    """attenuation = albedo * cos: the division by the pdf is missing."""

    def scattering(self, ray_in, hit):
        s = super().scattering(ray_in, hit)
        s.attenuation = s.attenuation * s.scattered_ray.direction.e2
        return s


class WrongRecordedPdf(Lambertian):
    """ScatterInfo.pdf is the uniform density, pdf() the cosine density."""

    def scattering(self, ray_in, hit):
        s = super().scattering(ray_in, hit)
        s.pdf = 1.0 / (2.0 * math.pi)
        return s


class NonReciprocal(Lambertian):
    """f grows with the viewer's cosine only."""

    def BRDF(self, ray_view, ray_light, hit):
        f = super().BRDF(ray_view, ray_light, hit)
        return f * (0.5 - ray_view.direction.e2)  # -direction.e2 = cos(theta_o)


class NegativeAtGrazing(Lambertian):
    """f < 0 for light within 0.06 degrees of the horizon."""

    def BRDF(self, ray_view, ray_light, hit):
        z = ray_light.direction.e2
        if z <= 0.0:
            return BLACK
        return self.albedo.value(hit) * (INV_PI * (z - 1e-3) / z)


class CrashesAtGrazing(Lambertian):
    def pdf(self, ray_view, ray_light, hit):
        z = ray_light.direction.e2
        if 0.0 < z < 1e-4:
            raise ZeroDivisionError("grazing")
        return super().pdf(ray_view, ray_light, hit)


class DiffuseTransmitter(Material):
    """Diffuse on both sides of the surface: f = r / pi toward the viewer's side, t / pi
    through it (0 < t); directions drawn uniformly over the viewer's hemisphere with
    probability r / (r + t), else over the other one. Reciprocal (no refraction).
    Uniform, not cosine-weighted, sampling and t > 0 keep it from being a Lambertian
    in disguise (this file ships to students: nothing here answers a task)."""

    def __init__(self, r: float = 0.3, t: float = 0.5) -> None:
        if not t > 0.0:
            raise ValueError(f"t: a transmitter transmits, expected t > 0, got {t!r}")
        self.r, self.t = r, t

    def BRDF(self, ray_view, ray_light, hit):
        cos_o, cos_i = -dot(hit.normal, ray_view.direction), dot(hit.normal, ray_light.direction)
        if cos_o <= 0.0 or cos_i == 0.0:
            return BLACK
        value = (self.r if cos_i > 0.0 else self.t) * INV_PI
        return Color(value, value, value)

    def pdf(self, ray_view, ray_light, hit):
        cos_o, cos_i = -dot(hit.normal, ray_view.direction), dot(hit.normal, ray_light.direction)
        if cos_o <= 0.0 or cos_i == 0.0:
            return 0.0
        p_r = self.r / (self.r + self.t)
        return (p_r if cos_i > 0.0 else 1.0 - p_r) / (2.0 * math.pi)

    def scattering(self, ray_in, hit):
        if dot(hit.normal, ray_in.direction) >= 0.0:
            return None
        r = generator().random
        z, phi = r(), 2.0 * math.pi * r()
        s = math.sqrt(max(0.0, 1.0 - z * z))
        local = Vec3(s * math.cos(phi), s * math.sin(phi), z)
        side = hit.normal if r() < self.r / (self.r + self.t) else -hit.normal
        ray = spawn_ray(hit.point, hit.normal, ONB(side).to_world(local))
        weight = 2.0 * (self.r + self.t) * z  # f |cos| / pdf on either side
        return ScatterInfo(ray, Color(weight, weight, weight), self.pdf(ray_in, ray, hit))


class AbsorbsEverything(Lambertian):
    """Reflects nothing: BRDF black, pdf 0, scattering() None. Consistent, and no
    check of sampling may pass it (it shows nothing)."""

    def BRDF(self, ray_view, ray_light, hit):
        return BLACK

    def pdf(self, ray_view, ray_light, hit):
        return 0.0

    def scattering(self, ray_in, hit):
        return None


class UpperPdfOnly(DiffuseTransmitter):
    """pdf() forgets the transmitted half: 0 below the surface."""

    def pdf(self, ray_view, ray_light, hit):
        if dot(hit.normal, ray_light.direction) <= 0.0:
            return 0.0
        return super().pdf(ray_view, ray_light, hit)
