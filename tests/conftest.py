"""Shared test configuration.

Hypothesis explores new random examples on every local run; under CI (CI=true)
it is derandomized, so a CI run is reproducible and never fails by chance.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")
