"""The layout shows the architecture: short modules and functions, and tests that mirror
the modules.

- every module of rtpy/ has at most MAX_MODULE_LINES lines, and every function there at
  most MAX_FUNCTION_LINES from its `def` to its last line, except LONG_FUNCTIONS, each a
  formula that reads better whole;
- every module rtpy/<path>/<name>.py has its test file tests/<path>/test_<name>.py,
  except a package's __init__.py (its exports: what it defines is tested where it is
  used) and UNMIRRORED, each with where it is tested;
- every test file has a test that is not marked slow, so that the everyday loop
  `python -m pytest -m "not slow"` touches every module;
- every module of rtpy/ is on a floor (FLOORS): the course (the top-level modules,
  materials/ and integrators/: what a student reads, private `_` helpers included),
  the engine (engine/: the render loop, backends, workers, files, signals; and the
  vectorized twin numpy_backend/), the files (io/), the checks (testing/, grading/
  and the front door `rtpy/__init__.py`) and the command line (cli/). A module
  imports from its own floor or below, anywhere in it except under
  `if TYPE_CHECKING:`, but for UPWARD_IMPORTS, each with why; and no modules import
  each other in a circle at import time (their module-level imports).

Each check is a function of a source tree, run on this one and, to show that it can
fail, on a small tree with planted violations. An exception that no longer applies
is reported too, so the lists stay true.
"""

from __future__ import annotations

import ast
import math
import subprocess
import sys
from pathlib import Path

from .tiers import FAST_TESTS

ROOT = Path(__file__).resolve().parents[1]
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80

# "path::qualified name" -> why the function reads better whole.
LONG_FUNCTIONS: dict[str, str] = {}

# rtpy module -> where it is tested instead of a mirrored test file.
UNMIRRORED = {
    "rtpy/__main__.py": "tests/cli/test_main.py runs `python -m rtpy`",
    "rtpy/numpy_backend/integrators/integrator.py": (
        "the base class of the kernels in tests/numpy_backend/integrators/"
    ),
    "rtpy/numpy_backend/integrators/jittered.py": (
        "tests/numpy_backend/test_agreement.py renders every scene with it"
    ),
    "rtpy/numpy_backend/materials/material.py": (
        "the base class of the kernels in tests/numpy_backend/materials/"
    ),
    "rtpy/numpy_backend/materials/glossy.py": (
        "the mixture every glossy kernel uses: tests/numpy_backend/materials/test_table.py"
    ),
    "rtpy/numpy_backend/materials/blinn_phong.py": (
        "tests/numpy_backend/materials/test_table.py, against the scalar model"
    ),
    "rtpy/numpy_backend/materials/oren_nayar.py": (
        "tests/numpy_backend/materials/test_table.py, against the scalar model"
    ),
}


FLOOR_NAMES = ("the course", "the engine", "the files", "the checks", "the front")
# Path under rtpy/ (a file, or a folder ending in "/") -> its floor, the longest that
# matches; a module no entry matches is on floor 0, the course: the top-level modules,
# materials/ and integrators/, what a student reads.
FLOORS: dict[str, int] = {
    "rtpy/engine/": 1,
    "rtpy/numpy_backend/": 1,
    "rtpy/io/": 2,
    "rtpy/testing/": 3,
    "rtpy/grading/": 3,
    "rtpy/cli/": 4,
    "rtpy/__main__.py": 4,
    # The front door: `import rtpy` exports the API of every floor (render, load_scene,
    # BACKENDS) and imports the registrations the engine looks up (backends, writers);
    # the graders import it whole to see every name a student's code may reach.
    "rtpy/__init__.py": 3,
}

# "importer -> imported" (paths) -> why the import goes up a floor.
UPWARD_IMPORTS: dict[str, str] = {}


def modules(root: Path) -> list[Path]:
    return sorted((root / "rtpy").rglob("*.py"))


def long_modules(root: Path) -> list[str]:
    """The modules of rtpy/ over MAX_MODULE_LINES lines."""
    out = []
    for path in modules(root):
        n = len(path.read_text().splitlines())
        if n > MAX_MODULE_LINES:
            out.append(f"{path.relative_to(root)}: {n} lines > {MAX_MODULE_LINES}")
    return out


def function_lengths(path: Path) -> dict[str, int]:
    """Qualified name -> lines from `def` to the last line, for every function."""
    lengths = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    lengths[name] = child.end_lineno - child.lineno + 1
                visit(child, f"{name}.")

    visit(ast.parse(path.read_text()), "")
    return lengths


def long_functions(root: Path, allowed: dict[str, str]) -> list[str]:
    """Functions of rtpy/ over MAX_FUNCTION_LINES lines that `allowed` does not name,
    and the entries of `allowed` that are not such a function."""
    out, found = [], set()
    for path in modules(root):
        rel = path.relative_to(root).as_posix()
        for name, n in function_lengths(path).items():
            key = f"{rel}::{name}"
            if n > MAX_FUNCTION_LINES:
                found.add(key)
                if key not in allowed:
                    out.append(f"{key}: {n} lines > {MAX_FUNCTION_LINES}")
    stale = [key for key in allowed if key not in found]
    return out + [f"{key}: not a function over {MAX_FUNCTION_LINES} lines" for key in stale]


def mirror_of(rel: Path) -> Path:
    """rtpy/a/b.py -> tests/a/test_b.py, and a private rtpy/a/_b.py -> tests/a/test_b.py."""
    return Path("tests", *rel.parts[1:-1], f"test_{rel.stem.lstrip('_')}.py")


def missing_mirrors(root: Path, exceptions: dict[str, str]) -> list[str]:
    """Modules of rtpy/ without their test file, and exceptions that no longer apply."""
    out = []
    for path in modules(root):
        rel = path.relative_to(root)
        mirrored = (root / mirror_of(rel)).exists()
        if rel.name == "__init__.py":
            continue
        if rel.as_posix() in exceptions:
            if mirrored:
                out.append(f"{rel.as_posix()}: has {mirror_of(rel).as_posix()}, drop it")
        elif not mirrored:
            out.append(f"{rel.as_posix()}: no {mirror_of(rel).as_posix()}")
    present = {p.relative_to(root).as_posix() for p in modules(root)}
    return out + [f"{rel}: no such module, drop it" for rel in exceptions if rel not in present]


def files_without_fast_tests(root: Path) -> list[str]:
    """Test files of root/tests where pytest -m "not slow" collects nothing."""
    every = {p.relative_to(root).as_posix() for p in (root / "tests").rglob("test_*.py")}
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-qq", "-m", "not slow",
         "-p", "no:cacheprovider", "tests"],
        cwd=root, capture_output=True, text=True,
    )  # fmt: skip
    fast = {line.split(": ")[0] for line in result.stdout.splitlines() if ": " in line}
    if result.returncode not in (0, 5):  # 5: nothing collected
        raise AssertionError(f"pytest --collect-only failed:\n{result.stdout[-3000:]}")
    return [f"{rel}: every test is marked slow" for rel in sorted(every - fast)]


def test_modules_and_functions_of_rtpy_are_short():
    assert long_modules(ROOT) == []
    assert long_functions(ROOT, LONG_FUNCTIONS) == []


def test_every_module_has_its_mirrored_test_file():
    assert missing_mirrors(ROOT, UNMIRRORED) == []


def test_every_test_file_has_a_test_in_the_fast_tier(request):
    """From this run's collection where it holds every test file (tests/tiers.py
    records it before -m deselects), else from a collection of its own."""
    every = {p.as_posix() for p in (ROOT / "tests").rglob("test_*.py")}
    collected = request.config.stash.get(FAST_TESTS, {})
    if every <= set(collected):
        slow_only = [Path(p).relative_to(ROOT).as_posix() for p in every if not collected[p]]
        assert sorted(slow_only) == []
    else:
        assert files_without_fast_tests(ROOT) == []


def test_the_checks_catch_planted_violations(tmp_path):
    """A tree with one violation of each rule, and an exception of each kind that
    no longer applies."""
    (tmp_path / "rtpy" / "pkg").mkdir(parents=True)
    (tmp_path / "tests" / "pkg").mkdir(parents=True)
    (tmp_path / "rtpy" / "__init__.py").write_text("")
    (tmp_path / "rtpy" / "pkg" / "__init__.py").write_text("")  # needs no test file
    (tmp_path / "rtpy" / "big.py").write_text("x = 1\n" * (MAX_MODULE_LINES + 1))
    body = "".join(f"        y = {k}\n" for k in range(MAX_FUNCTION_LINES))  # def + 80 lines
    (tmp_path / "rtpy" / "pkg" / "shade.py").write_text(
        f"class Lobe:\n    def long(self):\n{body}\n\ndef short():\n    pass\n"
    )
    (tmp_path / "rtpy" / "pkg" / "light.py").write_text("def fine():\n    pass\n")
    (tmp_path / "tests" / "test_big.py").write_text(
        "import pytest\n\n\n@pytest.mark.slow\ndef test_slow():\n    pass\n"
    )
    (tmp_path / "tests" / "pkg" / "test_light.py").write_text("def test_fast():\n    pass\n")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.pytest.ini_options]\nmarkers = ["slow: slow"]\n'
    )

    assert long_modules(tmp_path) == [f"rtpy/big.py: {MAX_MODULE_LINES + 1} lines > 500"]
    assert long_functions(tmp_path, {}) == ["rtpy/pkg/shade.py::Lobe.long: 81 lines > 80"]
    allowed = {"rtpy/pkg/shade.py::Lobe.long": "a formula", "rtpy/big.py::gone": "x"}
    assert long_functions(tmp_path, allowed) == [
        f"rtpy/big.py::gone: not a function over {MAX_FUNCTION_LINES} lines"
    ]
    assert missing_mirrors(tmp_path, {}) == ["rtpy/pkg/shade.py: no tests/pkg/test_shade.py"]
    stale = {"rtpy/pkg/shade.py": "tested elsewhere", "rtpy/pkg/light.py": "x", "rtpy/no.py": "x"}
    assert missing_mirrors(tmp_path, stale) == [
        "rtpy/pkg/light.py: has tests/pkg/test_light.py, drop it",
        "rtpy/no.py: no such module, drop it",
    ]
    assert files_without_fast_tests(tmp_path) == ["tests/test_big.py: every test is marked slow"]


# --- floors and cycles -------------------------------------------------------------------


def floor_of(rel: str, floors: dict[str, int] = FLOORS) -> int:
    """The floor of the module at rel (rtpy/...): the longest entry of floors that
    matches it, else 0."""
    hits = [p for p in floors if rel == p or (p.endswith("/") and rel.startswith(p))]
    return floors[max(hits, key=len)] if hits else 0


def module_names(root: Path) -> dict[str, str]:
    """Dotted module name -> path, for every module of rtpy/ (a package: its __init__)."""
    names = {}
    for path in modules(root):
        rel = path.relative_to(root)
        parts = list(rel.with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names[".".join(parts)] = rel.as_posix()
    return names


def _under_type_checking(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def imports_of(root: Path, rel: str, names: dict[str, str]) -> list[tuple[int, str, bool]]:
    """(line, path of the rtpy module imported, at module level?) for each import of
    the module at rel, but those under `if TYPE_CHECKING:`. `from a import b` imports
    the module a.b when there is one, else a."""
    name = next(n for n, r in names.items() if r == rel)
    package = name.split(".") if rel.endswith("__init__.py") else name.split(".")[:-1]
    found: list[tuple[int, str, bool]] = []

    def resolve(node: ast.Import | ast.ImportFrom) -> list[str]:
        if isinstance(node, ast.Import):
            return [a.name for a in node.names]
        base = node.module or ""
        if node.level:
            up = package[: len(package) - node.level + 1]
            base = ".".join([*up, *([node.module] if node.module else [])])
        return [f"{base}.{a.name}" if f"{base}.{a.name}" in names else base for a in node.names]

    def visit(node: ast.AST, top: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if _under_type_checking(child):
                for other in child.orelse:
                    visit(ast.Module(body=[other], type_ignores=[]), top)
            elif isinstance(child, ast.Import | ast.ImportFrom):
                for target in resolve(child):
                    while target and target not in names:  # import a.b.c: the module a.b
                        target = target.rpartition(".")[0]
                    if target:
                        found.append((child.lineno, names[target], top))
            else:
                inner = isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
                visit(child, top and not inner)

    visit(ast.parse((root / rel).read_text()), True)
    return sorted(set(found))  # `from a import b, c`: one import of a


def upward_imports(
    root: Path, allowed: dict[str, str], floors: dict[str, int] = FLOORS
) -> list[str]:
    """Imports of rtpy/ from a higher floor that `allowed` does not name, and the
    entries of `allowed` that are not such an import."""
    names = module_names(root)
    out, found = [], set()
    for rel in names.values():
        for line, target, _ in imports_of(root, rel, names):
            low, high = floor_of(rel, floors), floor_of(target, floors)
            if high > low:
                found.add(key := f"{rel} -> {target}")
                if key not in allowed:
                    out.append(
                        f"{rel}:{line}: imports {target}, a floor up "
                        f"({FLOOR_NAMES[low]} -> {FLOOR_NAMES[high]})"
                    )
    stale = [key for key in allowed if key not in found]
    return out + [f"{key}: not an import a floor up, drop it" for key in stale]


def import_cycles(root: Path) -> list[str]:
    """Each circle of modules of rtpy/ that import each other at module level (but
    under TYPE_CHECKING): its shortest circle through its first module."""
    names = module_names(root)
    graph = {
        rel: sorted({t for _, t, top in imports_of(root, rel, names) if top and t != rel})
        for rel in names.values()
    }
    out = []
    for group in _strongly_connected(graph):
        if len(group) < 2:
            continue
        start = min(group)
        paths = {start: [start]}
        queue = [start]
        while queue:  # breadth first, within the group, back to start
            rel = queue.pop(0)
            nxt = [t for t in graph[rel] if t in group]
            if start in nxt:
                out.append("import cycle: " + " -> ".join([*paths[rel], start]))
                break
            for t in nxt:
                if t not in paths:
                    paths[t] = [*paths[rel], t]
                    queue.append(t)
    return sorted(out)


def _strongly_connected(graph: dict[str, list[str]]) -> list[set[str]]:
    """Tarjan's strongly connected components of graph."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    groups: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = set()
            while True:
                w = stack.pop()
                group.add(w)
                if w == v:
                    break
            groups.append(group)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return groups


def engine_pipes(root: Path) -> list[str]:
    """What the course's files (floor 0) carry for a backend: a parameter defaulting to
    math's or the builtins' functions (`sqrt=math.sqrt`, `maximum=max`), a class's
    `kernel = ...`, a read of Vec3's slot e0 outside vec3.py."""
    out = []
    for path in modules(root):
        rel = path.relative_to(root).as_posix()
        if floor_of(rel) != 0:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                for default in [*node.args.defaults, *node.args.kw_defaults]:
                    text = ast.unparse(default) if default is not None else ""
                    function = callable(getattr(math, text.removeprefix("math."), None))
                    if text in ("max", "min") or (text.startswith("math.") and function):
                        out.append(f"{rel}:{node.lineno}: {node.name} takes ={text}")
            elif isinstance(node, ast.ClassDef):
                for item in node.body:
                    targets = item.targets if isinstance(item, ast.Assign) else []
                    if any(isinstance(t, ast.Name) and t.id == "kernel" for t in targets):
                        out.append(f"{rel}:{item.lineno}: {node.name}.kernel")
            elif isinstance(node, ast.Attribute) and node.attr == "e0" and rel != "rtpy/vec3.py":
                out.append(f"{rel}:{node.lineno}: reads .e0")
    return out


def test_the_course_files_carry_nothing_for_a_backend(tmp_path):
    assert engine_pipes(ROOT) == []
    planted = tmp_path / "rtpy" / "materials" / "velvet.py"
    planted.parent.mkdir(parents=True)
    planted.write_text(
        "import math\n\n\nclass Velvet:\n    kernel = 'velvet'\n\n\n"
        "def f(x, y, sqrt=math.sqrt, maximum=max):\n    return x.e0\n"
    )
    assert len(engine_pipes(tmp_path)) == 4


def test_every_module_is_on_a_floor_and_imports_only_down():
    present = [p.relative_to(ROOT).as_posix() for p in modules(ROOT)]
    assert {floor_of(rel) for rel in present} == {0, 1, 2, 3, 4}
    assert [entry for entry in FLOORS if not any(rel.startswith(entry) for rel in present)] == []
    assert upward_imports(ROOT, UPWARD_IMPORTS) == []


def test_no_modules_import_each_other_in_a_circle():
    assert import_cycles(ROOT) == []


def test_the_floor_checks_catch_planted_violations(tmp_path):
    """A tree with one import a floor up (and one under TYPE_CHECKING, allowed), one
    circle at import time (and one through a function's import, which is none), and
    an allowed upward import that no longer is one."""
    (tmp_path / "rtpy" / "io").mkdir(parents=True)
    (tmp_path / "rtpy" / "__init__.py").write_text("")
    (tmp_path / "rtpy" / "io" / "__init__.py").write_text("")
    (tmp_path / "rtpy" / "core.py").write_text(
        "from typing import TYPE_CHECKING\n\nfrom . import low\n\n"
        "if TYPE_CHECKING:\n    from .io import fmt\n\n\n"
        "def save():\n    from .io.fmt import write\n"
    )
    (tmp_path / "rtpy" / "low.py").write_text("from .core import save\n")
    (tmp_path / "rtpy" / "io" / "fmt.py").write_text(
        "from .. import core\n\n\ndef write():\n    pass\n"
    )

    planted = ("rtpy/core.py", "rtpy/engine/a.py", "rtpy/io/x.py", "rtpy/grading/g.py",
               "rtpy/cli/c.py")  # fmt: skip
    assert [floor_of(rel) for rel in planted] == [0, 1, 2, 3, 4]
    assert upward_imports(tmp_path, {}) == [
        "rtpy/core.py:10: imports rtpy/io/fmt.py, a floor up (the course -> the files)"
    ]
    allowed = {"rtpy/core.py -> rtpy/io/fmt.py": "a reason", "rtpy/low.py -> rtpy/io/fmt.py": "x"}
    assert upward_imports(tmp_path, allowed) == [
        "rtpy/low.py -> rtpy/io/fmt.py: not an import a floor up, drop it"
    ]
    assert import_cycles(tmp_path) == ["import cycle: rtpy/core.py -> rtpy/low.py -> rtpy/core.py"]


# --- a render from the command line ------------------------------------------------------


def calls_up_into_io(run) -> list[str]:
    """The calls from a lower floor up into rtpy/io while run() runs, each as
    "caller -> callee" (file:function): the times the core hands control back to the
    tools. With the command line's own call down into the core, 1 + len(result) is
    how often the render crosses io/."""
    package = ROOT / "rtpy"
    found: set[str] = set()

    def rel(code) -> str | None:
        path = Path(code.co_filename)
        return (
            f"rtpy/{path.relative_to(package).as_posix()}" if path.is_relative_to(package) else None
        )

    def hook(frame, event, arg) -> None:
        callee = rel(frame.f_code) if event == "call" else None
        if callee is None or not callee.startswith("rtpy/io/"):
            return
        caller = frame.f_back
        while caller is not None and rel(caller.f_code) is None:
            caller = caller.f_back  # through numpy, the standard library, ...
        if caller is not None and floor_of(rel(caller.f_code)) < floor_of(callee):
            name = f"{rel(caller.f_code)}:{caller.f_code.co_name}"
            found.add(f"{name} -> {callee}:{frame.f_code.co_name}")

    sys.setprofile(hook)
    try:
        run()
    finally:
        sys.setprofile(None)
    return sorted(found)


def render_from_the_command_line(out: Path) -> None:
    from rtpy.cli.main import main

    main(["render", "cornell", "--width", "8", "--spp", "1", "-j", "1", "-q", "-o", str(out)])


def test_a_render_from_the_command_line_crosses_io_at_most_twice(tmp_path):
    """Down from the command line once, and back up once: the image writer that the
    command gave the core's atomic write."""
    out = tmp_path / "out.png"
    assert calls_up_into_io(lambda: render_from_the_command_line(out)) == [
        "rtpy/engine/files.py:atomic_write -> rtpy/io/image.py:write"
    ]
    assert out.exists()


def test_the_trace_sees_a_core_function_that_calls_io(tmp_path, monkeypatch):
    """A planted Renderer.render, compiled as rtpy/engine/renderer.py's code, that checks the
    output path through rtpy/io itself."""
    import rtpy.engine.renderer

    source = (
        "def render(self, *args, **kwargs):\n"
        "    from rtpy.io.image import check_image_path\n"
        "    check_image_path(OUT)\n"
        "    return ORIGINAL(self, *args, **kwargs)\n"
    )
    namespace = {"ORIGINAL": rtpy.engine.renderer.Renderer.render, "OUT": tmp_path / "out.png"}
    exec(compile(source, str(ROOT / "rtpy" / "engine" / "renderer.py"), "exec"), namespace)
    monkeypatch.setattr(rtpy.engine.renderer.Renderer, "render", namespace["render"])
    found = calls_up_into_io(lambda: render_from_the_command_line(tmp_path / "out.png"))
    assert "rtpy/engine/renderer.py:render -> rtpy/io/image.py:check_image_path" in found
    assert len(found) == 2
