"""The benchmark harness: run the paper's experiment grid resumably, then report its metrics.

- :func:`make_grid`, :class:`Experiment`, :func:`parse_seeds`: the grid;
- :func:`run_grid`, :class:`LocalRunner`, :class:`Runner`, :class:`ExecutorPool`: running it (the
  runner is a seam: a distributed engine plugs in as another :class:`Runner`);
- :class:`ResultStore`, :class:`ResponseCache`: the append-only results directory;
- :func:`load_results`: the records as a pandas DataFrame, one row per experiment.

The command line is ``audere bench run ...`` and ``audere bench report DIR``.
"""

from __future__ import annotations

import os
from typing import Any

from audere.bench._grid import METHODS, PROVISIONS, Experiment, make_grid, parse_seeds
from audere.bench._runner import ExecutorPool, LocalRunner, Runner, RunSummary, run_grid
from audere.bench._store import ResponseCache, ResultStore, read_jsonl

__all__ = [
    "METHODS",
    "PROVISIONS",
    "ExecutorPool",
    "Experiment",
    "LocalRunner",
    "ResponseCache",
    "ResultStore",
    "RunSummary",
    "Runner",
    "load_results",
    "make_grid",
    "parse_seeds",
    "read_jsonl",
    "run_grid",
]


def load_results(directory: str | os.PathLike[str]) -> Any:
    """The results of a run as a pandas DataFrame, one row per experiment.

    Parameters
    ----------
    directory
        A results directory written by ``audere bench run`` (or :func:`run_grid`).

    Returns
    -------
    pandas.DataFrame
        The columns of the records (``scenario``, ``seed``, ``method``, ``model``, ``temperature``,
        ``provision``, ``status``, ``success``, ``rounds``, ``rounds_to_success``, ``calls``,
        ``categories``, tokens, ``cost``, ``wall_s``, ...).

    Raises
    ------
    MissingDependencyError
        When pandas is not installed (``pip install 'audere[bench]'``).
    """
    from audere._optional import require

    pandas = require("pandas", extra="bench", purpose="audere.bench.load_results")
    from pathlib import Path

    from audere.bench._store import RESULTS

    path = Path(directory)
    file = path / RESULTS if path.is_dir() else path
    seen: dict[str, dict[str, Any]] = {}
    for record in read_jsonl(file):
        seen.setdefault(str(record.get("key")), record)
    return pandas.DataFrame(list(seen.values()))
