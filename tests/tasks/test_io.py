"""Task files: JSON and YAML round trips of every kind, hand-written files, the examples in docs/tasks.md."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from audere.tasks import (
    MazeTask,
    ReachAvoidTask,
    STLTask,
    TaskAdapter,
    TrackingTask,
    load_task,
    parse_task,
    save_task,
)

from .factories import ALL, KEY_DOOR, task

DATA = Path(__file__).parent / "data"
DOCS = Path(__file__).parents[2] / "docs" / "tasks.md"

KINDS = sorted(ALL)


@pytest.mark.parametrize("name", KINDS)
def test_json_round_trip(name: str) -> None:
    t = task(ALL[name])
    again = parse_task(t.to_json(), format="json")
    assert type(again) is type(t)
    assert again == t
    assert hash(again) == hash(t)
    assert again.model_dump(mode="json") == t.model_dump(mode="json")
    assert parse_task(t.to_json(indent=None), format="json") == t


@pytest.mark.parametrize("name", KINDS)
def test_yaml_round_trip(name: str) -> None:
    t = task(ALL[name])
    again = parse_task(t.to_yaml())
    assert again == t
    assert again.to_yaml() == t.to_yaml()


@pytest.mark.parametrize("suffix", [".json", ".yaml", ".yml"])
@pytest.mark.parametrize("name", KINDS)
def test_file_round_trip(tmp_path: Path, name: str, suffix: str) -> None:
    t = task(ALL[name])
    path = save_task(t, tmp_path / f"task{suffix}")
    assert load_task(path) == t
    assert load_task(str(path)) == t


def test_equality_sees_every_field() -> None:
    t = task(ALL["tracking"])
    ref = np.array(t.reference)
    ref[2, 1] += 1e-9
    other = task(ALL["tracking"], reference=ref.tolist())
    assert other != t
    assert task(ALL["tracking"]) == t
    assert t != "tracking"


def test_a_loaded_task_checks_like_the_original() -> None:
    t = task(KEY_DOOR)
    again = parse_task(t.to_yaml())
    states = np.array(
        [[1, 1], [1, 4], [1, 7], [1, 9], [4, 9], [7, 9], [9, 9], [9, 9], [9, 9], [9, 9], [9, 9]]
    )
    assert again.check({"states": states}) == t.check({"states": states})


EXPECTED_TYPES = {
    "reach_avoid.yaml": ReachAvoidTask,
    "tracking.yaml": TrackingTask,
    "maze.yaml": MazeTask,
    "stl.yaml": STLTask,
}


@pytest.mark.parametrize("filename", sorted(EXPECTED_TYPES))
def test_hand_written_yaml_files_load(filename: str) -> None:
    t = load_task(DATA / filename)
    assert isinstance(t, EXPECTED_TYPES[filename])
    assert t.name == f"hand-written/{filename.removesuffix('.yaml')}"
    assert parse_task(t.to_yaml()) == t


def test_hand_written_files_hold_what_they_say() -> None:
    ra = load_task(DATA / "reach_avoid.yaml")
    assert isinstance(ra, ReachAvoidTask)
    assert [o.kind for o in ra.obstacles] == ["circle", "square", "rectangle", "polygon"]
    assert (ra.margin, ra.goal, ra.goal_tolerance) == (0.1, (9.0, 9.0), 0.1)
    tr = load_task(DATA / "tracking.yaml")
    assert isinstance(tr, TrackingTask)
    assert tr.reference.shape == (6, 2)
    assert tr.u_max == (0.3, 0.5)
    maze = load_task(DATA / "maze.yaml")
    assert isinstance(maze, MazeTask)
    assert maze.door_path((0, 0), (1, 1)) == [(0, 0), (0, 1), (1, 1)]
    stl = load_task(DATA / "stl.yaml")
    assert isinstance(stl, STLTask)
    assert stl == task(KEY_DOOR, name="hand-written/stl")


def _doc_examples() -> list[str]:
    text = DOCS.read_text(encoding="utf-8")
    return re.findall(r"```yaml\n(.*?)```", text, flags=re.DOTALL)


def test_the_documented_yaml_examples_are_valid_tasks() -> None:
    examples = _doc_examples()
    kinds: list[Any] = [type(parse_task(example)) for example in examples]
    assert {ReachAvoidTask, TrackingTask, MazeTask, STLTask} <= set(kinds)


def test_task_adapter_validates_any_kind() -> None:
    for name in KINDS:
        t = task(ALL[name])
        assert TaskAdapter.validate_python(t.model_dump()) == t


def test_model_copy_validates_and_rebuilds_derived_values() -> None:
    t = task(ALL["reach_avoid_path"])
    assert t.world().obstacles[0].radius == 1.0  # cache the checking world
    wider = t.model_copy(update={"margin": 0.5})
    assert wider.world().obstacles[0].radius == 1.5
    assert not wider.check(np.array([[1.0, 1.0], [1.0, 6.2], [9.0, 6.2], [9.0, 9.0]])).success
    with pytest.raises(ValueError, match=r"x0 \(start\) \(5\.000, 5\.000\) lies inside obstacle 0"):
        t.model_copy(update={"x0": (5.0, 5.0)})
    assert t.model_copy() == t
