"""What run_autograder takes from a submission: the week's task files, and only those.

Gradescope puts the submission in /autograder/submission/: the repository's files
(uploaded as a folder), a zip of them, or a GitHub checkout whose repository may sit
one folder down. `find_repository` finds the folder holding rtpy/ with the task
files; `take_task_files` copies those files (and nothing else) over the pristine
copy of the assignment. A task file that cannot be used is put back to the
assignment's stub and the reason is kept for the report:

- missing from the submission, a symbolic link (or below one), too large or not text;
- not valid Python (`compile_errors`: the SyntaxError's line), or more than Python's
  compiler can take (it compiles in a process of its own, with limits, so that such
  a file costs its own tasks and never the judge);
- importing it fails or hangs (`import_problem`, in the sandboxed child process
  (rtpy.grading.sandbox) with a time limit: the exception and the line in the
  student's file).

Files changed elsewhere in the submission are listed (`ignored_changes`) so the
student learns that those edits do not count.
"""

from __future__ import annotations

import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from .protocol import printable

MAX_FILE_BYTES = 1_000_000  # a task file larger than this is not a student's source
MAX_UNZIPPED_BYTES = 500_000_000
MAX_DEPTH = 3  # how far below the submission folder the repository may be
SKIPPED_FOLDERS = {"__MACOSX", ".git", "__pycache__", ".venv", "venv", "node_modules"}
FRAME = re.compile(r'File "([^"]+)", line (\d+)')
COMPILE_SECONDS = 30.0  # to compile the task files
COMPILE_MEMORY = 2 * 2**30  # bytes the compiling process may take
# Arguments: the files; prints [None | [line, message] | text] in their order.
COMPILE = """import json, sys
found = []
for path in sys.argv[1:]:
    try:
        compile(open(path, encoding="utf-8").read(), path, "exec", dont_inherit=True)
        found.append(None)
    except SyntaxError as err:
        found.append([err.lineno, err.msg])
    except ValueError as err:
        found.append(str(err))
print(json.dumps(found))
"""


class SubmissionError(Exception):
    """A submission that cannot be read at all (a broken zip, nothing in it)."""


@dataclass
class Taken:
    """The task files taken from a submission, and what went wrong with the others."""

    repository: Path | None
    files: list[str] = field(default_factory=list)  # task files taken (posix, from the root)
    problems: dict[str, str] = field(default_factory=dict)  # task file -> why it is the stub
    notes: list[str] = field(default_factory=list)  # where files were found


def unpack(submission: Path, scratch: Path) -> Path:
    """The folder to search: `submission` itself, or where its one zip is unpacked when
    it holds a zip and no rtpy/ folder."""
    if any(p.is_dir() for p in _folders(submission, "rtpy")):
        return submission
    zips = sorted(p for p in submission.rglob("*.zip") if _visible(p, submission))
    if not zips:
        return submission
    dest = scratch / "unzipped"
    dest.mkdir(parents=True, exist_ok=True)
    try:
        with zipfile.ZipFile(zips[0]) as archive:
            _extract(archive, dest)
    except (zipfile.BadZipFile, OSError, RuntimeError, EOFError) as err:
        raise SubmissionError(f"{zips[0].name}: not a zip file that can be read ({err})") from err
    return dest


def _extract(archive: zipfile.ZipFile, dest: Path) -> None:
    """Extract regular files only, each inside dest, at most MAX_UNZIPPED_BYTES in all."""
    total = 0
    root = dest.resolve()
    for info in archive.infolist():
        if info.is_dir() or (info.external_attr >> 16) & 0o170000 == 0o120000:
            continue  # folders are made as needed; symbolic links are skipped
        target = (dest / info.filename).resolve()
        if not target.is_relative_to(root):
            continue  # ../ or an absolute path
        total += info.file_size
        if total > MAX_UNZIPPED_BYTES:
            raise SubmissionError(f"the zip unpacks to more than {MAX_UNZIPPED_BYTES:,} bytes")
        target.parent.mkdir(parents=True, exist_ok=True)
        with archive.open(info) as src, open(target, "wb") as out:
            shutil.copyfileobj(src, out)


def _visible(path: Path, base: Path) -> bool:
    return not any(part in SKIPPED_FOLDERS for part in path.relative_to(base).parts)


def _folders(base: Path, name: str) -> list[Path]:
    """Folders called `name` at most MAX_DEPTH levels below base (base/name included)."""
    found, level = [], [base]
    for _ in range(MAX_DEPTH + 1):
        nxt = []
        for folder in level:
            try:
                children = sorted(p for p in folder.iterdir() if p.is_dir() and not p.is_symlink())
            except OSError:
                continue
            for child in children:
                if child.name in SKIPPED_FOLDERS:
                    continue
                if child.name == name:
                    found.append(child)
                nxt.append(child)
        level = nxt
    return found


def find_repository(base: Path, task_files: list[str]) -> Path | None:
    """The folder (base or below) whose rtpy/ holds the most task files, the shallowest
    of those; None when no rtpy/ folder holds any."""
    best, best_count = None, 0
    for rtpy_dir in _folders(base, "rtpy"):
        root = rtpy_dir.parent
        count = sum((root / rel).is_file() for rel in task_files)
        if count > best_count:
            best, best_count = root, count
    return best


def _by_name(base: Path, rel: str) -> Path | None:
    """The one file under base with rel's file name, for a submission of loose files."""
    name = Path(rel).name
    matches = [p for p in base.rglob(name) if p.is_file() and _visible(p, base)]
    return matches[0] if len(matches) == 1 else None


def take_task_files(base: Path, task_files: list[str], work: Path) -> Taken:
    """Copy each task file found under base over work's copy; the others keep the stub."""
    repository = find_repository(base, task_files)
    taken = Taken(repository)
    if repository is not None and repository != base:
        shown = repository.relative_to(base).as_posix()
        taken.notes.append(f"Your repository was found in the folder {shown}/.")
    for rel in task_files:
        source = repository / rel if repository is not None else None
        if source is None or not source.is_file():
            source = _by_name(base, rel)
            if source is not None:
                taken.notes.append(f"{rel}: taken from {source.relative_to(base).as_posix()}")
        problem = _unusable(source, base)
        if problem:
            taken.problems[rel] = problem
            continue
        shutil.copyfile(source, work / rel)
        taken.files.append(rel)
    return taken


def _unusable(source: Path | None, base: Path) -> str | None:
    """Why the file at source cannot be taken, or None. A task file is read as a
    regular file of the submission: a symbolic link, or a file below one, is refused
    (it could name any file of the grading machine)."""
    if source is None:
        return "not in your submission"
    rel = source.relative_to(base)
    for k in range(1, len(rel.parts) + 1):
        if (base / Path(*rel.parts[:k])).is_symlink():
            return "a symbolic link, not a file: submit the file itself"
    if not source.is_file():
        return "not a regular file"
    if source.stat().st_size > MAX_FILE_BYTES:
        return f"larger than {MAX_FILE_BYTES:,} bytes"
    try:
        source.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        return "not a UTF-8 text file"
    return None


def compile_errors(work: Path, files: list[str]) -> dict[str, str]:
    """task file -> its SyntaxError (line and message), for those that do not compile.
    They are compiled by a process of their own (COMPILE_SECONDS, COMPILE_MEMORY), and
    one by one when that process fails (a file too much for the compiler)."""
    errors = {}
    together = _compiled([work / rel for rel in files])
    if not isinstance(together, list) or len(together) != len(files):
        together = [_compiled([work / rel]) for rel in files]
        together = [f[0] if isinstance(f, list) and len(f) == 1 else f for f in together]
    for rel, found in zip(files, together, strict=True):
        if found is None:
            continue
        if isinstance(found, list) and len(found) == 2:
            lineno, msg = found
            lines = (work / rel).read_text(encoding="utf-8").splitlines()
            line = (
                lines[lineno - 1].strip()
                if isinstance(lineno, int) and 0 < lineno <= len(lines)
                else ""
            )
            shown = f": {printable(line, 200)}" if line else ""
            errors[rel] = f"line {lineno}: SyntaxError: {printable(str(msg), 200)}{shown}"
        else:
            errors[rel] = f"cannot be compiled: {printable(str(found), 300)}"
    return errors


def _compiled(paths: list[Path]):
    """For each path: None when it compiles, [line, message] of its SyntaxError, or
    why not; a text alone when the compiling process failed."""
    options: dict = {}
    if os.name == "posix":
        options["preexec_fn"] = _compile_limits
    try:
        proc = subprocess.run(
            [sys.executable, "-I", "-S", "-c", COMPILE, *map(str, paths)], capture_output=True,
            text=True, timeout=COMPILE_SECONDS, cwd=paths[0].parent if paths else None,
            **options,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        return f"Python's compiler did not finish within {COMPILE_SECONDS:g} s"
    try:
        if proc.returncode == 0:
            return json.loads(proc.stdout)
    except ValueError:
        pass
    return "the file is too large or too deeply nested for Python's compiler"


def _compile_limits() -> None:
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (COMPILE_MEMORY, COMPILE_MEMORY))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def import_problem(child, files: list[str], work: Path) -> tuple[str | None, str] | None:
    """None when the sandboxed child (a new rtpy.grading.sandbox.Child in work) imports
    every rtpy module and the probes; else (the student's task file to blame, or None
    when none can be named; the problem). The child is stopped."""
    from .sandbox import ChildFailure, StudentError

    try:
        child.call("import_everything", {}, float(child.config.get("import_timeout", 60.0)))
        return None
    except StudentError as err:
        if err.where is not None and err.where[1] in files:
            return err.where[1], f"line {err.where[2]}: {err}"
        return None, str(err)
    except ChildFailure as err:
        text = child.output()
        dump = "Timeout (" in text and "Traceback" not in text  # faulthandler's
        frames = [(_relative(path, work), line) for path, line in FRAME.findall(text)]
        if dump:  # faulthandler lists the most recent call first, a traceback last
            frames.reverse()
        blamed = None
        for rel, line in frames:
            if rel in files:
                blamed = (rel, line)  # the innermost task file
        lines = [ln.strip() for ln in text.strip().splitlines() if ln.strip()]
        if dump:
            what = f"importing it did not finish within {child.start_timeout:g} s"
        else:
            what = printable(lines[-1], 300) if lines and "Traceback" in text else str(err)
        if blamed is None:
            return None, what
        return blamed[0], f"line {blamed[1]}: {what}"
    finally:
        child.stop()


def _relative(path: str, base: Path) -> str | None:
    """path (as the child printed it: text, never looked up) relative to base, in
    posix form; None outside it."""
    text = os.path.normpath(path)
    for root in {str(base), os.path.realpath(base)}:
        prefix = os.path.join(os.path.normpath(root), "")
        if text.startswith(prefix):
            return Path(text[len(prefix) :]).as_posix()
    return None


def ignored_changes(repository: Path | None, pristine: Path, task_files: list[str]) -> list[str]:
    """Files of the submitted repository, other than the task files, that differ from
    the assignment's or are new under rtpy/ (their changes are not graded)."""
    if repository is None:
        return []
    changed = []
    for folder in ("rtpy", "assignments", "tests", "scenes"):
        top = repository / folder
        if not top.is_dir():
            continue
        for path in sorted(top.rglob("*")):
            rel = path.relative_to(repository).as_posix()
            if not path.is_file() or rel in task_files or not _visible(path, repository):
                continue
            original = pristine / rel
            if original.is_file():
                if not filecmp.cmp(path, original, shallow=False):
                    changed.append(rel)
            elif folder == "rtpy" and path.suffix == ".py":
                changed.append(rel)
    return changed
