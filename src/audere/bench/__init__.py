"""The benchmark harness: run the paper's experiment grid resumably, then report its metrics.

- :func:`make_grid`, :class:`Experiment`, :func:`parse_seeds`: the grid;
- :func:`run_grid`, :class:`LocalRunner`, :class:`Runner`, :class:`ExecutorPool`: running it (the
  runner is a seam: a distributed engine plugs in as another :class:`Runner`);
- :class:`ResultStore`, :class:`ResponseCache`: the append-only results directory;
- :func:`read_records`, :func:`summarize`, :func:`success_at_k`, :func:`wilson_interval`: metrics;
- :func:`write_report`, :func:`experiment_html`, :func:`write_experiment_html`: tables, figures, pages;
- :func:`load_results`: the records as a pandas DataFrame, one row per experiment.

The command line is ``audere bench run ...`` and ``audere bench report DIR``.
"""

from __future__ import annotations

import os
from typing import Any

from audere.bench._grid import METHODS, PROVISIONS, Experiment, make_grid, parse_seeds
from audere.bench._metrics import read_records, success_at_k, summarize, wilson_interval
from audere.bench._report import Report, experiment_html, write_experiment_html, write_report
from audere.bench._runner import ExecutorPool, LocalRunner, Runner, RunSummary, run_grid
from audere.bench._store import ResponseCache, ResultStore, read_jsonl

__all__ = [
    "METHODS",
    "PROVISIONS",
    "ExecutorPool",
    "Experiment",
    "LocalRunner",
    "Report",
    "ResponseCache",
    "ResultStore",
    "RunSummary",
    "Runner",
    "experiment_html",
    "load_results",
    "make_grid",
    "parse_seeds",
    "read_jsonl",
    "read_records",
    "run_grid",
    "success_at_k",
    "summarize",
    "wilson_interval",
    "write_experiment_html",
    "write_report",
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
