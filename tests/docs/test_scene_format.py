"""docs/scene-format.md is the whole contract of scene files: every key it documents is
accepted by the loader, and every key the loader accepts is documented.

The loader is probed only through rtpy.load_scene() on small files: a bogus key's
error message lists the valid keys ("unknown key ...; valid keys: a, b"), a bogus type
lists the types ('expected one of "x", "y"'), a bogus table lists the tables.
"""

from __future__ import annotations

import re
import tomllib

import pytest

import rtpy
from rtpy.materials import MATERIALS

from .markdown import ROOT, code_spans, sections, tables

DOC = ROOT / "docs" / "scene-format.md"
BOGUS = "zzz_not_a_key"

# The tables of a scene file, as the page's headings name them, and how to write a
# probe for each: the header of one entry with its type (None: the table has no
# types), and the TOML that names a type for typed tables.
PLAIN = {"[camera]": "[camera]", "[render]": "[render]"}
TYPED = {
    "[textures.NAME]": "[textures.probe]",
    "[materials.NAME]": "[materials.probe]",
    "[[objects]]": "[[objects]]",
    "[[lights]]": "[[lights]]",
}
TOP_LEVEL = {"[camera]": "camera", "[render]": "render", "[textures.NAME]": "textures"} | {
    "[materials.NAME]": "materials",
    "[[objects]]": "objects",
    "[[lights]]": "lights",
}


# --- what the page documents ---------------------------------------------------------
def table_of(text: str, name: str) -> list[list[str]]:
    """The rows of the first table under the heading that names `name` in code."""
    for heading, body in sections(text):
        if f"`{name}`" in heading:
            found = tables(body)
            assert found, f"docs/scene-format.md: no table under the heading {heading!r}"
            return found[0][1]
    raise AssertionError(f"docs/scene-format.md: no section headed `{name}`")


def documented(text: str) -> dict[str, dict[str | None, set[str]]]:
    """{table: {type (None for untyped tables): the documented keys}}."""
    out: dict[str, dict[str | None, set[str]]] = {}
    for name in PLAIN:
        out[name] = {None: {code_spans(row[0])[0] for row in table_of(text, name)}}
    for name in TYPED:
        kinds: dict[str | None, set[str]] = {}
        for row in table_of(text, name):
            kind = code_spans(row[0])[0].strip('"')
            kinds[kind] = {"type", *code_spans(row[1])}
        out[name] = kinds
    return out


def documented_defaults(text: str, name: str) -> dict[str, str]:
    """{key: the TOML text of its documented default} of an untyped table."""
    return {code_spans(row[0])[0]: code_spans(row[1])[0] for row in table_of(text, name)}


# --- what the loader accepts ----------------------------------------------------------
class Probe:
    """Loads small scene files through rtpy.load_scene and reads its messages."""

    def __init__(self, folder) -> None:
        self.folder = folder
        self.count = 0

    def load(self, text: str):
        """The scene, or the error message (str) when the file is refused."""
        self.count += 1
        path = self.folder / f"probe{self.count}.toml"
        path.write_text(text)
        try:
            return rtpy.load_scene(str(path))
        except Exception as e:  # the loader's error type may move; its message is the API
            return f"{type(e).__name__}: {e}"

    def message(self, text: str) -> str:
        result = self.load(text)
        assert isinstance(result, str), f"the loader accepted a bogus entry:\n{text}"
        return result

    def valid_keys(self, header: str, kind: str | None) -> set[str]:
        typed = f'type = "{kind}"\n' if kind is not None else ""
        msg = self.message(f"{header}\n{typed}{BOGUS} = 1\n")
        m = re.search(r"unknown key.*?valid keys: (.*?)(?: \(line \d+\))?(?: — .*)?$", msg)
        assert m, f"{header}: no list of valid keys in the loader's message: {msg}"
        return {k.strip() for k in m.group(1).split(",")}

    def types(self, header: str) -> set[str]:
        msg = self.message(f'{header}\ntype = "{BOGUS}"\n')
        m = re.search(r"expected one of (.*?)(?: \(line \d+\))?(?: — .*)?$", msg)
        assert m, f"{header}: no list of types in the loader's message: {msg}"
        return set(re.findall(r'"([^"]+)"', m.group(1)))

    def tables(self) -> set[str]:
        msg = self.message(f"{BOGUS} = 1\n")
        m = re.search(r"the tables are (.*?)(?: \(line \d+\))?(?: — .*)?$", msg)
        assert m, f"no list of tables in the loader's message: {msg}"
        return {t.strip() for t in m.group(1).split(",")}


def shipped_with_rtpy(kind: str) -> bool:
    """A material type of rtpy itself, not one a test or plugin registered."""
    cls = MATERIALS.get(kind)
    return cls is None or cls.__module__.startswith("rtpy.")


def contract_problems(text: str, probe: Probe) -> list[str]:
    """Every difference between the keys the page documents and the keys the loader
    accepts, one line each."""
    problems = []
    docs = documented(text)
    accepted_tables = probe.tables()
    for name, top in TOP_LEVEL.items():
        if top not in accepted_tables:
            problems.append(f"{name} is documented but the loader has no table {top!r}")
    for top in accepted_tables - set(TOP_LEVEL.values()):
        problems.append(f"the loader accepts the table {top!r}, which is not documented")
    for name, header in {**PLAIN, **TYPED}.items():
        kinds = docs[name]
        if name in TYPED:
            accepted = {k for k in probe.types(header) if shipped_with_rtpy(k)}
            for kind in sorted(set(kinds) - accepted):
                problems.append(f'{name}: type "{kind}" is documented but not accepted')
            for kind in sorted(accepted - set(kinds)):
                problems.append(f'{name}: type "{kind}" is accepted but not documented')
        for kind, keys in kinds.items():
            where = name if kind is None else f'{name} type "{kind}"'
            typed = f'type = "{kind}"\n' if kind is not None else ""
            try:
                valid = probe.valid_keys(header, kind)
            except AssertionError as e:
                problems.append(f"{where}: {e}")
                continue
            for key in sorted(keys - valid):
                problems.append(f"{where}: {key!r} is documented but not accepted")
            for key in sorted(valid - keys):
                problems.append(f"{where}: {key!r} is accepted but not documented")
            for key in sorted(keys & valid - {"type"}):
                result = probe.load(f"{header}\n{typed}{key} = 1\n")
                if isinstance(result, str) and "unknown key" in result:
                    problems.append(f"{where}: {key!r} is refused as unknown: {result}")
    return problems


def default_problems(text: str, probe: Probe) -> list[str]:
    """[camera] and [render] keys whose documented default differs from what the
    loader uses when the key is left out."""

    def state(scene) -> dict:
        camera = scene.camera
        public = {k: getattr(camera, k) for k in dir(camera) if not k.startswith("_")}
        fields = {k: v for k, v in public.items() if not callable(v)}
        return {
            "camera": fields,
            "settings": scene.settings,
            "background": scene.background,
            "sky": scene.sky,
        }

    problems = []
    empty = probe.load("")
    assert not isinstance(empty, str), f"an empty scene file is refused: {empty}"
    for name in PLAIN:
        for key, default in documented_defaults(text, name).items():
            try:
                tomllib.loads(f"v = {default}")
            except tomllib.TOMLDecodeError:
                problems.append(f"{name} {key}: the default `{default}` is not a TOML value")
                continue
            scene = probe.load(f"{name}\n{key} = {default}\n")
            if isinstance(scene, str):
                problems.append(f"{name} {key}: the documented default is refused: {scene}")
            elif state(scene) != state(empty):
                problems.append(
                    f"{name} {key}: writing the documented default {default} gives another "
                    "scene than leaving the key out"
                )
    return problems


@pytest.fixture
def probe(tmp_path) -> Probe:
    return Probe(tmp_path)


def test_every_documented_key_is_accepted_and_every_accepted_key_documented(probe):
    problems = contract_problems(DOC.read_text(encoding="utf-8"), probe)
    assert not problems, "docs/scene-format.md and the loader differ:\n" + "\n".join(problems)


def test_documented_defaults_are_the_loaders(probe):
    problems = default_problems(DOC.read_text(encoding="utf-8"), probe)
    assert not problems, "docs/scene-format.md's defaults differ:\n" + "\n".join(problems)


def test_a_page_that_differs_from_the_loader_is_caught(probe):
    """Planted mistakes: a documented key the loader lacks, an accepted key left out,
    a material type left out, a wrong default."""
    text = DOC.read_text(encoding="utf-8")
    bogus_key = text.replace("| `spp` | `16` |", "| `spp` | `16` |\n| `spp_bogus` | `1` | x |", 1)
    no_mis = re.sub(r"^\| `mis` \|.*\n", "", text, count=1, flags=re.MULTILINE)
    no_ward = re.sub(r'^\| `"ward"` \|.*\n', "", text, count=1, flags=re.MULTILINE)
    no_fuzz = text.replace("`fuzz` (0)", "fuzz (0)", 1)
    wrong_default = text.replace("| `vfov` | `90` |", "| `vfov` | `60` |", 1)
    for planted in (bogus_key, no_mis, no_ward, no_fuzz, wrong_default):
        assert planted != text, "a planted mistake did not apply: update this test"
    assert any("'spp_bogus' is documented" in p for p in contract_problems(bogus_key, probe))
    assert any("'mis' is accepted" in p for p in contract_problems(no_mis, probe))
    assert any('type "ward" is accepted' in p for p in contract_problems(no_ward, probe))
    assert any("'fuzz' is accepted" in p for p in contract_problems(no_fuzz, probe))
    assert any("vfov" in p for p in default_problems(wrong_default, probe))
