"""Run a small benchmark grid offline, report it, and load the results for your own analysis.

Run it with ``python examples/small_benchmark.py`` (about a minute). The same as
``audere bench run --scenarios track-lin,plan-easy --methods use-api,code,predict --seeds 5``
followed by ``audere bench report``.
"""

from __future__ import annotations

from pathlib import Path

from audere.bench import make_grid, read_records, run_grid, summarize, write_report


def main() -> None:
    out = Path("small-benchmark")
    grid = make_grid(
        scenarios=["track-lin", "plan-easy"], seeds=range(5), methods=["use-api", "code", "predict"]
    )
    summary = run_grid(grid, out, concurrency=2)
    print(f"{summary.ran} experiments run, {summary.skipped} already done, {summary.solved} solved")
    for row in summarize(read_records(out)):
        print(f"  {row['scenario']:10} {row['method']:8} {row['solved']}/{row['n']} solved")
    report = write_report(out)
    print(f"wrote {report.summary_md} and {len(report.figures)} figure files")


if __name__ == "__main__":
    main()
