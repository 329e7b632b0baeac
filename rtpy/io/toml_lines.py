"""Where tables and keys are in the text of a TOML file, for error messages.

tomllib reports no positions for values, so TomlLines finds them by scanning:
a table's header line, then the first `key =` line after it (inline tables and
dotted keys fall back to the line that names the table). Where names a table
of a scene file: its label in messages and its path.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["TomlLines", "Where", "dotted", "quote_key"]

_BARE = r"[A-Za-z0-9_-]+"
_BASIC = r'"(?:[^"\\\n]|\\.)*"'
_LITERAL = r"'[^'\n]*'"
_KEY = rf"(?:{_BARE}|{_BASIC}|{_LITERAL})"
_DOTTED = rf"{_KEY}(?:[ \t]*\.[ \t]*{_KEY})*"
_HEADER_RE = re.compile(rf"^[ \t]*(\[\[|\[)[ \t]*({_DOTTED})[ \t]*(\]\]|\])[ \t]*(?:#.*)?$")
_KEYLINE_RE = re.compile(rf"^[ \t]*({_DOTTED})[ \t]*=")
_KEYPART_RE = re.compile(_KEY)


def _split_dotted(text: str) -> tuple[str, ...]:
    parts = []
    for m in _KEYPART_RE.finditer(text):
        k = m.group(0)
        if k.startswith('"'):
            try:
                k = json.loads(k)
            except ValueError:
                k = k[1:-1]
        elif k.startswith("'"):
            k = k[1:-1]
        parts.append(k)
    return tuple(parts)


class TomlLines:
    """Where tables and keys are in the text. tomllib reports no positions for
    values, so the loader finds them by scanning: the table's header line, then
    the first `key =` line after it (inline tables and dotted keys fall back to
    the line that names the table)."""

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()
        self.headers: list[tuple[int, tuple[str, ...], bool]] = []  # (0-based line, path, [[ ]])
        in_string: str | None = None
        for i, line in enumerate(self.lines):
            if in_string is not None:
                if line.count(in_string) % 2 == 1:
                    in_string = None
                continue
            m = _HEADER_RE.match(line)
            if m:
                self.headers.append((i, _split_dotted(m.group(2)), m.group(1) == "[["))
                continue
            for quote in ('"""', "'''"):
                if line.count(quote) % 2 == 1:
                    in_string = quote
                    break

    def _section_end(self, start: int) -> int:
        for i, _, _ in self.headers:
            if i > start:
                return i
        return len(self.lines)

    def _key_line(self, start: int, end: int, key: str) -> int | None:
        for i in range(start, end):
            m = _KEYLINE_RE.match(self.lines[i])
            if m and _split_dotted(m.group(1))[:1] == (key,):
                return i + 1
        return None

    def _header(self, path: tuple[str, ...], index: int | None) -> int | None:
        if index is None:
            for i, p, is_array in self.headers:
                if p == path and not is_array:
                    return i
            return None
        arrays = [i for i, p, is_array in self.headers if p == path and is_array]
        return arrays[index] if 0 <= index < len(arrays) else None

    def _in_section(self, path: tuple[str, ...], key: str) -> int | None:
        """The `key =` line in the section of the (non-array) table `path`."""
        if not path:
            first = self.headers[0][0] if self.headers else len(self.lines)
            return self._key_line(0, first, key)
        start = self._header(path, None)
        if start is None:
            return None
        return self._key_line(start + 1, self._section_end(start), key)

    def locate(self, path: tuple[str, ...], index: int | None, key: str | None) -> int | None:
        """1-based line of `key` in table `path` (the index-th [[path]] when index is
        not None), else of the table itself, else None."""
        if not path:
            if key is None:
                return None
            line = self._in_section((), key)
            if line is not None:
                return line
            for i, p, _ in self.headers:
                if p[:1] == (key,):
                    return i + 1
            return None
        start = self._header(path, index)
        if start is not None:
            if key is not None:
                line = self._key_line(start + 1, self._section_end(start), key)
                if line is not None:
                    return line
                for i, p, _ in self.headers:  # a sub-table [path.key]
                    if i > start and p == (*path, key):
                        return i + 1
            return start + 1
        # Defined inline (`name = { ... }`) or by dotted keys in a parent table.
        for k in range(len(path) - 1, -1, -1):
            line = self._in_section(path[:k], path[k])
            if line is not None:
                return line
        if index is None:  # only sub-tables written, e.g. [materials.x] without [materials]
            for i, p, _ in self.headers:
                if p[: len(path)] == path:
                    return i + 1
        return None

    def context(self, line: int) -> tuple[str | None, str | None]:
        """(table label, key) of the given 1-based line, for syntax errors."""
        label = None
        counts: dict[tuple[str, ...], int] = {}
        for i, p, is_array in self.headers:
            if is_array:
                counts[p] = counts.get(p, 0) + 1
            if i + 1 > line:
                break
            label = f"[[{dotted(p)}]] #{counts[p]}" if is_array else f"[{dotted(p)}]"
            if i + 1 == line:
                return label, None
        key = None
        if 1 <= line <= len(self.lines):
            m = _KEYLINE_RE.match(self.lines[line - 1])
            if m:
                key = ".".join(quote_key(k) for k in _split_dotted(m.group(1)))
        return label, key


def quote_key(k: str) -> str:
    return k if re.fullmatch(_BARE, k) else json.dumps(k, ensure_ascii=False)


def dotted(path: Iterable[str]) -> str:
    return ".".join(quote_key(k) for k in path)


@dataclass(frozen=True)
class Where:
    """A table of the file: its label in messages and where to find it."""

    label: str  # "[camera]", "[materials.glass]", "[[objects]] #3"
    path: tuple[str, ...]
    index: int | None = None  # 0-based, for arrays of tables

    @staticmethod
    def table(*path: str) -> Where:
        return Where(f"[{dotted(path)}]", tuple(path))

    @staticmethod
    def array(name: str, index: int) -> Where:
        return Where(f"[[{quote_key(name)}]] #{index + 1}", (name,), index)
