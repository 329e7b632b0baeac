"""Reading the tables and values of a scene file, and the one error it raises.

TableReader checks what a table holds (its keys, the type of each value, the
`type` of a texture, material, object or light) and turns every problem into a
SceneError that names the file, the table and the key, says what was expected
and what was found, gives the line and suggests the nearest valid name.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from dataclasses import KW_ONLY, dataclass
from pathlib import Path
from typing import Any

from .. import _checks as checks
from .._checks import ANY, Invalid, Range, describe, suggest
from ..render_settings import SETTINGS, SettingError
from ..vec3 import Color, Vec3
from .toml_lines import TomlLines, Where, quote_key

__all__ = ["SceneError", "SceneWarning", "TableReader"]


# --------------------------------------------------------------------------- errors


@dataclass(eq=False)
class SceneError(Exception):
    """A scene file (or scene name) that cannot be loaded. str(error) is the whole
    message; the parts are also kept as attributes (file, table, key, line,
    suggestion, detail)."""

    detail: str
    _: KW_ONLY
    file: str | None = None
    table: str | None = None
    key: str | None = None
    line: int | None = None
    suggestion: str | None = None

    def __post_init__(self) -> None:
        super().__init__(self._format())

    def _format(self) -> str:
        head = ""
        if self.table is not None:
            head = self.table + (f" {self.key}" if self.key is not None else "")
        elif self.key is not None:
            head = self.key
        parts = [p for p in (self.file, head) if p]
        text = ": ".join([*parts, self.detail])
        if self.line is not None:
            text += f" (line {self.line})"
        if self.suggestion is not None:
            text += f" — did you mean '{self.suggestion}'?"
        return text.translate(_ESCAPE_LINE_BREAKS)

    def as_warning(self) -> SceneWarning:
        """The same message as a warning: something the loader left out but could load."""
        return SceneWarning(str(self))


class SceneWarning(UserWarning):
    """A scene file that loads but not entirely as written (a mesh's degenerate faces
    left out); str(warning) is one line naming the file, the table and the key."""


# A message is one line: names and strings quoted from the file keep no character
# that str.splitlines (or a terminal) takes for a line break.
_ESCAPE_LINE_BREAKS = str.maketrans(
    {c: repr(c)[1:-1] for c in "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"}
)


# --------------------------------------------------------------------------- reading tables


class TableReader:
    """Reads the tables of one parsed TOML file and the typed values in them; every
    problem is a SceneError that names the file, the table, the key and the line."""

    def __init__(self, text: str, path: Path) -> None:
        self.path = path
        self.file = str(path)
        self.lines = TomlLines(text)

    # --- errors ---------------------------------------------------------------
    def fail(
        self, where: Where | None, key: str | None, detail: str, suggestion: str | None = None
    ) -> SceneError:
        if where is None:
            line = self.lines.locate((), None, key)
            table = None
        else:
            line = self.lines.locate(where.path, where.index, key)
            table = where.label
        return SceneError(
            detail, file=self.file, table=table, key=key, line=line, suggestion=suggestion
        )

    def expected(self, where: Where, key: str, what: str, found: Any) -> SceneError:
        return self.fail(where, key, f"expected {what}, found {describe(found)}")

    def check_keys(self, where: Where, table: dict, valid: Iterable[str], what: str = "") -> None:
        valid = list(valid)
        for key in table:
            if key not in valid:
                listed = ", ".join(valid)
                for_what = f" for {what}" if what else ""
                raise self.fail(
                    where,
                    key,
                    f"unknown key{for_what}; valid keys: {listed}",
                    suggest(key, valid),
                )

    def require(self, where: Where, table: dict, key: str, what: str) -> Any:
        if key not in table:
            raise self.fail(where, key, f"missing required key (expected {what})")
        return table[key]

    # --- values -------------------------------------------------------------------
    def checked(self, where: Where, key: str, check: Callable, v: Any, *args) -> Any:
        """check(v, *args) (one of rtpy._checks' checks), its Invalid as a SceneError."""
        try:
            return check(v, *args)
        except Invalid as e:
            raise self.fail(where, key, e.detail, e.suggestion) from None

    def setting(self, where: Where, key: str, v: Any) -> Any:
        """A render setting's value (rtpy.render_settings.SETTINGS)."""
        try:
            return SETTINGS[key].check(v)
        except SettingError as e:
            raise self.fail(where, key, e.detail, e.suggestion) from None

    def number(self, where: Where, key: str, v: Any, rng: Range = ANY) -> float:
        return self.checked(where, key, checks.number, v, rng)

    def integer(self, where: Where, key: str, v: Any, rng: Range = ANY) -> int:
        return self.checked(where, key, checks.integer, v, rng)

    def boolean(self, where: Where, key: str, v: Any) -> bool:
        return self.checked(where, key, checks.boolean, v)

    def string(self, where: Where, key: str, v: Any, choices: tuple[str, ...] = ()) -> str:
        return self.checked(where, key, checks.string, v, choices)

    def vec3(self, where: Where, key: str, v: Any, check: Callable = checks.point) -> Vec3:
        """A vector checked by check (a point, an edge, scales, ...)."""
        return Vec3(*self.checked(where, key, check, v))

    def color(self, where: Where, key: str, v: Any, rng: Range = ANY) -> Color:
        return Color(*self.checked(where, key, checks.triple, v, rng))

    # --- tables -------------------------------------------------------------------
    def table(self, data: dict, name: str) -> dict:
        t = data.get(name, {})
        if not isinstance(t, dict):
            raise self.fail(Where.table(name), None, f"expected a table, found {describe(t)}")
        return t

    def named_tables(self, data: dict, name: str) -> dict[str, dict]:
        t = self.table(data, name)
        for sub, value in t.items():
            if not isinstance(value, dict):
                where = Where.table(name)
                raise self.fail(
                    where,
                    sub,
                    f"expected a table [{name}.{quote_key(sub)}] with a `type` key, "
                    f"found {describe(value)}",
                )
        return t

    def array_of_tables(self, data: dict, name: str) -> list[dict]:
        v = data.get(name, [])
        if not isinstance(v, list):
            raise self.fail(
                Where(f"[[{name}]]", (name,)),
                None,
                f"expected an array of tables, found {describe(v)} "
                f"(write [[{name}]] before each one, not [{name}])",
            )
        for i, item in enumerate(v):
            if not isinstance(item, dict):
                raise self.fail(
                    Where.array(name, i), None, f"expected a table, found {describe(item)}"
                )
        return v

    def type_of(self, where: Where, table: dict, kinds: Iterable[str], what: str) -> str:
        kinds = tuple(kinds)
        listed = ", ".join(f'"{k}"' for k in kinds)
        if "type" not in table:
            raise self.fail(
                where, "type", f"missing required key (the {what} type: one of {listed})"
            )
        v = table["type"]
        if not isinstance(v, str):
            raise self.expected(where, "type", f"a {what} type: one of {listed}", v)
        if v not in kinds:
            raise self.fail(
                where,
                "type",
                f"unknown {what} type {json.dumps(v, ensure_ascii=False)}; "
                f"expected one of {listed}",
                suggest(v, kinds),
            )
        return v
