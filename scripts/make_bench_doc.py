"""Regenerate the latest results of docs/bench.md, docs/bench/bench.csv and
docs/bench/bench.png: run `rtpy bench` on the analytic scenes and two bundled
scenes with both backends, and write the section between the markers of
docs/bench.md with the command, the machine and its load, the table and what
it shows (rtpy.cli.bench.report.format_doc_section). The rest of docs/bench.md is
written by hand.

Run ``python scripts/make_bench_doc.py`` (about 15 minutes on 2 cores: 56
series of --budget seconds each, plus rendering the two references once);
``--budget 1 --scenes furnace`` makes a quick trial run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rtpy.cli.bench.machine import machine
from rtpy.cli.bench.report import format_doc_section, plot, replace_generated, write_outputs
from rtpy.cli.bench.run import run_bench
from rtpy.testing.analytic_scenes import ANALYTIC_SCENES

DOCS = Path(__file__).resolve().parent.parent / "docs"
SCENES = [*ANALYTIC_SCENES, "cornell", "week08_three_balls"]
BACKENDS = ("numpy", "scalar")
WIDTH, REPEATS = 64, 4


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--budget", type=float, default=8.0, help="seconds per series")
    parser.add_argument("--scenes", nargs="*", default=SCENES, help="scenes to measure")
    args = parser.parse_args(argv)

    def log(message: str) -> None:
        print(message, file=sys.stderr)

    before = machine()
    result = run_bench(
        args.scenes, BACKENDS, budget=args.budget, width=WIDTH, repeats=REPEATS, log=log
    )
    after = machine()
    if result.interrupted:
        log("interrupted: docs/bench.md is left as it was")
        return 130
    out = DOCS / "bench"
    for path in write_outputs(result, out):
        if path.suffix == ".json":  # its date and load belong to one run, not the docs
            path.unlink()
    plot(result, out)
    command = (
        f"python -m rtpy bench {' '.join(args.scenes)} \\\n"
        f"    --backends {','.join(BACKENDS)} --budget {args.budget:g} "
        f"--width {WIDTH} --repeats {REPEATS}"
    )
    doc = DOCS / "bench.md"
    section = format_doc_section(result, command, before, after)
    doc.write_text(replace_generated(doc.read_text(), section))
    log(f"wrote {doc}, {out / 'bench.csv'} and {out / 'bench.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
