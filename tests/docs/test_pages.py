"""The documentation pages: the README is short and links every page of docs/, every
link stays inside the repository and resolves, and no page or module reads as a
development diary (dates, rounds of work, commit references, measurement history
belong in commit messages)."""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

from .markdown import ROOT, anchors, links

README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = (
    "scene-format.md",
    "course-map.md",
    "students.md",
    "instructors.md",
    "numpy-backend.md",
    "bench.md",
    "performance.md",
)
README_LIMIT = 12 * 1024  # bytes

# What a diary looks like, each with what to write instead.
DIARY = (
    (re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b"), "a date"),
    (re.compile(r"\b(?:this|last|previous|earlier|latest) rounds?\b", re.I), "a round of work"),
    (re.compile(r"\btried and (?:dropped|rejected|abandoned)\b", re.I), "what was tried"),
    (re.compile(r"\b(?:until|since|before|after) commit\b", re.I), "a commit reference"),
    (re.compile(r"\bas of (?:\d|today|now|this|commit|version)", re.I), "'as of' a time"),
    (
        re.compile(r"\b(?:was|were)\s+(?:about\s+|~\s*)?\d[\d.,]*\s*(?:%|x\b|×)", re.I),
        "a measurement of an earlier version",
    ),
    (
        re.compile(r"(?:faster|slower)\b[^\n]{0,40}\b(?:numpy|python)\s+\d+\.\d+", re.I),
        "a timing tied to a library version",
    ),
    (
        re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b"),
        "a commit hash",
    ),
)


def pages() -> list[Path]:
    return [README, *sorted(DOCS.glob("*.md"))]


def link_problems(page: Path, text: str) -> list[str]:
    """Links of `page` that leave the repository or point at nothing, one line each."""
    problems = []
    name = page.relative_to(ROOT).as_posix()
    for target in links(text):
        if re.match(r"[a-z][a-z0-9+.-]*:", target, re.I):
            problems.append(f"{name}: {target} leaves the repository")
            continue
        path_part, _, anchor = target.partition("#")
        dest = (page.parent / unquote(path_part)).resolve() if path_part else page
        if not dest.is_relative_to(ROOT):
            problems.append(f"{name}: {target} points outside the repository")
        elif not dest.exists():
            problems.append(f"{name}: {target}: no such file")
        elif anchor and dest.suffix == ".md":
            if anchor not in anchors(dest.read_text(encoding="utf-8")):
                problems.append(f"{name}: {target}: no heading with the anchor #{anchor}")
    return problems


def diary_problems(name: str, text: str) -> list[str]:
    problems = []
    for number, line in enumerate(text.splitlines(), 1):
        for pattern, what in DIARY:
            m = pattern.search(line)
            if m:
                problems.append(f"{name}:{number}: {what} ({m.group(0)!r}): {line.strip()}")
    return problems


def test_docs_holds_every_page_and_the_readme_links_each():
    readme_links = set(links(README.read_text(encoding="utf-8")))
    missing = [p for p in PAGES if not (DOCS / p).is_file()]
    unlinked = [p for p in PAGES if not any(t.split("#")[0] == f"docs/{p}" for t in readme_links)]
    assert not missing, f"missing in docs/: {', '.join(missing)}"
    assert not unlinked, f"README.md does not link docs/{', docs/'.join(unlinked)}"


def test_readme_is_at_most_12_kb():
    size = len(README.read_bytes())
    assert size <= README_LIMIT, f"README.md is {size:,} bytes; at most {README_LIMIT:,}"


def test_every_link_stays_inside_the_repository_and_resolves():
    problems = [p for page in pages() for p in link_problems(page, page.read_text("utf-8"))]
    assert not problems, "\n".join(problems)


def test_no_page_or_module_reads_as_a_diary():
    files = [*pages(), *sorted((ROOT / "rtpy").rglob("*.py"))]
    problems = [
        p
        for path in files
        for p in diary_problems(path.relative_to(ROOT).as_posix(), path.read_text("utf-8"))
    ]
    assert not problems, "history belongs in commit messages:\n" + "\n".join(problems)


def test_the_checks_catch_planted_mistakes():
    page = DOCS / "students.md"
    bad_links = (
        "[contract](../../shared/scene-format.md) [web](https://example.org) "
        "[gone](missing.md) [anchor](scene-format.md#no-such-heading) "
        "![img](scenes/no_such.png)"
    )
    found = link_problems(page, bad_links)
    assert len(found) == 5, found
    assert "outside the repository" in found[0] and "leaves the repository" in found[1]
    assert "no heading" in found[3]
    diary = (
        "On 2026-11-23 the sphere test was 1.3x faster.\n"
        "Changes of this round; tried and dropped: a BVH.\n"
        "Kept until commit 44a8adf, as of 2026.\n"
        "2.6x faster for 32,768 numbers, numpy 2.4\n"
    )
    found = diary_problems("x.md", diary)
    kinds = {p.split(": ")[1].split(" (")[0] for p in found}
    assert kinds == {what for _, what in DIARY}, found
    clean = "Renders 16 spp in 2.3 s; a hit at t = 1e-9; colour #ffffff; seed 1234567."
    assert diary_problems("x.md", clean) == []
