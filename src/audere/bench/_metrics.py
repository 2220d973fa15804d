"""The benchmark's numbers: success rates with Wilson intervals, rounds and calls to success, success@k.

Everything here works on the records of ``results.jsonl`` (one JSON object per finished experiment,
see :func:`read_records`) as plain dictionaries, with the standard library and numpy only.

Infrastructure trouble is never counted as the model's failure: experiments whose status is
``"model_error"`` (the provider failed after retries) or ``"error"`` (the harness failed) are left
out of every success-rate denominator and counted apart, as ``n_infra``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, Final

import numpy as np

from audere.bench._store import RESULTS, iter_jsonl
from audere.errors import AudereError, InvalidArgumentError

__all__ = [
    "CATEGORIES",
    "GROUP",
    "INFRA_STATUSES",
    "METHOD_ORDER",
    "PROVISION_ORDER",
    "RESULTS_FILE",
    "SCENARIO_ORDER",
    "format_markdown",
    "is_counted",
    "is_solved",
    "read_records",
    "success_at_k",
    "summarize",
    "wilson_interval",
    "write_csv",
]

RESULTS_FILE: Final = RESULTS
"""The name of the records file inside a results directory."""

GROUP: Final = ("scenario", "method", "model", "temperature", "provision")
"""The record fields that define one cell of the benchmark grid (the seeds are its repetitions)."""

SCENARIO_ORDER: Final = ("track-lin", "track-car", "plan-easy", "plan-hard", "plan-stl")
"""The paper's scenarios, in the paper's order; other scenarios sort after them, alphabetically."""

METHOD_ORDER: Final = ("use-api", "code", "predict")
"""The methods, in the paper's order."""

CATEGORIES: Final = (
    "parsing",
    "syntax",
    "runtime",
    "timeout",
    "task_failure",
    "model_error",
    "sandbox_error",
)
"""The round outcomes counted as errors (every category but ``"success"``), in the taxonomy's order."""

PROVISION_ORDER: Final = ("on-demand", "all")
"""The API provisions, the paper's default first."""

INFRA_STATUSES: Final = frozenset({"model_error", "error"})
"""Statuses of experiments that infrastructure trouble ended: excluded from success rates."""

_Z95: Final = 1.959963984540054


# --------------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------------


def _jsonl_path(path_or_dir: str | Path, filename: str) -> Path:
    path = Path(path_or_dir)
    if path.is_dir():
        path = path / filename
    if not path.is_file():
        raise AudereError(
            f"path_or_dir: expected a results directory holding {filename} or the file itself, "
            f"got {str(path_or_dir)!r} (no file {str(path)!r})"
        )
    return path


def read_records(path_or_dir: str | Path) -> list[dict[str, Any]]:
    """Read the records of a benchmark run.

    Parameters
    ----------
    path_or_dir
        A results directory (its ``results.jsonl`` is read) or the ``.jsonl`` file itself.

    Returns
    -------
    list of dict
        One record per finished experiment, in the order written. A last line torn by a killed run
        is skipped. Should a key be written more than once, its first record is kept (as
        :func:`audere.bench.load_results` does).

    Raises
    ------
    AudereError
        If there is no such file, or a line other than the last is not a JSON object (the message
        names the file and the line number).
    """
    records: dict[Any, dict[str, Any]] = {}
    for number, record in iter_jsonl(_jsonl_path(path_or_dir, RESULTS_FILE)):
        key = record.get("key")
        records.setdefault(key if isinstance(key, str) else ("line", number), record)
    return list(records.values())


# --------------------------------------------------------------------------------------------------
# Statistics
# --------------------------------------------------------------------------------------------------


def _check_count(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 0:
        raise InvalidArgumentError(f"{name}: expected an integer >= 0, got {value!r}")
    return int(value)


def wilson_interval(successes: int, n: int, z: float = _Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion.

    Parameters
    ----------
    successes
        Number of successes, ``0 <= successes <= n``.
    n
        Number of trials.
    z
        The standard normal quantile of the confidence level (the default gives 95 %).

    Returns
    -------
    tuple of float
        ``(low, high)``, within [0, 1]; ``(0.0, 1.0)`` when ``n == 0`` (nothing is known).

    Raises
    ------
    InvalidArgumentError
        If a count is not an integer >= 0, ``successes > n``, or ``z`` is not a finite number > 0.

    Examples
    --------
    >>> [round(v, 4) for v in wilson_interval(81, 263)]
    [0.2553, 0.3662]
    """
    k = _check_count("successes", successes)
    trials = _check_count("n", n)
    if k > trials:
        raise InvalidArgumentError(f"successes: expected at most n={trials}, got {k}")
    if isinstance(z, bool) or not isinstance(z, int | float | np.floating) or not math.isfinite(z) or z <= 0:
        raise InvalidArgumentError(f"z: expected a finite number > 0, got {z!r}")
    if trials == 0:
        return 0.0, 1.0
    p = k / trials
    z2 = float(z) ** 2
    denominator = 1.0 + z2 / trials
    centre = (p + z2 / (2 * trials)) / denominator
    half = float(z) / denominator * math.sqrt(p * (1.0 - p) / trials + z2 / (4 * trials**2))
    low = 0.0 if k == 0 else max(0.0, centre - half)
    high = 1.0 if k == trials else min(1.0, centre + half)
    return low, high


# --------------------------------------------------------------------------------------------------
# Grouping
# --------------------------------------------------------------------------------------------------


def _field(record: Mapping[str, Any], name: str) -> Any:
    try:
        return record[name]
    except KeyError:
        key = record.get("key", "?")
        raise AudereError(f"record {key!r}: expected a field {name!r}, got only {sorted(record)}") from None


def _check_by(by: object) -> tuple[str, ...]:
    if isinstance(by, str) or not isinstance(by, Sequence) or not all(isinstance(f, str) for f in by):
        raise InvalidArgumentError(f"by: expected a sequence of field names, got {by!r}")
    if len(set(by)) != len(by):
        raise InvalidArgumentError(f"by: expected distinct field names, got {list(by)!r}")
    return tuple(by)


def _check_records(records: object) -> list[Mapping[str, Any]]:
    if isinstance(records, Mapping | str | bytes) or not isinstance(records, Iterable):
        raise InvalidArgumentError(f"records: expected a sequence of record dicts, got {records!r}")
    items = list(records)
    for index, record in enumerate(items):
        if not isinstance(record, Mapping):
            raise InvalidArgumentError(f"records[{index}]: expected a record dict, got {record!r}")
    return items


def _order_key(field: str, value: Any) -> tuple[int, float, str]:
    """A sort key: paper order for scenarios and methods, numbers before strings, None last."""
    order = {"scenario": SCENARIO_ORDER, "method": METHOD_ORDER, "provision": PROVISION_ORDER}.get(field)
    if order is not None and value in order:
        return 0, float(order.index(value)), ""
    if value is None:
        return 3, 0.0, ""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return 1, float(value), ""
    return 2, 0.0, str(value)


def _groups(
    records: Sequence[Mapping[str, Any]], by: tuple[str, ...]
) -> list[tuple[tuple[Any, ...], list[Mapping[str, Any]]]]:
    groups: dict[tuple[Any, ...], list[Mapping[str, Any]]] = {}
    for record in records:
        values = tuple(_hashable(_field(record, name)) for name in by)
        groups.setdefault(values, []).append(record)
    return sorted(
        groups.items(),
        key=lambda item: tuple(_order_key(name, value) for name, value in zip(by, item[0], strict=True)),
    )


def _hashable(value: Any) -> Any:
    if isinstance(value, list):
        return tuple(_hashable(v) for v in value)
    if isinstance(value, dict):
        return tuple(sorted((k, _hashable(v)) for k, v in value.items()))
    return value


def is_counted(record: Mapping[str, Any]) -> bool:
    """Whether an experiment counts in success rates (it was not ended by infrastructure trouble).

    Parameters
    ----------
    record
        One record of ``results.jsonl``.

    Returns
    -------
    bool
        False for the statuses ``"model_error"`` and ``"error"``.
    """
    return _field(record, "status") not in INFRA_STATUSES


def is_solved(record: Mapping[str, Any]) -> bool:
    """Whether an experiment solved its task.

    Parameters
    ----------
    record
        One record of ``results.jsonl``.

    Returns
    -------
    bool
        True for the status ``"solved"``.
    """
    return bool(_field(record, "status") == "solved")


def _rounds_to_success(record: Mapping[str, Any]) -> int:
    value = record.get("rounds_to_success")
    return int(value if value is not None else _field(record, "rounds"))


def _mean(values: Sequence[float]) -> float | None:
    return float(np.mean(np.asarray(values, dtype=np.float64))) if values else None


def summarize(records: Iterable[Mapping[str, Any]], by: Sequence[str] = GROUP) -> list[dict[str, Any]]:
    """One row of statistics per group of experiments.

    Parameters
    ----------
    records
        Records as :func:`read_records` returns them.
    by
        The fields to group by (default :data:`GROUP`); an empty sequence pools every record.

    Returns
    -------
    list of dict
        One row per group, sorted by the ``by`` fields (scenarios in the paper's order, then the
        others alphabetically; methods in the order use-api, code, predict; numbers ascending). Each
        row has the ``by`` fields and:

        - ``n``: experiments counted (status neither ``"model_error"`` nor ``"error"``);
        - ``n_infra``: experiments ended by infrastructure trouble, left out of the rates;
        - ``solved``, ``success_rate`` (``solved / n``, None when ``n == 0``), ``ci_low`` and
          ``ci_high`` (95 % Wilson interval);
        - ``mean_rounds_to_success`` and ``mean_calls_to_success``: over the solved experiments (the
          paper's way; every model call counts, the API selection included), None when none was;
        - ``mean_rounds``: rounds played, over the counted experiments;
        - one count per error category (:data:`CATEGORIES`), over every round of every experiment
          of the group (infrastructure ones included, where ``model_error`` rounds are);
        - ``prompt_tokens``, ``completion_tokens``: totals over every experiment;
        - ``cost``: total in USD over every experiment, None when the cost of any experiment that
          called the model is unknown (one that made no call, such as a harness error, cost nothing);
        - ``mean_wall_s``: mean wall time of the counted experiments, in seconds.

    Raises
    ------
    InvalidArgumentError
        If ``records`` or ``by`` has the wrong type.
    AudereError
        If a record lacks a field that is needed.
    """
    fields = _check_by(by)
    rows: list[dict[str, Any]] = []
    for values, group in _groups(_check_records(records), fields):
        counted = [r for r in group if is_counted(r)]
        solved = [r for r in counted if is_solved(r)]
        n = len(counted)
        low, high = wilson_interval(len(solved), n)
        row: dict[str, Any] = dict(zip(fields, values, strict=True))
        row.update(
            n=n,
            n_infra=len(group) - n,
            solved=len(solved),
            success_rate=len(solved) / n if n else None,
            ci_low=low,
            ci_high=high,
            mean_rounds_to_success=_mean([_rounds_to_success(r) for r in solved]),
            mean_calls_to_success=_mean(
                [
                    int(
                        r["calls_to_success"] if r.get("calls_to_success") is not None else _field(r, "calls")
                    )
                    for r in solved
                ]
            ),
            mean_rounds=_mean([int(_field(r, "rounds")) for r in counted]),
        )
        counts = dict.fromkeys(CATEGORIES, 0)
        for record in group:
            for category in _field(record, "categories"):
                if category in counts:
                    counts[category] += 1
        row.update(counts)
        # An experiment that made no model call has no price (SolveResult.cost is None): it cost nothing.
        costs = [_field(r, "cost") for r in group if int(_field(r, "calls")) > 0]
        row.update(
            prompt_tokens=sum(int(_field(r, "prompt_tokens")) for r in group),
            completion_tokens=sum(int(_field(r, "completion_tokens")) for r in group),
            cost=None if any(c is None for c in costs) else float(sum(costs)),
            mean_wall_s=_mean([float(_field(r, "wall_s")) for r in counted]),
        )
        rows.append(row)
    return rows


def success_at_k(
    records: Iterable[Mapping[str, Any]], by: Sequence[str] = GROUP, k_max: int | None = None
) -> list[dict[str, Any]]:
    """Success within k rounds, for k = 1 .. ``k_max``, per group.

    Parameters
    ----------
    records
        Records as :func:`read_records` returns them.
    by
        The fields to group by (default :data:`GROUP`).
    k_max
        The largest k; None takes the largest ``max_rounds`` of the records.

    Returns
    -------
    list of dict
        Rows of the ``by`` fields, ``k``, ``n`` (experiments counted, as in :func:`summarize`),
        ``solved`` (those solved within k rounds), ``success_rate`` (``solved / n``, None when
        ``n == 0``) and its 95 % Wilson interval ``ci_low``, ``ci_high``, sorted by group then k.
        Nondecreasing in k; at the largest ``max_rounds`` it equals the group's success rate. Empty
        when there are no records.

    Raises
    ------
    InvalidArgumentError
        If ``k_max`` is not an integer >= 1, or ``records`` or ``by`` has the wrong type.
    AudereError
        If a record lacks a field that is needed.
    """
    fields = _check_by(by)
    items = _check_records(records)
    if k_max is not None and (isinstance(k_max, bool) or not isinstance(k_max, int) or k_max < 1):
        raise InvalidArgumentError(f"k_max: expected an integer >= 1 or None, got {k_max!r}")
    if not items:
        return []
    top = k_max if k_max is not None else max(int(_field(r, "max_rounds")) for r in items)
    rows: list[dict[str, Any]] = []
    for values, group in _groups(items, fields):
        counted = [r for r in group if is_counted(r)]
        needed = np.array([_rounds_to_success(r) for r in counted if is_solved(r)], dtype=np.int64)
        n = len(counted)
        for k in range(1, top + 1):
            solved = int(np.count_nonzero(needed <= k))
            low, high = wilson_interval(solved, n)
            row: dict[str, Any] = dict(zip(fields, values, strict=True))
            row.update(
                k=k, n=n, solved=solved, success_rate=solved / n if n else None, ci_low=low, ci_high=high
            )
            rows.append(row)
    return rows


# --------------------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------------------


def _columns(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None) -> list[str]:
    if columns is not None:
        if isinstance(columns, str) or not all(isinstance(c, str) for c in columns):
            raise InvalidArgumentError(f"columns: expected a sequence of column names, got {columns!r}")
        return list(columns)
    names: dict[str, None] = {}
    for row in rows:
        names.update(dict.fromkeys(row))
    return list(names)


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)


def _cell(value: Any) -> str:
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float | np.floating):
        return "nan" if math.isnan(value) else f"{float(value):.4g}"
    if isinstance(value, list | tuple):
        return ", ".join(_cell(v) for v in value)
    return str(value)


def format_markdown(rows: Iterable[Mapping[str, Any]], columns: Sequence[str] | None = None) -> str:
    """A Markdown (GitHub pipe) table of rows.

    Parameters
    ----------
    rows
        Rows as :func:`summarize` or :func:`success_at_k` return them.
    columns
        The columns, in order; None takes every key of the rows, in order of first appearance.

    Returns
    -------
    str
        The table, ending with a newline: numeric columns right-aligned, floats to 4 significant
        digits, missing values and None as ``–``, ``|`` escaped. An empty string when there are no
        rows and no columns.

    Raises
    ------
    InvalidArgumentError
        If ``rows`` or ``columns`` has the wrong type.
    """
    items = _check_records(rows)
    names = _columns(items, columns)
    if not names:
        return ""
    numeric = [
        any(_is_number(row.get(c)) for row in items)
        and all(row.get(c) is None or _is_number(row.get(c)) for row in items)
        for c in names
    ]

    def line(cells: Iterable[str]) -> str:
        return "| " + " | ".join(cell.replace("|", "\\|").replace("\n", " ") for cell in cells) + " |"

    out = [line(names), "|" + "|".join("---:" if right else ":---" for right in numeric) + "|"]
    out += [line(_cell(row.get(c)) for c in names) for row in items]
    return "\n".join(out) + "\n"


def write_csv(rows: Iterable[Mapping[str, Any]], path: str | Path) -> Path:
    """Write rows to a CSV file (standard library :mod:`csv`, a header line first).

    Parameters
    ----------
    rows
        Rows as :func:`summarize` or :func:`success_at_k` return them.
    path
        The file to write; missing parent directories are made.

    Returns
    -------
    pathlib.Path
        ``path``. Columns are every key of the rows in order of first appearance; None is written as
        an empty cell, floats at full precision, lists joined with ``;``.

    Raises
    ------
    InvalidArgumentError
        If ``rows`` has the wrong type.
    """
    items = _check_records(rows)
    names = _columns(items, None)
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)

    def cell(value: Any) -> Any:
        if value is None:
            return ""
        if isinstance(value, list | tuple):
            return ";".join(str(v) for v in value)
        if isinstance(value, np.generic):
            return value.item()
        return value

    with target.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(names)
        for row in items:
            writer.writerow([cell(row.get(name)) for name in names])
    return target
