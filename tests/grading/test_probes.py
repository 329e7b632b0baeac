"""The probes' registry and helpers (rtpy.grading.probes): materials built from plain
data, a week's probes loaded once, two weeks that name a probe alike refused."""

from __future__ import annotations

import numpy as np
import pytest

from rtpy.grading import probes
from rtpy.materials import Phong


def test_a_material_is_built_from_plain_data():
    m = probes.make_material({"type": "Phong", "albedo": [0.5, 0.4, 0.3], "kd": 0.5, "ks": 0.4})
    assert isinstance(m, Phong) and m.kd == 0.5
    with pytest.raises(ValueError, match="no material class"):
        probes.make_material({"type": "os"})


def test_probes_of_one_week_load_once_and_two_weeks_cannot_share_a_name(tmp_path):
    code = "from rtpy.grading.probes import probe\nfrom rtpy.grading.protocol import Float\n"
    code += "@probe(returns=Float)\ndef probes_test_value():\n    return 1.0\n"
    first = tmp_path / "week98" / "probes.py"
    first.parent.mkdir()
    first.write_text(code)
    registry = probes.load_probes([first, first])
    assert registry["probes_test_value"].function() == 1.0
    other = tmp_path / "week99" / "probes.py"
    other.parent.mkdir()
    other.write_text(code)
    with pytest.raises(ValueError, match="two probes are called 'probes_test_value'"):
        probes.load_probes([other])


def test_the_render_probe_renders_each_seed():
    probes.SCENES["probes_test_sky"] = lambda: __import__("rtpy").Scene(
        [], sky=True, camera=__import__("rtpy").Camera(width=8, aspect_ratio=2.0)
    )
    stack = probes.render("probes_test_sky", [1, 2], {"spp": 2, "integrator": "jittered"})
    assert stack.shape == (2, 4, 8, 3) and np.isfinite(stack).all()
    assert not np.array_equal(stack[0], stack[1])  # two seeds, two renders


def test_given_code_that_answers_a_task_is_seen_however_it_is_called():
    """given_code_unused: a call of the watched module's code, through the class or a
    reference kept before the watch, raises GivenCodeUsed naming it; code that does
    not call it passes; the previous profile function is put back."""
    import sys

    from rtpy import Interval, Lambertian, Ray, Scene, Sphere, Vec3
    from rtpy.bvh import BVH

    scene = Scene([Sphere(Vec3(0, 0, -2), 0.5, Lambertian())])
    ray, interval = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1)), Interval(0.0, 5.0)
    any_hit = BVH.any_hit  # kept before the watch, as a submission could
    task = "Scene.find_occlusion (rtpy/scene.py)"
    before = sys.getprofile()
    for use in (
        lambda: scene.bvh().any_hit(ray, 0.0, 5.0),
        lambda: any_hit(scene.bvh(), ray, 0, 5),
    ):
        with pytest.raises(probes.GivenCodeUsed, match=r"find_occlusion .* called rtpy\.bvh\.BVH"):
            with probes.given_code_unused(("rtpy.bvh",), task):
                use()
    with probes.given_code_unused(("rtpy.bvh",), task):
        assert scene.find_occlusion(ray, interval) is True  # 1 object: no BVH
    assert sys.getprofile() is before
