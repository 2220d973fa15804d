"""Tasks: typed problem descriptions, their natural-language rendering, and their checkers.

Build a task directly, load it from a file, or generate one with :mod:`audere.scenarios`::

    from audere.tasks import load_task
    task = load_task("my_task.yaml")
    print(task.describe())
    report = task.check(solution)
"""

from audere.tasks._io import load_task, parse_task, save_task
from audere.tasks._models import (
    Door,
    MazeTask,
    ReachAvoidTask,
    Region,
    STLTask,
    Task,
    TaskAdapter,
    TrackingTask,
)
from audere.tasks._report import CheckReport, ClauseResult, Violation, ViolationKind
from audere.tasks._solution import Solution, SolutionLike

__all__ = [
    "CheckReport",
    "ClauseResult",
    "Door",
    "MazeTask",
    "ReachAvoidTask",
    "Region",
    "STLTask",
    "Solution",
    "SolutionLike",
    "Task",
    "TaskAdapter",
    "TrackingTask",
    "Violation",
    "ViolationKind",
    "load_task",
    "parse_task",
    "save_task",
]
