"""The scenario registry: names, what each exercises, and the seeded :func:`make`."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from audere.errors import InvalidArgumentError
from audere.scenarios._base import AnyTask, Generated, Generator
from audere.scenarios._control import arm_reach, pendulum_swingup, reach_unicycle
from audere.scenarios._planning import plan_easy, plan_hard
from audere.scenarios._stl import plan_stl
from audere.scenarios._tracking import track_car, track_double, track_lin

__all__ = ["ScenarioInfo", "generate", "list_scenarios", "make"]

ApiName = Literal["astar", "rrt", "cem", "grad", "milp", "pid", "lqr", "mpc"]
"""The planning and control APIs a scenario can name as natural choices."""


class ScenarioInfo(BaseModel):
    """What a scenario is: its name, where it comes from, what it exercises."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field(description="Name for make(), e.g. 'plan-easy'.")
    paper_label: str | None = Field(description="Label in the paper (e.g. 'Plan-easy'), or null for ours.")
    kind: Literal["tracking", "reach_avoid", "maze", "stl"] = Field(description="Kind of the task generated.")
    dynamics: str | None = Field(description="Dynamics model name, or null for a geometric path task.")
    summary: str = Field(description="One line: what the robot must do.")
    capabilities: tuple[str, ...] = Field(
        description="What the scenario exercises, e.g. ('tracking', 'nonlinear')."
    )
    natural_apis: tuple[ApiName, ...] = Field(description="The APIs a planning expert would reach for first.")


_SCENARIOS: dict[str, tuple[ScenarioInfo, Generator]] = {
    info.name: (info, gen)
    for info, gen in (
        (
            ScenarioInfo(
                name="track-lin",
                paper_label="Track-lin",
                kind="tracking",
                dynamics="single_integrator",
                summary="Follow a flat or curved 21-point reference with a speed-bounded single integrator.",
                capabilities=("tracking", "linear"),
                natural_apis=("pid", "lqr", "mpc"),
            ),
            track_lin,
        ),
        (
            ScenarioInfo(
                name="track-car",
                paper_label="Track-car",
                kind="tracking",
                dynamics="unicycle",
                summary="Follow a 21-point reference with a unicycle (car with speed as a state) from rest.",
                capabilities=("tracking", "nonlinear"),
                natural_apis=("mpc", "cem", "grad"),
            ),
            track_car,
        ),
        (
            ScenarioInfo(
                name="plan-easy",
                paper_label="Plan-easy",
                kind="reach_avoid",
                dynamics=None,
                summary="Find a path across the map between 12 well-spaced circles and squares.",
                capabilities=("planning", "collision avoidance"),
                natural_apis=("rrt", "astar"),
            ),
            plan_easy,
        ),
        (
            ScenarioInfo(
                name="plan-hard",
                paper_label="Plan-hard",
                kind="maze",
                dynamics=None,
                summary="Find a path through a 3x3 maze of walls with random doors and 36 small obstacles.",
                capabilities=("planning", "collision avoidance", "maze"),
                natural_apis=("astar", "rrt"),
            ),
            plan_hard,
        ),
        (
            ScenarioInfo(
                name="plan-stl",
                paper_label="Plan-STL",
                kind="stl",
                dynamics="single_integrator",
                summary="Pick up the key before the door, avoid two walls, reach the goal in a time window.",
                capabilities=("stl", "temporal logic", "planning"),
                natural_apis=("milp",),
            ),
            plan_stl,
        ),
        (
            ScenarioInfo(
                name="track-double",
                paper_label=None,
                kind="tracking",
                dynamics="double_integrator",
                summary="Follow a 21-state reference with an acceleration-bounded double integrator.",
                capabilities=("tracking", "linear", "second order"),
                natural_apis=("lqr", "mpc", "pid"),
            ),
            track_double,
        ),
        (
            ScenarioInfo(
                name="pendulum-swingup",
                paper_label=None,
                kind="reach_avoid",
                dynamics="pendulum",
                summary="Swing a pendulum up and hold it upright with a torque too weak to lift it directly.",
                capabilities=("control", "nonlinear", "input saturation"),
                natural_apis=("mpc", "cem", "grad", "lqr"),
            ),
            pendulum_swingup,
        ),
        (
            ScenarioInfo(
                name="arm-reach",
                paper_label=None,
                kind="reach_avoid",
                dynamics="two_link_arm",
                summary="Bring a two-link arm's end effector to a point while it avoids two circles.",
                capabilities=("reaching", "nonlinear", "collision avoidance"),
                natural_apis=("mpc", "grad", "cem"),
            ),
            arm_reach,
        ),
        (
            ScenarioInfo(
                name="reach-unicycle",
                paper_label=None,
                kind="reach_avoid",
                dynamics="unicycle",
                summary="Drive a unicycle from rest to a point around circles that block the straight line.",
                capabilities=("planning", "nonlinear", "collision avoidance"),
                natural_apis=("mpc", "cem", "grad"),
            ),
            reach_unicycle,
        ),
    )
}


def list_scenarios() -> list[ScenarioInfo]:
    """Every scenario: the paper's five first (in the paper's order), then ours.

    Returns
    -------
    list of ScenarioInfo
        Name, paper label, task kind, dynamics, summary, capabilities and natural APIs of each.
    """
    return [info for info, _ in _SCENARIOS.values()]


def _check_seed(seed: int) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise InvalidArgumentError(
            f"seed must be a non-negative integer, got {type(seed).__name__}: {seed!r}"
        )
    if seed < 0:
        raise InvalidArgumentError(f"seed must be a non-negative integer, got {seed}")
    return int(seed)


def generate(name: str, seed: int) -> Generated:
    """Generate a task of scenario ``name`` together with its witness builder (see :func:`make`).

    Parameters
    ----------
    name
        Scenario name, one of ``[s.name for s in list_scenarios()]``.
    seed
        Non-negative integer seeding the scenario's random stream.

    Returns
    -------
    Generated
        The task and a builder of a solution the task's checker accepts (``None`` for
        pendulum-swingup).

    Raises
    ------
    InvalidArgumentError
        For an unknown ``name`` (the message lists the known names) or a bad ``seed``.
    """
    if not isinstance(name, str) or name not in _SCENARIOS:
        known = ", ".join(_SCENARIOS)
        raise InvalidArgumentError(f"name must be one of the scenarios {known}; got {name!r}")
    s = _check_seed(seed)
    _, generator = _SCENARIOS[name]
    return generator(np.random.default_rng(s), f"{name}/seed={s}")


def make(name: str, seed: int) -> AnyTask:
    """Generate the task of scenario ``name`` for ``seed``.

    The same name and seed always give the same task (equal JSON); the random draws come from
    ``numpy.random.default_rng(seed)`` alone. Every task is valid and solvable by construction
    (see ``docs/scenarios.md`` for how each scenario proves it).

    Parameters
    ----------
    name
        Scenario name, e.g. ``"plan-easy"``; :func:`list_scenarios` lists them all.
    seed
        Non-negative integer seeding the scenario's random stream.

    Returns
    -------
    TrackingTask | ReachAvoidTask | MazeTask | STLTask
        The task, named ``f"{name}/seed={seed}"``.

    Raises
    ------
    InvalidArgumentError
        For an unknown ``name`` (the message lists the known names) or a seed that is not a
        non-negative integer.
    """
    return generate(name, seed).task
