"""How to render: RenderSettings, and the one table of render settings.

SETTINGS lists every render setting once: its name, type, default, limits and
help. Everything that takes render settings checks them against it: the
RenderSettings dataclass (and so rtpy.render(**settings)), the scene loader's
[render] table (and [camera] width), and the command line's --set KEY=VALUE and
flags (--spp, --width, ...). A value that breaks its setting raises a
SettingError (a TypeError for a wrong type, a ValueError for a value out of
range) that names the setting, says what was expected and what was found.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from ._checks import (
    GAMMA,
    NON_NEGATIVE,
    RADIANCE,
    SEED,
    Invalid,
    Range,
    boolean,
    components,
    describe,
    integer,
    is_number,
    number,
    string,
    suggest,
    triple,
)
from .sampler import SAMPLERS
from .vec3 import Color

__all__ = [
    "INTEGRATOR_NAMES",
    "MAX_MAX_DEPTH",
    "MAX_SPP",
    "MAX_WIDTH",
    "RENDER_KEYS",
    "SETTINGS",
    "RenderSettings",
    "Setting",
    "SettingError",
    "unknown_setting",
]

INTEGRATOR_NAMES = ("center", "jittered", "shading", "direct", "whitted", "path")

# Sanity limits: larger values would exhaust memory or never finish.
MAX_WIDTH = 16384
MAX_SPP = 1_000_000
MAX_MAX_DEPTH = 500  # the Whitted integrator recurses once per segment


class SettingError(Exception):
    """A render setting's value that breaks its type or range. key: the setting;
    detail: "expected ..., found ..."; suggestion: the nearest valid name, if any."""

    def __init__(self, key: str, detail: str, suggestion: str | None = None) -> None:
        self.key, self.detail, self.suggestion = key, detail, suggestion
        hint = f" — did you mean '{suggestion}'?" if suggestion else ""
        super().__init__(f"{key}: {detail}{hint}")

    def for_option(self, option: str) -> str:
        """The message with the command-line option in place of the key."""
        return option + str(self)[len(self.key) :]


class SettingTypeError(SettingError, TypeError):
    """A render setting's value of the wrong type."""


class SettingValueError(SettingError, ValueError):
    """A render setting's value out of its range, or not one of its choices."""


@dataclass(frozen=True)
class Setting:
    """One render setting: its type and limits, its default and what it does.

    kind: "int", "float", "bool", "choice" (one of choices), "color" (three
    numbers) or "gamma" (a number in range, or one of choices). table: the scene
    file table that holds it ("render", or "camera" for width). field: it is a
    RenderSettings field (background and sky belong to the scene, width to the
    camera). flag: the command line also has --NAME for it (besides --set
    NAME=VALUE).
    """

    name: str
    kind: str
    default: Any
    help: str
    range: Range = Range()
    limit: str = ""  # why the range ends, e.g. " (larger counts are refused)"
    choices: tuple[str, ...] = ()
    table: str = "render"
    field: bool = True
    flag: bool = False

    def check(self, value: Any) -> Any:
        """The value as rtpy uses it (an int, a float, a Color, ...), or SettingError."""
        try:
            if self.kind == "int":
                return integer(value, self.range, self.limit)
            if self.kind == "float":
                return number(value, self.range)
            if self.kind == "bool":
                return boolean(value)
            if self.kind == "choice":
                return string(value, self.choices)
            if self.kind == "gamma":
                if isinstance(value, str):
                    return string(value, self.choices)
                if not is_number(value):
                    what = f'a number {self.range.text()} or "srgb"'
                    raise Invalid(f"expected {what}, found {describe(value)}", wrong_type=True)
                return number(value, self.range)
            return Color(*triple(components(value), self.range))
        except Invalid as e:
            error = SettingTypeError if e.wrong_type else SettingValueError
            raise error(self.name, e.detail, e.suggestion) from None


SETTINGS: dict[str, Setting] = {
    s.name: s
    for s in (
        Setting(
            "integrator",
            "choice",
            "path",
            '"center" (one ray per pixel centre, flat colours), "jittered" (spp random '
            'rays per pixel, flat colours), "shading" (local shading from every light, '
            'shadow rays only with shadows = true), "direct" (one bounce of direct light), '
            '"whitted" (direct light, recursive mirrors and glass) or "path" (unbiased '
            "path tracing)",
            choices=INTEGRATOR_NAMES,
            flag=True,
        ),
        Setting(
            "spp",
            "int",
            16,
            'camera samples per pixel ("center" uses 1)',
            Range(1, MAX_SPP),
            " (larger counts are refused)",
            flag=True,
        ),
        Setting(
            "max_depth",
            "int",
            8,
            "most ray segments in one path, the camera ray included",
            Range(1, MAX_MAX_DEPTH),
            " (deeper paths are refused)",
            flag=True,
        ),
        Setting(
            "nee",
            "bool",
            True,
            '"path": sample lights directly and combine with BRDF sampling by MIS; '
            "false = BRDF sampling alone",
        ),
        Setting(
            "russian_roulette",
            "int",
            5,
            "segment index after which paths may end at random; 0 = off",
            NON_NEGATIVE,
        ),
        Setting(
            "roulette",
            "choice",
            "throughput",
            '"path": how Russian roulette picks the survival probability q: "throughput" '
            '(q = min(0.95, max component of the path throughput)) or "fixed" (q = '
            "roulette_probability, the lecture's p_RR); a survivor is divided by q",
            choices=("throughput", "fixed"),
        ),
        Setting(
            "roulette_probability",
            "float",
            0.8,
            '"path" with roulette = "fixed": the probability q that a path goes on',
            Range(0, 1, lo_open=True),
        ),
        Setting(
            "shadows",
            "bool",
            False,
            '"shading": false = every light reaches every point it faces (no shadow rays); '
            "true = a shadow ray per light",
        ),
        Setting("seed", "int", 0, "random seed", SEED, flag=True),
        Setting(
            "background",
            "color",
            Color(0.0, 0.0, 0.0),
            "radiance of rays that leave the scene (when sky is false)",
            RADIANCE,
            field=False,
        ),
        Setting(
            "sky",
            "bool",
            False,
            "rays that leave the scene see a sky gradient instead of the background",
            field=False,
        ),
        Setting(
            "gamma",
            "gamma",
            2.0,
            "display transform of 8-bit output: a number > 0, x^(1/gamma) (the course's "
            '2.0), or "srgb", the sRGB curve; a PNG records which (gAMA or sRGB chunk)',
            GAMMA,
            choices=("srgb",),
        ),
        Setting(
            "mis",
            "bool",
            True,
            '"path" and "direct", with nee: true = light and BRDF sampling combined by '
            "MIS; false = next-event estimation alone (lights found only by light sampling; "
            "emission that a BRDF-sampled ray finds after a non-specular bounce is not added)",
        ),
        Setting(
            "sampler",
            "choice",
            "independent",
            'where the uniform numbers of the pixel samples come from: "independent" (each '
            'its own), "stratified" (jittered strata per pixel) or "sobol" (Owen-scrambled '
            "Sobol points); the last two stratify the pixel, lens and first-hit light and "
            "BRDF samples (docs/samplers.md)",
            choices=tuple(SAMPLERS),
            flag=True,
        ),
        Setting(
            "time_limit",
            "float",
            0.0,
            "seconds of rendering at most: whole passes until they are spent (at least "
            "one), spp the most samples per pixel; 0 = no limit",
            Range(0, 1e6, hi_open=True),
        ),
        Setting(
            "width",
            "int",
            400,
            "image width in pixels (the height follows from the aspect ratio)",
            Range(1, MAX_WIDTH),
            " (larger images are refused)",
            table="camera",
            field=False,
            flag=True,
        ),
    )
}

# The keys of a scene file's [render] table, in the order messages list them.
RENDER_KEYS = tuple(name for name, s in SETTINGS.items() if s.table == "render")


def unknown_setting(key: str, names) -> SettingTypeError:
    """The error for a key that is not one of `names`, listing them and suggesting
    the nearest."""
    return SettingTypeError(key, f"not a render setting ({', '.join(names)})", suggest(key, names))


@dataclass(frozen=True)
class RenderSettings:
    """How to render. The fields are the settings of SETTINGS that are not the
    scene's (background, sky) or the camera's (width), with the scene format's
    defaults; SETTINGS[name].help says what each does. Every value is checked
    (a SettingError names the field)."""

    integrator: str = SETTINGS["integrator"].default
    spp: int = SETTINGS["spp"].default
    max_depth: int = SETTINGS["max_depth"].default
    nee: bool = SETTINGS["nee"].default
    russian_roulette: int = SETTINGS["russian_roulette"].default
    roulette: str = SETTINGS["roulette"].default
    roulette_probability: float = SETTINGS["roulette_probability"].default
    shadows: bool = SETTINGS["shadows"].default
    seed: int = SETTINGS["seed"].default
    gamma: float | str = SETTINGS["gamma"].default
    mis: bool = SETTINGS["mis"].default
    sampler: str = SETTINGS["sampler"].default
    time_limit: float = SETTINGS["time_limit"].default

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, SETTINGS[f.name].check(getattr(self, f.name)))

    def with_overrides(self, **overrides) -> RenderSettings:
        """A copy with the given keys changed (None values are ignored)."""
        names = [f.name for f in fields(self)]
        for key in overrides:
            if key not in names:
                raise unknown_setting(key, names)
        return replace(self, **{k: v for k, v in overrides.items() if v is not None})
