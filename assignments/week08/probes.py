"""Week 08 probes: what the graders of test_week08.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py).

The reflection models are asked through the shared material probes (material_brdf,
material_pdf, material_draw: rtpy.grading.remote_material.RemoteMaterial); the path
integrator through the shared render probe, of the scenes built here. The verdicts
are the graders'."""

from rtpy import Camera, Color, Lambertian, Quad, Scene, Sphere, Vec3
from rtpy.grading.probes import MATERIALS, color, make_material, scene_builder, vec
from rtpy.materials import BlinnPhong, CookTorrance, DiffuseLight, Phong
from rtpy.testing.analytic_scenes import GlowingLambertian


class GlowingDiffuse(Lambertian):
    """A Lambertian surface of grey albedo rho that also emits Le from both faces (for
    the furnace); in a material spec, le is given as three numbers."""

    is_emitter = True

    def __init__(self, rho: float, le: Color) -> None:
        super().__init__(Color(rho, rho, rho))
        self.le = le

    def emitting(self, hit):
        return self.le


MATERIALS["GlowingDiffuse"] = GlowingDiffuse


@scene_builder
def week08_glossy_balls():
    """The graded render: a Phong, a Blinn-Phong and a Cook-Torrance ball on a grey
    floor under a quad light."""
    ground = Lambertian(Color(0.5, 0.5, 0.5))
    objects = [
        Quad(Vec3(-4, 0, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), ground),
        Sphere(Vec3(-1.1, 0.5, -2.5), 0.5, Phong(Color(0.7, 0.2, 0.2), kd=0.6, ks=0.3, exponent=8)),
        Sphere(
            Vec3(0.0, 0.5, -2.5), 0.5, BlinnPhong(Color(0.2, 0.7, 0.2), kd=0.6, ks=0.3, exponent=30)
        ),
        Sphere(
            Vec3(1.1, 0.5, -2.5),
            0.5,
            CookTorrance(Color(0.2, 0.2, 0.7), kd=0.6, ks=0.4, roughness=0.2),
        ),
        Quad(Vec3(-0.8, 2.5, -3.0), Vec3(1.6, 0, 0), Vec3(0, 0, 1.0), DiffuseLight(Color(5, 5, 5))),
    ]
    camera = Camera(Vec3(0, 1.2, 0.8), Vec3(0, 0.5, -2.5), vfov=50, aspect_ratio="16:9", width=32)
    return Scene(objects, background=Color(0.05, 0.05, 0.08), camera=camera)


def _furnace(material, eye: list, look_at: list) -> Scene:
    camera = Camera(vec(eye), vec(look_at), vfov=90, aspect_ratio=1.0, width=8)
    return Scene([Sphere(Vec3(0, 0, 0), 2.0, material)], camera=camera)


@scene_builder
def week08_furnace(material: dict, eye: list, look_at: list):
    """The camera at eye, looking at look_at, inside a closed sphere of radius 2 at the
    origin of the material `material` (a spec for make_material), 8 x 8 pixels."""
    return _furnace(make_material(material), eye, look_at)


@scene_builder
def week08_glowing_furnace(albedo: list, emit: list, eye: list, look_at: list):
    """week08_furnace with a GlowingLambertian(albedo, emit) sphere (rtpy.testing)."""
    return _furnace(GlowingLambertian(color(albedo), color(emit)), eye, look_at)
