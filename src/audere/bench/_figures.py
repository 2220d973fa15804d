"""The benchmark's figures (the paper's Figs. 4-6 and the ablations), drawn with matplotlib's object API.

Every function returns a :class:`matplotlib.figure.Figure` made without pyplot (no global state, safe
in tests and servers); :func:`save_figure` writes it as PNG and SVG. Success rates always carry their
95 % Wilson interval, and exclude experiments ended by infrastructure trouble (see
:mod:`audere.bench._metrics`).

A *series* (one colour, one legend entry) is a method, refined by whichever of model, temperature
and API provision take more than one value in the rows drawn, so that no two different settings are
ever pooled into one bar by accident; what is pooled (usually the scenarios, in the ablations) is
said in the title.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from audere.bench._metrics import (
    CATEGORIES,
    _order_key,
    summarize,
    wilson_interval,
)
from audere.errors import InvalidArgumentError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "figure_errors",
    "figure_models",
    "figure_provision",
    "figure_success_and_rounds",
    "figure_success_at_k",
    "figure_temperature",
    "save_figure",
]

_SETTINGS: Final = ("model", "temperature", "provision")
_METHOD_COLOURS: Final = {"use-api": "#1f77b4", "code": "#ff7f0e", "predict": "#2ca02c"}
_PALETTE: Final = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)
_CATEGORY_COLOURS: Final = {
    "parsing": "#9467bd",
    "syntax": "#e377c2",
    "runtime": "#d62728",
    "timeout": "#ff7f0e",
    "task_failure": "#8c564b",
    "model_error": "#7f7f7f",
    "sandbox_error": "#bcbd22",
}
_CI: Final = "95 % Wilson CI"
_MAX_BANDS: Final = 4


# --------------------------------------------------------------------------------------------------
# Rows: checking, pooling, series
# --------------------------------------------------------------------------------------------------


def _rows(rows: object, needed: Sequence[str], argument: str = "rows") -> list[Mapping[str, Any]]:
    if isinstance(rows, Mapping | str | bytes) or not isinstance(rows, Iterable):
        raise InvalidArgumentError(f"{argument}: expected a sequence of row dicts, got {rows!r}")
    items = list(rows)
    if not items:
        raise InvalidArgumentError(f"{argument}: expected at least one row, got none")
    for index, row in enumerate(items):
        if not isinstance(row, Mapping):
            raise InvalidArgumentError(f"{argument}[{index}]: expected a row dict, got {row!r}")
        missing = [name for name in needed if name not in row]
        if missing:
            raise InvalidArgumentError(
                f"{argument}[{index}]: expected the columns {list(needed)}, missing {missing} "
                f"(got {sorted(row)})"
            )
    return items


def _distinct(rows: Iterable[Mapping[str, Any]], field: str) -> list[Any]:
    values = {row.get(field) for row in rows}
    return sorted(values, key=lambda value: _order_key(field, value))


def _varying(rows: Sequence[Mapping[str, Any]], fields: Iterable[str]) -> list[str]:
    return [f for f in fields if any(f in row for row in rows) and len(_distinct(rows, f)) > 1]


def _pool(rows: Sequence[Mapping[str, Any]], keys: Sequence[str]) -> list[dict[str, Any]]:
    """Merge the rows that agree on ``keys``: counts add up, rates and intervals are recomputed."""
    groups: dict[tuple[Any, ...], list[Mapping[str, Any]]] = {}
    for row in rows:
        groups.setdefault(tuple(row.get(k) for k in keys), []).append(row)
    pooled: list[dict[str, Any]] = []
    for values, group in groups.items():
        n = sum(int(r["n"]) for r in group)
        solved = sum(int(r["solved"]) for r in group)
        low, high = wilson_interval(solved, n)
        out: dict[str, Any] = dict(zip(keys, values, strict=True))
        out.update(n=n, solved=solved, success_rate=solved / n if n else None, ci_low=low, ci_high=high)
        weighted = [
            (float(r["mean_rounds_to_success"]), int(r["solved"]))
            for r in group
            if r.get("mean_rounds_to_success") is not None and int(r["solved"]) > 0
        ]
        total = sum(w for _, w in weighted)
        out["mean_rounds_to_success"] = sum(m * w for m, w in weighted) / total if total else None
        for category in CATEGORIES:
            out[category] = sum(int(r.get(category) or 0) for r in group)
        pooled.append(out)
    pooled.sort(key=lambda r: tuple(_order_key(k, r[k]) for k in keys))
    return pooled


def _label(field: str, value: Any) -> str:
    if field == "temperature" and isinstance(value, int | float):
        return f"T={value:g}"
    if field == "provision":
        return f"APIs {value}"
    return str(value)


def _series_label(row: Mapping[str, Any], fields: Sequence[str]) -> str:
    return " · ".join(_label(f, row.get(f)) for f in fields)


def _series(
    rows: Sequence[Mapping[str, Any]], fields: Sequence[str]
) -> list[tuple[tuple[Any, ...], str, str]]:
    """The series of ``rows``: (values of ``fields``, legend label, colour), in order."""
    fields = list(fields)
    keys = sorted(
        {tuple(row.get(f) for f in fields) for row in rows},
        key=lambda values: tuple(_order_key(f, v) for f, v in zip(fields, values, strict=True)),
    )
    by_method = fields[:1] == ["method"] and all(values[0] in _METHOD_COLOURS for values in keys)
    out = []
    for index, values in enumerate(keys):
        row = dict(zip(fields, values, strict=True))
        if by_method:
            # One hue per method, a darker-to-lighter shade per setting within it.
            variants = [v for v in keys if v[0] == values[0]]
            colour = _shade(_METHOD_COLOURS[str(values[0])], variants.index(values), len(variants))
        else:
            colour = _PALETTE[index % len(_PALETTE)]
        out.append((values, _series_label(row, fields), colour))
    return out


def _linestyle(series: Sequence[tuple[tuple[Any, ...], str, str]], values: tuple[Any, ...]) -> str:
    """A line style per setting within a method, so that shades of one hue stay apart."""
    variants = [v for v, _, _ in series if v[:1] == values[:1]]
    return ("-", "--", ":", "-.")[variants.index(values) % 4]


def _shade(colour: str, index: int, count: int) -> str:
    """``colour`` darkened (first) to lightened (last), ``index`` of ``count`` shades."""
    from matplotlib.colors import to_hex, to_rgb

    if count <= 1:
        return colour
    t = -0.35 + 0.8 * index / (count - 1)
    rgb = np.array(to_rgb(colour))
    mixed = rgb * (1.0 + t) if t < 0 else rgb + (1.0 - rgb) * t
    return str(to_hex(tuple(np.clip(mixed, 0.0, 1.0))))


def _n_text(rows: Iterable[Mapping[str, Any]], what: str) -> str:
    counts = sorted({int(r["n"]) for r in rows})
    if len(counts) == 1:
        return f"n = {counts[0]} experiments per {what}"
    return f"n = {counts[0]}-{counts[-1]} experiments per {what}"


def _figure(width: float, height: float) -> Figure:
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def _grid(fig: Figure, panels: int, max_columns: int = 5) -> list[Axes]:
    columns = min(panels, max_columns)
    rows = -(-panels // columns)
    axes = fig.subplots(rows, columns, squeeze=False, sharey=True)
    flat = list(axes.ravel())
    for ax in flat[panels:]:
        ax.set_visible(False)
    return flat[:panels]


def _grouped_bars(
    ax: Axes,
    rows: Sequence[Mapping[str, Any]],
    x_field: str,
    series_fields: Sequence[str],
    value: str,
    *,
    error_bars: bool,
) -> None:
    """Bars of ``value`` for each x value (a group) and each series (a bar within the group)."""
    xs = _distinct(rows, x_field)
    series = _series(rows, series_fields)
    width = 0.8 / max(1, len(series))
    index = {(row.get(x_field), tuple(row.get(f) for f in series_fields)): row for row in rows}
    for s, (values, label, colour) in enumerate(series):
        positions, heights, low, high = [], [], [], []
        for i, x in enumerate(xs):
            row = index.get((x, values))
            if row is None or row.get(value) is None:
                continue
            positions.append(i - 0.4 + width * (s + 0.5))
            heights.append(float(row[value]))
            if error_bars:
                low.append(max(0.0, float(row[value]) - float(row["ci_low"])))
                high.append(max(0.0, float(row["ci_high"]) - float(row[value])))
        yerr = np.array([low, high]) if error_bars and positions else None
        ax.bar(
            positions,
            heights,
            width=width * 0.95,
            color=colour,
            label=label,
            yerr=yerr,
            capsize=3 if error_bars else 0,
            error_kw={"elinewidth": 1.0, "ecolor": "#222222"},
        )
    labels = [f"{x:g}" if isinstance(x, float) else str(x) for x in xs]
    long = max((len(label) for label in labels), default=0) > 10 and len(labels) > 4
    ax.set_xticks(range(len(xs)), labels, rotation=25 if long else 0, ha="right" if long else "center")
    ax.set_xlim(-0.6, len(xs) - 0.4)
    ax.grid(axis="y", alpha=0.3)
    ax.set_axisbelow(True)


def _columns_for(width_in: float, labels: Sequence[str]) -> int:
    """As many legend columns as fit a width (about 6 pt per character, 40 pt per handle)."""
    entry_pt = 6.0 * max((len(label) for label in labels), default=1) + 40.0
    return max(1, min(len(labels), int(width_in * 72.0 // entry_pt)))


def _legend_height(width_in: float, labels: Sequence[str]) -> float:
    """The height in inches a legend below the axes takes, so that figures grow to make room for it."""
    rows = -(-len(labels) // _columns_for(width_in, labels)) if labels else 0
    return 0.25 * rows + 0.5


def _legend_columns(fig: Figure, labels: Sequence[str]) -> int:
    return _columns_for(float(fig.get_figwidth()), labels)


def _legend_below(fig: Figure, ax: Axes, title: str | None = None) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(
            handles, labels, loc="outside lower center", ncols=_legend_columns(fig, labels), title=title
        )


# --------------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------------


def figure_success_and_rounds(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """The paper's Fig. 4: success rate and mean rounds to success, per scenario and method.

    Parameters
    ----------
    rows
        Rows of :func:`audere.bench._metrics.summarize` (with at least ``scenario``, ``method``,
        ``n``, ``solved``, ``mean_rounds_to_success``); rows that differ only in fields other than
        scenario, method, model, temperature and provision are pooled.

    Returns
    -------
    matplotlib.figure.Figure
        Left panel: success rate with 95 % Wilson error bars; right panel: mean rounds to success
        (over the solved experiments). One group of bars per scenario, one bar per series (method,
        refined by model, temperature and provision where they vary).

    Raises
    ------
    InvalidArgumentError
        If there are no rows or a row lacks a needed column.
    """
    items = _rows(rows, ("scenario", "method", "n", "solved", "mean_rounds_to_success"))
    series_fields = ["method", *_varying(items, _SETTINGS)]
    pooled = _pool(items, ["scenario", *series_fields])
    scenarios = _distinct(pooled, "scenario")
    width = max(9.0, 2.2 * len(scenarios) + 3.0)
    labels = [label for _, label, _ in _series(pooled, series_fields)]
    fig = _figure(width, 4.2 + _legend_height(width, labels))
    left, right = fig.subplots(1, 2)
    _grouped_bars(left, pooled, "scenario", series_fields, "success_rate", error_bars=True)
    left.set_ylim(0.0, 1.05)
    left.set_ylabel("success rate (fraction of experiments)")
    left.set_xlabel("scenario")
    left.set_title(f"Success rate ({_CI})")
    _grouped_bars(right, pooled, "scenario", series_fields, "mean_rounds_to_success", error_bars=False)
    right.set_ylim(bottom=0.0)
    right.set_ylabel("mean rounds to success (rounds)")
    right.set_xlabel("scenario")
    right.set_title("Rounds to success (mean over solved experiments)")
    _legend_below(fig, left)
    fig.suptitle(f"Success rate and rounds to success per scenario\n({_n_text(pooled, 'bar')})")
    return fig


def figure_success_at_k(sak_rows: Sequence[Mapping[str, Any]]) -> Figure:
    """The paper's Fig. 5: success within k rounds against k, one panel per scenario.

    Parameters
    ----------
    sak_rows
        Rows of :func:`audere.bench._metrics.success_at_k` (with at least ``scenario``, ``method``,
        ``k``, ``n`` and ``solved``).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per scenario (up to five per row), one line per series (method, refined by model,
        temperature and provision where they vary), its 95 % Wilson interval shaded (up to four
        series; with more the bands would hide each other, and the title says they are not drawn).

    Raises
    ------
    InvalidArgumentError
        If there are no rows or a row lacks a needed column.
    """
    items = _rows(sak_rows, ("scenario", "method", "k", "n", "solved"), argument="sak_rows")
    series_fields = ["method", *_varying(items, _SETTINGS)]
    pooled = _pool(items, ["scenario", *series_fields, "k"])
    scenarios = _distinct(pooled, "scenario")
    columns = min(len(scenarios), 5)
    lines = -(-len(scenarios) // columns)
    series = _series(pooled, series_fields)
    width = max(6.0, 3.0 * columns + 1.0)
    fig = _figure(width, 3.2 * lines + 0.8 + _legend_height(width, [label for _, label, _ in series]))
    axes = _grid(fig, len(scenarios))
    bands = len(series) <= _MAX_BANDS
    k_values = _distinct(pooled, "k")
    for ax, scenario in zip(axes, scenarios, strict=True):
        for values, label, colour in series:
            points = [
                r
                for r in pooled
                if r["scenario"] == scenario
                and tuple(r.get(f) for f in series_fields) == values
                and r["success_rate"] is not None
            ]
            if not points:
                continue
            k = np.array([float(r["k"]) for r in points])
            rate = np.array([float(r["success_rate"]) for r in points])
            if bands:
                ax.fill_between(
                    k,
                    [float(r["ci_low"]) for r in points],
                    [float(r["ci_high"]) for r in points],
                    color=colour,
                    alpha=0.12,
                    linewidth=0,
                )
            style = _linestyle(series, values)
            ax.plot(k, rate, marker="o", markersize=4, color=colour, linestyle=style, label=label)
        ax.set_title(str(scenario))
        ax.set_ylim(0.0, 1.05)
        ax.set_xticks([int(k) for k in k_values])
        ax.set_xlabel("rounds allowed k")
        ax.grid(alpha=0.3)
    for ax in axes[::columns]:
        ax.set_ylabel("success rate within k rounds\n(fraction of experiments)")
    _legend_below(fig, axes[0])
    shading = f"shaded: {_CI}" if bands else f"{_CI} not drawn for more than {_MAX_BANDS} series"
    fig.suptitle(f"Success within k rounds, one panel per scenario\n({shading}; {_n_text(pooled, 'point')})")
    return fig


def figure_errors(records: Sequence[Mapping[str, Any]]) -> Figure:
    """The paper's Fig. 6: how failed rounds failed, per scenario and method, as stacked counts.

    Parameters
    ----------
    records
        Records as :func:`audere.bench._metrics.read_records` returns them.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per scenario (up to five per row); in each, one horizontal bar per series (method,
        refined by model, temperature and provision where they vary; the same rows in every panel)
        stacking the number of rounds that ended in each error category (every round of every
        experiment, infrastructure ones included).

    Raises
    ------
    InvalidArgumentError
        If there are no records.
    AudereError
        If a record lacks a needed field.
    """
    from matplotlib.patches import Patch

    items = _rows(records, ("scenario", "method", "categories"), argument="records")
    series_fields = ["method", *_varying(items, _SETTINGS)]
    rows = summarize(items, by=("scenario", *series_fields))
    scenarios = _distinct(rows, "scenario")
    series = _series(rows, series_fields)
    present = [c for c in CATEGORIES if any(row[c] for row in rows)]
    columns = min(len(scenarios), 5)
    lines = -(-len(scenarios) // columns)
    label_width = max(len(label) for _, label, _ in series)
    width = max(7.0, 2.6 * columns + 0.09 * label_width + 1.0)
    height = lines * (0.32 * len(series) + 1.4) + 0.8
    fig = _figure(width, height + _legend_height(width, [c.replace("_", " ") for c in present]))
    axes = _grid(fig, len(scenarios))
    positions = np.arange(len(series))
    for ax, scenario in zip(axes, scenarios, strict=True):
        cells = {tuple(r.get(f) for f in series_fields): r for r in rows if r["scenario"] == scenario}
        left = np.zeros(len(series))
        for category in present:
            counts = np.array(
                [float(cells[values][category]) if values in cells else 0.0 for values, _, _ in series]
            )
            ax.barh(positions, counts, left=left, color=_CATEGORY_COLOURS[category], height=0.7)
            left += counts
        if not left.any():
            ax.text(0.5, 0.5, "no failed rounds", transform=ax.transAxes, ha="center", va="center")
        ax.set_yticks(positions, [label for _, label, _ in series])
        ax.set_ylim(len(series) - 0.5, -0.5)  # the first series on top
        ax.set_title(str(scenario))
        ax.set_xlabel("failed rounds (count)")
        ax.grid(axis="x", alpha=0.3)
        ax.set_axisbelow(True)
    handles = [Patch(color=_CATEGORY_COLOURS[c], label=c.replace("_", " ")) for c in present]
    if handles:
        labels = [str(h.get_label()) for h in handles]
        fig.legend(
            handles=handles, loc="outside lower center", ncols=_legend_columns(fig, labels), title="error"
        )
    fig.suptitle(
        f"Rounds that failed, by error category\n(one panel per scenario, one bar per "
        f"{' · '.join(series_fields)}; summed over seeds)"
    )
    return fig


def _pooled_over_scenarios(items: Sequence[Mapping[str, Any]]) -> str:
    scenarios = [s for s in _distinct(items, "scenario") if s is not None]
    if len(scenarios) > 1:
        return f"pooled over {len(scenarios)} scenarios"
    if scenarios:
        return str(scenarios[0])
    return "all experiments"


def _ablation_bars(
    rows: Sequence[Mapping[str, Any]], variable: str, title: str, xlabel: str
) -> Figure | None:
    items = _rows(rows, ("method", "n", "solved"))
    if len(_distinct(items, variable)) < 2:
        return None
    series_fields = ["method", *_varying(items, [f for f in _SETTINGS if f != variable])]
    pooled = _pool(items, [variable, *series_fields])
    xs = _distinct(pooled, variable)
    fig = _figure(max(6.5, 1.6 * len(xs) * max(1, len(_series(pooled, series_fields))) / 2 + 2.5), 4.6)
    ax = fig.subplots()
    _grouped_bars(ax, pooled, variable, series_fields, "success_rate", error_bars=True)
    ax.set_ylim(0.0, 1.05)
    ax.set_ylabel("success rate (fraction of experiments)")
    ax.set_xlabel(xlabel)
    ax.set_title(f"{title}\n({_pooled_over_scenarios(items)}; {_CI}; {_n_text(pooled, 'bar')})")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), title=" · ".join(series_fields))
    return fig


def figure_temperature(rows: Sequence[Mapping[str, Any]]) -> Figure | None:
    """Success rate against the sampling temperature, one line per series, pooled over scenarios.

    Parameters
    ----------
    rows
        Rows of :func:`audere.bench._metrics.summarize` (with ``temperature``, ``method``, ``n`` and
        ``solved``).

    Returns
    -------
    matplotlib.figure.Figure or None
        The figure (95 % Wilson error bars), or None when the rows hold fewer than two temperatures.

    Raises
    ------
    InvalidArgumentError
        If there are no rows or a row lacks a needed column.
    """
    items = _rows(rows, ("method", "n", "solved"))
    temperatures = [t for t in _distinct(items, "temperature") if t is not None]
    if len(temperatures) < 2:
        return None
    series_fields = ["method", *_varying(items, ("model", "provision"))]
    pooled = _pool(items, ["temperature", *series_fields])
    series = _series(pooled, series_fields)
    span = float(max(temperatures)) - float(min(temperatures))
    dodge = 0.012 * span if span > 0 else 0.0
    fig = _figure(7.5, 4.6)
    ax = fig.subplots()
    for index, (values, label, colour) in enumerate(series):
        points = [
            r
            for r in pooled
            if tuple(r.get(f) for f in series_fields) == values
            and r["success_rate"] is not None
            and r["temperature"] is not None
        ]
        if not points:
            continue
        offset = (index - (len(series) - 1) / 2) * dodge
        x = np.array([float(r["temperature"]) for r in points]) + offset
        rate = np.array([float(r["success_rate"]) for r in points])
        yerr = np.array(
            [
                [max(0.0, float(r["success_rate"]) - float(r["ci_low"])) for r in points],
                [max(0.0, float(r["ci_high"]) - float(r["success_rate"])) for r in points],
            ]
        )
        style = _linestyle(series, values)
        ax.errorbar(x, rate, yerr=yerr, marker="o", capsize=3, color=colour, linestyle=style, label=label)
    ax.set_xticks([float(t) for t in temperatures])
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("sampling temperature (unitless)")
    ax.set_ylabel("success rate (fraction of experiments)")
    ax.set_title(
        f"Success rate vs sampling temperature\n"
        f"({_pooled_over_scenarios(items)}; {_CI}; {_n_text(pooled, 'point')})"
    )
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), title=" · ".join(series_fields))
    return fig


def figure_models(rows: Sequence[Mapping[str, Any]]) -> Figure | None:
    """Success rate per model, one bar per series, pooled over scenarios.

    Parameters
    ----------
    rows
        Rows of :func:`audere.bench._metrics.summarize` (with ``model``, ``method``, ``n`` and
        ``solved``).

    Returns
    -------
    matplotlib.figure.Figure or None
        The figure (95 % Wilson error bars), or None when the rows hold fewer than two models.

    Raises
    ------
    InvalidArgumentError
        If there are no rows or a row lacks a needed column.
    """
    return _ablation_bars(rows, "model", "Success rate per model", "model")


def figure_provision(rows: Sequence[Mapping[str, Any]]) -> Figure | None:
    """Success rate per API provision (APIs on demand or all up front), pooled over scenarios.

    Parameters
    ----------
    rows
        Rows of :func:`audere.bench._metrics.summarize` (with ``provision``, ``method``, ``n`` and
        ``solved``).

    Returns
    -------
    matplotlib.figure.Figure or None
        The figure (95 % Wilson error bars), or None when the rows hold fewer than two provisions.

    Raises
    ------
    InvalidArgumentError
        If there are no rows or a row lacks a needed column.
    """
    return _ablation_bars(rows, "provision", "Success rate per API provision", "API provision")


def save_figure(fig: Figure, path_without_suffix: str | Path) -> list[Path]:
    """Write a figure as PNG (150 dpi) and SVG.

    Parameters
    ----------
    fig
        The figure.
    path_without_suffix
        The path without its suffix: ``figures/errors`` writes ``figures/errors.png`` and
        ``figures/errors.svg``. Missing parent directories are made.

    Returns
    -------
    list of pathlib.Path
        The PNG and the SVG file.

    Raises
    ------
    InvalidArgumentError
        If ``fig`` is not a matplotlib figure.
    """
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise InvalidArgumentError(f"fig: expected a matplotlib Figure, got {type(fig).__name__}")
    base = Path(path_without_suffix)
    base.parent.mkdir(parents=True, exist_ok=True)
    png = base.with_name(base.name + ".png")
    svg = base.with_name(base.name + ".svg")
    fig.savefig(png, format="png", dpi=150)
    fig.savefig(svg, format="svg", metadata={"Date": None})
    return [png, svg]
