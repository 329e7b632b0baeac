"""Speed against error: `python -m rtpy bench` (docs/bench.md).

scenes.py      the integrator variants and the scenes with their references
convergence.py error, bias tests and convergence slopes against a reference
run.py         rendering the levels of every series and measuring them
report.py      the printed tables, bench.csv, bench.json and bench.png
command.py     the command line
machine.py     the machine a run was measured on
"""
