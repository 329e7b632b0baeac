"""The layout shows the architecture: short modules and functions, and tests that mirror
the modules.

- every module of rtpy/ has at most MAX_MODULE_LINES lines, and every function there at
  most MAX_FUNCTION_LINES from its `def` to its last line, except LONG_FUNCTIONS, each a
  formula that reads better whole;
- every module rtpy/<path>/<name>.py has its test file tests/<path>/test_<name>.py,
  except a package's __init__.py (its exports: what it defines is tested where it is
  used) and UNMIRRORED, each with where it is tested;
- every test file has a test that is not marked slow, so that the everyday loop
  `python -m pytest -m "not slow"` touches every module.

Each check is a function of a source tree, run on this one and, to show that it can
fail, on a small tree with planted violations. An exception that no longer applies
is reported too, so the lists stay true.
"""

from __future__ import annotations

import ast
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
    "rtpy/__main__.py": "tests/io/test_cli.py runs `python -m rtpy`",
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
    """rtpy/a/b.py -> tests/a/test_b.py."""
    return Path("tests", *rel.parts[1:-1], f"test_{rel.stem}.py")


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
