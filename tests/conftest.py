"""Shared test configuration: environment for offline, headless runs and the Hypothesis profile."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile

# Both are read at import time, so they are set before anything imports litellm or matplotlib:
# litellm would otherwise fetch its model cost map from the network when imported, and matplotlib
# would try to pick an interactive backend.
os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")
os.environ.setdefault("MPLBACKEND", "Agg")

# Hypothesis keeps a cache (constants collected from the source) under ./.hypothesis by default; tests
# never write into the working directory, so it goes to a temporary directory removed at exit.
if "HYPOTHESIS_STORAGE_DIRECTORY" not in os.environ:
    _hypothesis_dir = tempfile.mkdtemp(prefix="audere-hypothesis-")
    os.environ["HYPOTHESIS_STORAGE_DIRECTORY"] = _hypothesis_dir
    atexit.register(shutil.rmtree, _hypothesis_dir, ignore_errors=True)

from hypothesis import settings  # after the environment is set, on purpose

# "ci": reproducible (derandomized, so every run draws the same examples), no per-example deadline
# (timings vary on loaded machines), and no example database (tests never write into the working
# directory). Choose another profile with HYPOTHESIS_PROFILE=<name>, e.g. "dev" for more examples.
settings.register_profile("ci", deadline=None, derandomize=True, database=None, max_examples=50)
settings.register_profile("dev", deadline=None, database=None, max_examples=200)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
