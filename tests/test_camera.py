"""Tests for rtpy.camera: image size, field of view, pixel orientation, jitter and defocus."""

from __future__ import annotations

import math

import pytest

from rtpy.camera import Camera, parse_aspect_ratio
from rtpy.sampling import make_generator, use_generator

from .vectors import V, angle, cross3, dot3, norm3, unit3

LOOK_FROM = (1.0, 2.0, 3.0)
LOOK_AT = (-2.0, 1.0, -4.0)
VUP = (0.0, 1.0, 0.0)


def frame(look_from=LOOK_FROM, look_at=LOOK_AT, vup=VUP):
    """(forward, right, up) computed independently of the camera."""
    fwd = unit3(tuple(look_at[i] - look_from[i] for i in range(3)))
    right = unit3(cross3(fwd, vup))
    up = cross3(right, fwd)
    return fwd, right, up


def make_camera(**kw) -> Camera:
    args = dict(
        look_from=V(*LOOK_FROM),
        look_at=V(*LOOK_AT),
        vup=V(*VUP),
        vfov=40.0,
        aspect_ratio=101 / 51,
        width=101,
    )
    args.update(kw)
    return Camera(**args)


def expected_direction(cam: Camera, px: float, py: float, fwd, right, up):
    """Unit direction through fractional pixel (px, py) of a pinhole camera."""
    tan_v = math.tan(math.radians(cam.vfov) / 2.0)
    tan_h = tan_v * cam.width / cam.height
    x = ((px + 0.5) / cam.width) * 2.0 - 1.0
    y = 1.0 - ((py + 0.5) / cam.height) * 2.0
    d = tuple(fwd[i] + right[i] * x * tan_h + up[i] * y * tan_v for i in range(3))
    return unit3(d)


def test_basis_matches_independent_frame():
    cam = make_camera()
    fwd, right, up = frame()
    assert cam.u.tolist() == pytest.approx(list(right), abs=1e-14)
    assert cam.v.tolist() == pytest.approx(list(up), abs=1e-14)
    assert cam.w.tolist() == pytest.approx([-x for x in fwd], abs=1e-14)


def test_middle_pixel_center_ray_points_at_look_at():
    cam = make_camera()
    assert (cam.width, cam.height) == (101, 51)
    r = cam.get_center_ray(50, 25)
    assert r.origin.tolist() == list(LOOK_FROM)
    fwd, _, _ = frame()
    assert r.direction.tolist() == pytest.approx(list(fwd), abs=1e-14)
    assert math.isclose(r.direction.length(), 1.0, abs_tol=1e-14)


@pytest.mark.parametrize(
    "width, aspect, vfov",
    [(101, 101 / 51, 40.0), (401, 16 / 9, 90.0), (7, 1.0, 120.0), (64, 3.0, 20.0)],
)
def test_horizontal_and_vertical_extent(width, aspect, vfov):
    cam = make_camera(width=width, aspect_ratio=aspect, vfov=vfov)
    w, h = cam.width, cam.height
    fwd, right, up = frame()
    cy, cx = (h - 1) / 2.0, (w - 1) / 2.0
    left = cam._ray_through(-0.5, cy).direction.tolist()
    right_edge = cam._ray_through(w - 0.5, cy).direction.tolist()
    top = cam._ray_through(cx, -0.5).direction.tolist()
    bottom = cam._ray_through(cx, h - 0.5).direction.tolist()
    half_v = math.radians(vfov) / 2.0
    # The viewport width follows the rounded pixel counts: tan(half h) = tan(vfov/2) w/h.
    half_h = math.atan(math.tan(half_v) * w / h)
    assert angle(left, fwd) == pytest.approx(half_h, abs=1e-12)
    assert angle(right_edge, fwd) == pytest.approx(half_h, abs=1e-12)
    assert angle(left, right_edge) == pytest.approx(2 * half_h, abs=1e-12)
    assert angle(top, fwd) == pytest.approx(half_v, abs=1e-12)
    assert angle(bottom, fwd) == pytest.approx(half_v, abs=1e-12)
    assert angle(top, bottom) == pytest.approx(2 * half_v, abs=1e-12)
    # ... and on the right sides.
    assert dot3(left, right) < 0 < dot3(right_edge, right)
    assert dot3(bottom, up) < 0 < dot3(top, up)


def test_pixel_00_is_top_left():
    cam = make_camera()
    d = cam.get_center_ray(0, 0).direction
    assert dot3(d.tolist(), cam.u.tolist()) < 0.0  # left
    assert dot3(d.tolist(), cam.v.tolist()) > 0.0  # up
    d = cam.get_center_ray(cam.width - 1, cam.height - 1).direction
    assert dot3(d.tolist(), cam.u.tolist()) > 0.0
    assert dot3(d.tolist(), cam.v.tolist()) < 0.0
    # Default camera looks down -z with y up: top-left is -x, +y.
    d = Camera(width=20).get_center_ray(0, 0).direction
    assert d.e0 < 0.0 and d.e1 > 0.0 and d.e2 < 0.0


@pytest.mark.parametrize("i, j", [(0, 0), (100, 0), (0, 50), (100, 50), (13, 37), (77, 4)])
def test_center_rays_match_pinhole_projection(i, j):
    cam = make_camera()
    fwd, right, up = frame()
    r = cam.get_center_ray(i, j)
    assert r.direction.tolist() == pytest.approx(
        list(expected_direction(cam, i, j, fwd, right, up)), abs=1e-13
    )


@pytest.mark.parametrize(
    "width, aspect, height",
    [
        (400, 16 / 9, 225),
        (401, 16 / 9, 225),
        (1, 16 / 9, 1),
        (10, 100.0, 1),
        (101, 101 / 51, 51),
        (300, "4:3", 225),
        (1920, "16:9", 1080),
        (1000, "16/9", 562),
        (100, 0.5, 200),
    ],
)
def test_height_from_width_and_aspect(width, aspect, height):
    cam = Camera(width=width, aspect_ratio=aspect)
    a = aspect if isinstance(aspect, float) else None
    if a is not None:
        assert height == max(1, int(width / a))
    assert cam.height == height
    assert cam.width == width


def test_string_aspect_ratio():
    assert parse_aspect_ratio("16:9") == pytest.approx(16 / 9)
    assert parse_aspect_ratio("16/9") == pytest.approx(16 / 9)
    assert parse_aspect_ratio("1.5") == 1.5
    assert parse_aspect_ratio(2) == 2.0
    assert Camera(aspect_ratio="16:9").aspect_ratio == pytest.approx(16 / 9)


def pixel_coords(cam: Camera, origin, direction, fwd, right, up):
    """Fractional pixel coordinates where a ray meets the focus plane."""
    fd = cam.focus_distance
    t = fd / dot3(direction, fwd)
    # Offset of the ray's origin from the eye along fwd is zero (lens plane).
    p = tuple(origin[i] + t * direction[i] - LOOK_FROM[i] for i in range(3))
    tan_v = math.tan(math.radians(cam.vfov) / 2.0)
    vh = 2.0 * fd * tan_v
    vw = vh * cam.width / cam.height
    px = (dot3(p, right) / vw + 0.5) * cam.width - 0.5
    py = (0.5 - dot3(p, up) / vh) * cam.height - 0.5
    return px, py


@pytest.mark.parametrize("i, j", [(50, 25), (0, 0), (100, 50), (3, 40)])
def test_get_ray_stays_in_the_pixel(i, j):
    cam = make_camera()
    fwd, right, up = frame()
    center = cam.get_center_ray(i, j).direction.tolist()
    tan_v = math.tan(math.radians(cam.vfov) / 2.0)
    pixel_size = 2.0 * tan_v / cam.height  # at unit distance along fwd
    diag_angle = math.atan(math.sqrt(2.0) * pixel_size)
    pxs, pys = [], []
    with use_generator(make_generator(1234)):
        for _ in range(300):
            r = cam.get_ray(i, j)
            assert r.origin.tolist() == list(LOOK_FROM)
            d = r.direction.tolist()
            assert math.isclose(norm3(d), 1.0, abs_tol=1e-14)
            assert angle(center, d) < diag_angle
            px, py = pixel_coords(cam, r.origin.tolist(), d, fwd, right, up)
            assert i - 0.5 - 1e-9 <= px <= i + 0.5 + 1e-9
            assert j - 0.5 - 1e-9 <= py <= j + 0.5 + 1e-9
            pxs.append(px)
            pys.append(py)
    # Spread over the whole pixel (a box filter), centered on it.
    assert max(pxs) - min(pxs) > 0.9 and max(pys) - min(pys) > 0.9
    assert abs(sum(pxs) / len(pxs) - i) < 4 * math.sqrt(1 / 12 / len(pxs))
    assert abs(sum(pys) / len(pys) - j) < 4 * math.sqrt(1 / 12 / len(pys))


def test_get_ray_is_deterministic_for_a_fixed_generator():
    cam = make_camera()
    with use_generator(make_generator(5)):
        a = [cam.get_ray(7, 9).direction.tolist() for _ in range(5)]
    with use_generator(make_generator(5)):
        b = [cam.get_ray(7, 9).direction.tolist() for _ in range(5)]
    assert a == b


@pytest.mark.parametrize("i, j", [(10, 5), (0, 0), (19, 9)])
def test_defocus_rays_cross_at_the_focus_plane(i, j):
    fd, angle_deg = 4.0, 10.0
    cam = Camera(
        V(*LOOK_FROM),
        V(*LOOK_AT),
        V(*VUP),
        vfov=50.0,
        aspect_ratio=2.0,
        width=20,
        defocus_angle=angle_deg,
        focus_distance=fd,
    )
    fwd, right, up = frame()
    tan_v = math.tan(math.radians(50.0) / 2.0)
    tan_h = tan_v * cam.width / cam.height
    x = ((i + 0.5) / cam.width) * 2.0 - 1.0
    y = 1.0 - ((j + 0.5) / cam.height) * 2.0
    focus_point = [
        LOOK_FROM[k] + fd * (fwd[k] + right[k] * x * tan_h + up[k] * y * tan_v) for k in range(3)
    ]
    lens_radius = fd * math.tan(math.radians(angle_deg / 2.0))
    origins = []
    with use_generator(make_generator(77)):
        for _ in range(100):
            r = cam.get_center_ray(i, j)
            o, d = r.origin.tolist(), r.direction.tolist()
            assert math.isclose(norm3(d), 1.0, abs_tol=1e-14)
            off = [o[k] - LOOK_FROM[k] for k in range(3)]
            assert abs(dot3(off, fwd)) < 1e-12  # on the lens plane
            assert norm3(off) <= lens_radius * (1 + 1e-12)
            t_focus = fd / dot3(d, fwd)
            p = r.at(t_focus).tolist()
            assert p == pytest.approx(focus_point, abs=1e-12)
            origins.append(off)
    # The origins really vary over the lens.
    spread = max(norm3([a[k] - b[k] for k in range(3)]) for a in origins for b in origins[:5])
    assert spread > 0.5 * lens_radius


def test_pinhole_rays_start_at_look_from():
    cam = make_camera(defocus_angle=0.0)
    with use_generator(make_generator(1)):
        for _ in range(10):
            assert cam.get_ray(5, 5).origin.tolist() == list(LOOK_FROM)


@pytest.mark.parametrize(
    "look_from, look_at, vup",
    [
        ((0, 0, 0), (0, 5, 0), (0, 1, 0)),
        ((0, 0, 0), (0, -5, 0), (0, 1, 0)),
        ((1, 1, 1), (2, 2, 2), (3, 3, 3)),
        ((1, 1, 1), (2, 2, 2), (-1e-3, -1e-3, -1e-3)),
    ],
)
def test_vup_parallel_to_view_raises(look_from, look_at, vup):
    with pytest.raises(ValueError):
        Camera(V(*look_from), V(*look_at), V(*vup))


def test_vup_almost_parallel_is_accepted():
    cam = Camera(V(0, 0, 0), V(0, 5, 0), V(0, 1, 1e-3))
    fwd, right, up = frame((0, 0, 0), (0, 5, 0), (0, 1, 1e-3))
    assert cam.u.tolist() == pytest.approx(list(right), abs=1e-12)
    assert cam.v.tolist() == pytest.approx(list(up), abs=1e-12)


def test_look_from_equal_look_at_raises_value_error():
    with pytest.raises(ValueError):
        Camera(V(1, 2, 3), V(1, 2, 3))


def test_zero_vup_raises_value_error():
    with pytest.raises(ValueError):
        Camera(V(0, 0, 0), V(0, 0, -1), V(0, 0, 0))


@pytest.mark.parametrize(
    "kw",
    [
        {"vfov": 0.0},
        {"vfov": 180.0},
        {"width": 0},
        {"aspect_ratio": 0.0},
        {"focus_distance": 0.0},
        {"defocus_angle": -1.0},
        {"aspect_ratio": "16:0"},
    ],
)
def test_invalid_parameters_raise(kw):
    with pytest.raises(ValueError):
        Camera(**kw)


def test_with_width_keeps_everything_but_size():
    cam = make_camera(defocus_angle=2.5, focus_distance=7.0, aspect_ratio="16:9", width=320)
    other = cam.with_width(64)
    assert other is not cam
    assert (other.width, other.height) == (64, max(1, int(64 / (16 / 9))))
    assert (cam.width, cam.height) == (320, 180)
    for name in ("look_from", "look_at", "vup"):
        assert getattr(other, name).tolist() == getattr(cam, name).tolist()
    assert other.vfov == cam.vfov
    assert other.aspect_ratio == cam.aspect_ratio
    assert other.defocus_angle == cam.defocus_angle
    assert other.focus_distance == cam.focus_distance
    for name in ("u", "v", "w"):
        assert getattr(other, name).tolist() == pytest.approx(getattr(cam, name).tolist())
    # Same view: the middle of the image looks the same way in both.
    a = cam._ray_through((cam.width - 1) / 2, (cam.height - 1) / 2)
    b = other._ray_through((other.width - 1) / 2, (other.height - 1) / 2)
    # Defocus moves origins; compare where the rays meet the focus plane instead.
    fwd, _, _ = frame()
    pa = a.at(7.0 / dot3(a.direction.tolist(), fwd)).tolist()
    pb = b.at(7.0 / dot3(b.direction.tolist(), fwd)).tolist()
    assert pa == pytest.approx(pb, abs=1e-12)
