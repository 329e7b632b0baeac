"""Reading the repository's Markdown pages: sections, tables, code spans, links."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

FENCE = re.compile(r"^```.*?^```[^\n]*$", re.MULTILINE | re.DOTALL)
CODE_SPAN = re.compile(r"`([^`\n]+)`")
# [text](target) and ![alt](target), with an optional "title"
LINK = re.compile(r"!?\[[^\]\n]*\]\(\s*([^)\s]+)(?:\s+\"[^\"]*\")?\s*\)")


def without_code(text: str) -> str:
    """The text with fenced code blocks, indented code lines and code spans removed
    (links inside code are not links)."""
    text = FENCE.sub("", text)
    text = "\n".join(line for line in text.splitlines() if not line.startswith("    "))
    return CODE_SPAN.sub("", text)


def sections(text: str, level: int = 2) -> list[tuple[str, str]]:
    """(heading, body) of every heading of this level, outside fenced code; the body
    runs to the next heading of this level or a higher one."""
    marks = re.compile(rf"^(#{{1,{level}}}) (.*)$", re.MULTILINE)
    fenced = [m.span() for m in FENCE.finditer(text)]
    found = [m for m in marks.finditer(text) if not any(a <= m.start() < b for a, b in fenced)]
    out = []
    for k, m in enumerate(found):
        end = found[k + 1].start() if k + 1 < len(found) else len(text)
        if len(m.group(1)) == level:
            out.append((m.group(2).strip(), text[m.end() : end]))
    return out


def split_row(line: str) -> list[str]:
    """The cells of a table row `| a | b |`, stripped."""
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def tables(body: str) -> list[tuple[list[str], list[list[str]]]]:
    """Every table in `body` as (header cells, rows of cells)."""
    out: list[tuple[list[str], list[list[str]]]] = []
    lines = FENCE.sub("", body).splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("|") and k + 1 < len(lines) and set(lines[k + 1]) <= set("|-: "):
            header = split_row(lines[k])
            rows = []
            k += 2
            while k < len(lines) and lines[k].startswith("|"):
                rows.append(split_row(lines[k]))
                k += 1
            out.append((header, rows))
        else:
            k += 1
    return out


def code_spans(cell: str) -> list[str]:
    return CODE_SPAN.findall(cell)


def links(text: str) -> list[str]:
    """The targets of the links and images in Markdown text."""
    return LINK.findall(without_code(text))


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces to
    hyphens."""
    text = heading.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text: str) -> set[str]:
    """The anchors of every heading in the page (a repeated heading gets -1, -2, ...)."""
    seen: dict[str, int] = {}
    out = set()
    fenced = [m.span() for m in FENCE.finditer(text)]
    for m in re.finditer(r"^#{1,6} (.*)$", text, re.MULTILINE):
        if any(a <= m.start() < b for a, b in fenced):
            continue
        base = slug(m.group(1))
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out
