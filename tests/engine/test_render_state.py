"""rtpy.engine.render_state: a render kept in its checkpoint when Ctrl-C, a time limit or a
crash stops it, continued to the image an uninterrupted render gives, bit for bit;
a checkpoint of another render refused in one line, the file untouched."""

from __future__ import annotations

import json

import numpy as np
import pytest

import rtpy
from rtpy import Color, Lambertian, Scene, Sphere, Vec3
from rtpy._bvh_build import build_tree
from rtpy.engine.backend import make_backend
from rtpy.engine.render_state import FORMAT, Checkpoint, ResumeError, state_path
from rtpy.mesh import Mesh
from rtpy.render_settings import RenderSettings

from .test_renderer import Clock, small_scene

SPP = 8


class Stopping(Sphere):
    """A sphere that stops the render (raising `stop`) after `calls` intersection
    tests; its count lives in the class, not in the scene the checkpoint knows."""

    calls = 10**12
    stop: type[BaseException] = KeyboardInterrupt

    def __init__(self) -> None:
        super().__init__(Vec3(0, 0, -50), 1.0, Lambertian())

    def hit_t(self, ray, t_min, t_max):
        type(self).calls -= 1
        if type(self).calls == 0:
            raise type(self).stop("stopped")
        return super().hit_t(ray, t_min, t_max)


@pytest.fixture
def stopping(monkeypatch):
    """A scene and camera with a Stopping sphere (its class, reset after the test)."""
    monkeypatch.setattr(Stopping, "calls", 10**12)
    monkeypatch.setattr(Stopping, "stop", KeyboardInterrupt)
    scene, camera = small_scene()
    scene.add_object(Stopping())
    return scene, camera


def test_a_render_stopped_by_ctrl_c_resumes_to_the_uninterrupted_image(tmp_path, stopping):
    state = tmp_path / "out.png.resume.npz"
    scene, camera = stopping
    full = rtpy.render(scene, camera=camera, spp=SPP, seed=7)
    Stopping.calls = 5000  # in the second or third pass
    stopped = rtpy.render(scene, camera=camera, spp=SPP, seed=7, checkpoint=state)
    assert stopped.interrupted and 1 <= stopped.samples_min < SPP and state.exists()
    Stopping.calls = 10**12
    resumed = rtpy.render(scene, camera=camera, spp=SPP, seed=7, checkpoint=state, resume=True)
    assert resumed.stats["resumed_samples"] == stopped.samples_min
    np.testing.assert_array_equal(resumed.linear, full.linear)
    assert not state.exists()  # finished: the state goes


@pytest.mark.slow
def test_a_render_stopped_by_its_time_limit_resumes_to_the_same_image(tmp_path, monkeypatch):
    """The state holds the whole passes and the units of the pass in progress; the
    resumed render renders the rest (fewer paths than the whole)."""
    state = tmp_path / "s.npz"
    scene, camera = small_scene()
    camera = camera.with_width(100)  # 100 x 56: passes of 2, 2, 3, ... units
    kw = dict(camera=camera, spp=SPP, seed=8, checkpoint=state)
    full = rtpy.render(scene, camera=camera, spp=SPP, seed=8)
    with monkeypatch.context() as m:
        m.setattr("rtpy.engine.renderer.time", Clock())
        stopped = rtpy.render(scene, time=4.5, **kw)  # four units: the first pass and more
    assert stopped.stats["stopped"] == "time limit" and stopped.samples_min == 2
    resumed = rtpy.render(scene, resume=True, **kw)
    assert resumed.stats["paths_rendered"] < full.stats["paths_rendered"] - stopped.stats["paths"]
    np.testing.assert_array_equal(resumed.linear, full.linear)


def test_a_failure_mid_render_keeps_what_is_finished(tmp_path, stopping):
    """A failure (a bug in a material, a worker lost) saves the state before it is
    raised: the resumed render is the uninterrupted one."""
    state = tmp_path / "s.npz"
    scene, camera = stopping
    full = rtpy.render(scene, camera=camera, spp=SPP, seed=9)
    Stopping.calls, Stopping.stop = 6000, RuntimeError
    with pytest.raises(RuntimeError, match="stopped"):
        rtpy.render(scene, camera=camera, spp=SPP, seed=9, checkpoint=state)
    assert state.exists()
    Stopping.calls = 10**12
    resumed = rtpy.render(scene, camera=camera, spp=SPP, seed=9, checkpoint=state, resume=True)
    assert resumed.stats["resumed_samples"] >= 1
    np.testing.assert_array_equal(resumed.linear, full.linear)


@pytest.mark.slow
def test_the_state_is_saved_as_the_render_goes(tmp_path, monkeypatch):
    """A crash that writes nothing more (a killed process, a power cut) loses only
    what came after the last save: here one after every unit, each holding more."""
    monkeypatch.setattr("rtpy.engine.renderer.CHECKPOINT_SECONDS", 0.0)
    state = tmp_path / "s.npz"
    scene, camera = small_scene()
    held = []

    def look(image) -> None:
        with np.load(state) as saved:
            held.append(saved["sums"][..., 3].sum() + saved["current"][..., 3].sum())

    rtpy.render(scene, camera=camera.with_width(100), spp=SPP, checkpoint=state,
                preview=look, preview_seconds=0)  # fmt: skip
    assert len(held) > 10 and held == sorted(held) and len(set(held)) == len(held)


@pytest.fixture
def stopped_state(tmp_path, stopping):
    """A checkpoint of the stopping scene at SPP, seed 1, stopped after its first
    passes: (its path, the scene, the camera)."""
    state = tmp_path / "s.npz"
    scene, camera = stopping
    Stopping.calls = 5000
    rtpy.render(scene, camera=camera, spp=SPP, seed=1, checkpoint=state)
    Stopping.calls = 10**12
    return state, scene, camera


@pytest.mark.parametrize(
    "change,message",
    [
        ({"spp": 16}, "saved with spp = 8, not 16"),
        ({"seed": 2}, "saved with seed = 1, not 2"),
        ({"width": 20}, "saved with width = 40, not 20"),
        ({"backend": "numpy"}, "saved with backend = 'scalar', not 'numpy'"),
        ({"sampler": "sobol"}, "saved with sampler = 'independent', not 'sobol'"),
        ({"scene": "albedo"}, "saved for another scene"),
    ],
)
def test_a_checkpoint_of_another_render_is_refused_and_kept(stopped_state, change, message):
    state, scene, camera = stopped_state
    before = state.read_bytes()
    kw = {"camera": camera, "spp": SPP, "seed": 1, **change}
    if kw.pop("scene", None):
        scene.objects[0].material = Lambertian(Color(0.5, 0.5, 0.25))
    with pytest.raises(ResumeError) as info:
        rtpy.render(scene, checkpoint=state, resume=True, **kw)
    assert str(info.value) == f"{state}: {message}" or message in str(info.value)
    assert "\n" not in str(info.value) and str(info.value).startswith(str(state))
    assert state.read_bytes() == before


def test_the_gamma_and_time_limit_may_change(stopped_state):
    state, scene, camera = stopped_state
    image = rtpy.render(
        scene, camera=camera, spp=SPP, seed=1, gamma="srgb", checkpoint=state, resume=True
    )
    assert image.samples_min == SPP and image.stats["resumed_samples"] > 0


def test_another_rtpy_version_is_refused(stopped_state, monkeypatch):
    state, scene, camera = stopped_state
    monkeypatch.setattr("rtpy.engine.render_state.version", lambda: "99.0")
    with pytest.raises(ResumeError, match=r"saved by rtpy .*, this is rtpy 99\.0$"):
        rtpy.render(scene, camera=camera, spp=SPP, seed=1, checkpoint=state, resume=True)


@pytest.mark.parametrize(
    "corrupt,message",
    [
        (lambda p: p.write_bytes(b"not a zip"), "not a saved render"),
        (lambda p: p.write_bytes(p.read_bytes()[:200]), "not a saved render"),
        ("format", "its format differs"),
        ("counts", "not those of whole passes"),
        ("negative", "not finite and non-negative"),
        ("rows", "its first row 10000 does not fit"),
        ("huge", r"not a saved render \(sums: its header declares 8000000000000 bytes"),
        ("zero-d", "its current are float64 of 0 dimensions, not 3"),
        ("deep", "not a saved render"),
    ],
)
def test_a_file_that_is_not_a_saved_render_is_refused(stopped_state, corrupt, message):
    state, scene, camera = stopped_state
    if callable(corrupt):
        corrupt(state)
    else:
        with np.load(state) as data:
            arrays = dict(data)
        key = json.loads(str(arrays["key"]))
        if corrupt == "format":
            key["format"] = FORMAT + 1
        elif corrupt == "counts":
            arrays["sums"][0, 0, 3] += 1
        elif corrupt == "rows":
            key["first_row"] = 10000
        elif corrupt == "zero-d":
            arrays["current"] = np.array(0.0)
        elif corrupt in ("huge", "deep"):
            return crafted(state, key, corrupt, (scene, camera))
        else:
            arrays["sums"][0, 0, 0] = -1.0
        arrays["key"] = np.array(json.dumps(key))
        with open(state, "wb") as f:
            np.savez(f, **arrays)
    with pytest.raises(ResumeError, match=message):
        rtpy.render(scene, camera=camera, spp=SPP, seed=1, checkpoint=state, resume=True)


def crafted(state, key, how: str, render) -> None:
    """Write a state whose sums header declares 10^12 numbers ("huge") or whose key
    is JSON nested a million deep ("deep"), and check it is refused in one line."""
    import io
    import zipfile

    header = io.BytesIO()
    declared = {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}
    np.lib.format.write_array_header_1_0(header, declared)
    text = "[" * 10**6 + "]" * 10**6 if how == "deep" else json.dumps(key)
    with zipfile.ZipFile(state, "w") as z:
        for name, array in (("key", np.array(text)), ("current", np.zeros((0, 40, 5)))):
            member = io.BytesIO()
            np.save(member, array)
            z.writestr(f"{name}.npy", member.getvalue())
        z.writestr("sums.npy", header.getvalue() if how == "huge" else b"")
    scene, camera = render
    with pytest.raises(ResumeError) as info:
        rtpy.render(scene, camera=camera, spp=SPP, seed=1, checkpoint=state, resume=True)
    message = str(info.value)
    assert message.startswith(f"{state}: not a saved render") and "\n" not in message, message
    if how == "huge":
        assert "declares 8000000000000 bytes" in message


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="no FIFOs here")
def test_a_state_that_is_a_fifo_is_refused_at_once(tmp_path):
    import os

    scene, camera = small_scene()
    state = tmp_path / "s.npz"
    os.mkfifo(state)  # no writer: a reader that opens it waits forever
    with pytest.raises(ResumeError, match="cannot be read: it is a FIFO"):
        rtpy.render(scene, camera=camera, spp=2, checkpoint=state, resume=True)


def test_resume_without_a_saved_render_starts_from_the_first_pass(tmp_path):
    scene, camera = small_scene()
    state = tmp_path / "none.npz"
    image = rtpy.render(scene, camera=camera, spp=2, checkpoint=state, resume=True)
    assert image.samples_min == 2 and image.stats["resumed_samples"] == 0 and not state.exists()
    with pytest.raises(ValueError, match="resume: .*pass checkpoint="):
        rtpy.render(scene, camera=camera, resume=True)
    with pytest.raises(TypeError, match="checkpoint must be a file name"):
        rtpy.render(scene, camera=camera, checkpoint=3)


def test_the_command_line_keeps_the_state_beside_the_output(tmp_path):
    assert state_path(tmp_path / "out.png") == tmp_path / "out.png.resume.npz"


@pytest.mark.parametrize("letter", ["a", "é"])
def test_the_state_of_an_output_with_the_longest_name_fits_and_stays_apart(tmp_path, letter):
    """A name of 255 bytes is legal; its state's name is cut and given a digest of
    the whole name, so it fits, and two outputs that differ only at the end keep
    their states apart."""
    stem = letter * ((251 - 1) // len(letter.encode()))
    first, second = (tmp_path / f"{stem}{end}.png" for end in "xy")
    assert len(first.name.encode()) <= 255
    states = [state_path(first), state_path(second)]
    assert states[0] == state_path(first) and states[0] != states[1]
    for state in states:
        assert state.parent == tmp_path and state.name.endswith(".resume.npz")
        assert len(state.name.encode()) <= 255 and state.name.startswith(stem[:100])
        state.write_bytes(b"")  # the file system takes the name


def scene_digest(tmp_path, scene: Scene) -> str:
    """The digest of `scene` a checkpoint keys its state with."""
    _, camera = small_scene()
    backend = make_backend("numpy", scene, camera, RenderSettings())
    return Checkpoint(tmp_path / "s.npz", backend).scene


def test_the_scene_digest_sees_every_vertex_and_no_tree(tmp_path):
    """A mesh's arrays are hashed whole, its tree not at all: a tree is made from
    them and never changes the image, and it is half a large mesh's bytes."""
    rng = np.random.default_rng(4)
    positions = rng.uniform(-1, 1, (300, 3))
    triangles = np.stack([np.arange(300).reshape(100, 3), np.full((100, 3), -1)], axis=2)
    mesh = Mesh(positions, np.zeros((0, 3)), triangles, Lambertian())
    digest = scene_digest(tmp_path, Scene([mesh]))
    moved = positions.copy()
    moved[217, 1] = np.nextafter(moved[217, 1], 2.0)
    other = Mesh(moved, np.zeros((0, 3)), triangles, Lambertian())
    assert scene_digest(tmp_path, Scene([other])) != digest
    mesh.tree = build_tree(*mesh.triangle_boxes(), leaf_size=1)  # another tree
    assert scene_digest(tmp_path, Scene([mesh])) == digest
