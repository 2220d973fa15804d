"""Plots of tasks, solutions and check reports.

>>> from audere.viz import plot
>>> fig = plot(task, solution, report)   # doctest: +SKIP
>>> fig.savefig("task.png")              # doctest: +SKIP

matplotlib is imported only when :func:`plot` is called, so ``import audere.viz`` stays cheap.
"""

from audere.viz._plot import plot

__all__ = ["plot"]
