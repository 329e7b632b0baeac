"""The options of the commands that render (`render`, `ladder`): their types, the
render settings given by flags and --set, read as TOML, and the one-line UsageError
that names the option of a value refused."""

from __future__ import annotations

import argparse
import tomllib

from ..render_settings import SETTINGS, unknown_setting

MAX_WORKERS = 256  # more processes than that only exhaust the machine


def seconds(text: str, zero: bool = False) -> float:
    """A number of seconds below 1e6: above 0, or from 0 with zero=True."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not ((value >= 0.0 if zero else value > 0.0) and value < 1e6):
        lowest = "from 0" if zero else "above 0"
        raise argparse.ArgumentTypeError(f"expected seconds {lowest}, got {text}")
    return value


def preview_seconds(text: str) -> float:
    """--preview-seconds: 0 (a preview after every unit of work) or more."""
    return seconds(text, zero=True)


def worker_count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 1 <= value <= MAX_WORKERS:
        raise argparse.ArgumentTypeError(f"expected 1 to {MAX_WORKERS} processes, got {value}")
    return value


def flag(name: str) -> str:
    """The option of a render setting that has a flag: max_depth -> --max-depth."""
    return "--" + name.replace("_", "-")


def add_setting_options(r: argparse.ArgumentParser, hidden: tuple[str, ...] = ()) -> None:
    """--NAME for the render settings that have a flag, and --set KEY=VALUE for all
    of them (rtpy.render_settings.SETTINGS); the values are checked after parsing.
    The flags of `hidden` are parsed but left out of the help (a command that refuses
    them says so in one line)."""
    for name, setting in SETTINGS.items():
        if setting.flag:
            metavar = {"int": "N", "float": "X", "choice": "NAME"}.get(setting.kind)
            text = argparse.SUPPRESS if name in hidden else setting.help
            r.add_argument(flag(name), dest=name, metavar=metavar, help=text)
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"override a render setting, VALUE in TOML syntax ({', '.join(SETTINGS)})",
    )


class UsageError(Exception):
    pass


def shown(text: str) -> str:
    """text as a message shows it: as it is when printable, else quoted and escaped
    (a message stays one line)."""
    return text if text.isprintable() else repr(text)


def read_value(text: str, option: str):
    """A command-line value read as one TOML value (2, 2.5, true, [0.1, 0.2, 0.3],
    "path"), or the text itself when it is not TOML (a bare word such as srgb) or more
    than TOML takes (an integer of thousands of digits, arrays nested thousands deep).
    UsageError naming `option` for a line break (TOML reads the next line as more
    keys); a table is one value, refused by the setting's check as in a scene file."""
    if "\n" in text or "\r" in text:
        raise UsageError(f"{option}: expected one value on one line, got {text!r}")
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        return text.strip()


def parse_set(items: list[str]) -> dict:
    """--set KEY=VALUE pairs -> {key: value}, values read as TOML."""
    result = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            raise UsageError(f"--set {item!r}: expected KEY=VALUE")
        if key not in SETTINGS:
            error = unknown_setting(key, list(SETTINGS))
            raise UsageError(error.for_option(f"--set {shown(key)}"))
        result[key] = read_value(text, f"--set {key}")
    return result


def given_settings(args: argparse.Namespace) -> dict[str, tuple[str, object]]:
    """The render settings the command line gives: key -> (the option that gave it,
    its value read as TOML); UsageError for a flag (--spp) and --set of one key."""
    given = {key: (f"--set {key}", value) for key, value in parse_set(args.set).items()}
    flags = {name: flag(name) for name, setting in SETTINGS.items() if setting.flag}
    flags["time_limit"] = "--time"
    for key, option in flags.items():
        text = getattr(args, key)
        if text is None:
            continue
        if key in given:
            raise UsageError(f"{option} and --set {key} set one value: give one of them")
        given[key] = (option, read_value(text, option))
    return given


def check_backend(name: str) -> None:
    """UsageError when the backend is withheld (the numpy backend in an assignment
    repository, whose stub says so in WITHHELD)."""
    if name != "numpy":
        return
    import rtpy.numpy_backend as backend

    withheld = getattr(backend, "WITHHELD", None)
    if withheld:
        raise UsageError(f"--backend numpy: {withheld}")
