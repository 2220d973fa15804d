"""The executor's interface with benign code: what the code sees, what comes back, argument errors.

Hostile code is the matrix's business (``test_matrix.py``, through separate host processes); the code
here is harmless, so the executor lives in the test process.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere import scenarios  # noqa: E402 - after the platform mark on purpose
from audere.agent.sandbox import (  # noqa: E402
    Execution,
    ExecutionStatus,
    Executor,
    FakeExecutor,
    Limits,
    SandboxExecutor,
    _harden,
)
from audere.errors import AudereError, InvalidArgumentError  # noqa: E402

PRELOAD = ("numpy", "audere.apis", "audere.planners", "audere.tasks", "audere.world")


@pytest.fixture(scope="module")
def executor() -> Iterator[SandboxExecutor]:
    with SandboxExecutor(preload=PRELOAD) as sandbox:
        yield sandbox


def test_inputs_arrive_as_values(executor: SandboxExecutor) -> None:
    code = "import numpy as np\nresult = {'scaled': np.asarray(xs) * k, 'n': [len(names)]}"
    execution = executor.run(code, inputs={"xs": np.arange(4.0), "k": 2.5, "names": ["a", "b"]})
    assert execution.status is ExecutionStatus.OK, execution.message
    assert execution.result is not None
    np.testing.assert_array_equal(execution.result["scaled"], np.arange(4.0) * 2.5)
    np.testing.assert_array_equal(execution.result["n"], [2.0])


def test_code_without_result(executor: SandboxExecutor) -> None:
    execution = executor.run("x = 1")
    assert execution.status is ExecutionStatus.OK
    assert execution.result is None
    assert "no `result`" in execution.message


def test_task_arrives_without_its_checker(executor: SandboxExecutor) -> None:
    task = scenarios.make("plan-easy", seed=0)
    code = (
        "import numpy as np\n"
        "try:\n"
        "    task.check(None)\n"
        "    verdict = 'checked'\n"
        "except RuntimeError as error:\n"
        "    verdict = str(error)\n"
        "print(verdict)\n"
        "result = np.array([task.start, task.goal])\n"
    )
    execution = executor.run(code, inputs={"task": task})
    assert execution.status is ExecutionStatus.OK, execution.message
    assert "checker is not available" in execution.stdout
    assert execution.result is not None
    np.testing.assert_allclose(execution.result["result"], [task.start, task.goal])


@pytest.mark.parametrize("module", ["audere.scenarios", "audere.recipes", "audere.scenarios._planning"])
def test_scenario_generator_and_recipes_are_hidden(executor: SandboxExecutor, module: str) -> None:
    execution = executor.run(f"import {module}")
    assert execution.status is ExecutionStatus.EXCEPTION
    assert execution.exception is not None
    assert execution.exception.type in {"ImportError", "ModuleNotFoundError"}
    assert "not available inside the sandbox" in execution.exception.message


def test_apis_called_are_recorded(executor: SandboxExecutor) -> None:
    task = scenarios.make("plan-easy", seed=1)
    code = (
        "from audere.planners import astar, occupancy_grid\n"
        "grid = occupancy_grid(task.world(), resolution=0.25, margin=0.05)\n"
        "plan = astar(grid, task.start, task.goal)\n"
        "again = astar(grid, task.start, task.goal)\n"
        "result = plan.waypoints\n"
    )
    execution = executor.run(code, inputs={"task": task}, timeout_s=30.0)
    assert execution.status is ExecutionStatus.OK, execution.message
    assert execution.apis_called == ("astar",)
    assert execution.result is not None
    assert execution.result["result"].shape[1] == 2
    # a fresh child per run: the record does not carry over
    assert executor.run("result = 1.0").apis_called == ()


def test_apis_called_through_the_registry(executor: SandboxExecutor) -> None:
    code = (
        "from audere.apis import get_api\n"
        "try:\n"
        "    get_api('pid').function(None)\n"
        "except Exception:\n"
        "    pass\n"
    )
    execution = executor.run(code)
    assert execution.status is ExecutionStatus.OK, execution.message
    assert execution.apis_called == ("pid",)


def test_execution_round_trips_through_json(executor: SandboxExecutor) -> None:
    execution = executor.run("print('hi')\nresult = [[1, 2], [3, 4]]")
    again = Execution.from_dict(execution.to_dict())
    assert again.status is execution.status
    assert again.stdout == "hi\n"
    assert again.result is not None
    np.testing.assert_array_equal(again.result["result"], [[1.0, 2.0], [3.0, 4.0]])
    assert again.layers == execution.layers


def test_output_truncation_is_said(executor: SandboxExecutor) -> None:
    execution = executor.run("print('x' * 5000)", limits=Limits(output_bytes=100))
    assert execution.status is ExecutionStatus.OK
    assert execution.stdout_truncated
    assert len(execution.stdout) == 100
    assert not execution.stderr_truncated


def test_the_supervisor_is_reused(executor: SandboxExecutor) -> None:
    executor.run("result = 1.0")
    starts = executor.starts
    pid = executor.info["pid"]
    for _ in range(3):
        assert executor.run("result = 2.0").ok
    assert executor.starts == starts
    assert executor.info["pid"] == pid


def test_isolated_sys_path_leaves_out_the_script_directory() -> None:
    entries = _harden.isolated_sys_path()
    assert entries
    assert os.getcwd() not in entries
    assert "" not in entries
    if sys.path and not sys.flags.safe_path:
        assert sys.path[0] not in entries or sys.path[0] in sys.path[1:]
    import audere

    package_parent = str(Path(audere.__file__).resolve().parents[1])
    assert any(Path(package_parent).is_relative_to(os.path.realpath(e)) for e in entries)


def test_paths_make_a_users_module_importable(tmp_path: Path) -> None:
    modules = tmp_path / "mine"
    modules.mkdir()
    (modules / "my_planner.py").write_text("def double(x):\n    return 2 * x\n")
    (tmp_path / ".env").write_text("API_KEY=sk-FAKE-next-to-the-modules\n")
    code = (
        "import my_planner\n"
        "try:\n"
        "    secret = open(env).read()\n"
        "except OSError as error:\n"
        "    secret = type(error).__name__\n"
        "print(secret)\n"
        "result = [my_planner.double(21)]\n"
    )
    with SandboxExecutor(preload=("numpy", "my_planner"), paths=[str(modules)]) as sandbox:
        execution = sandbox.run(code, inputs={"env": str(tmp_path / ".env")})
        assert "my_planner" in sandbox.info["preloaded"]
    assert execution.status is ExecutionStatus.OK, execution.message
    assert execution.result is not None
    np.testing.assert_array_equal(execution.result["result"], [42.0])
    if any(name.startswith(("landlock", "bwrap")) for name in execution.layers):
        assert "sk-FAKE" not in execution.stdout, execution.stdout


def test_without_paths_the_users_module_is_not_importable(tmp_path: Path) -> None:
    (tmp_path / "not_installed.py").write_text("X = 1\n")
    with SandboxExecutor(layers=(), preload=("numpy", "not_installed")) as sandbox:
        execution = sandbox.run("import not_installed")
        assert "not_installed" in sandbox.info["missing"]
    assert execution.status is ExecutionStatus.EXCEPTION
    assert execution.exception is not None
    assert execution.exception.type == "ModuleNotFoundError"


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"code": 3}, "code: expected Python source"),
        ({"code": "x = 1", "timeout_s": 0}, "timeout_s: expected a positive number"),
        ({"code": "x = 1", "timeout_s": float("nan")}, "timeout_s: expected a positive number"),
        ({"code": "x = 1", "timeout_s": True}, "timeout_s: expected a positive number"),
        ({"code": "x = 1", "limits": {"cpu_s": 1}}, "limits: expected an audere Limits"),
        ({"code": "x = 1", "inputs": [1, 2]}, "inputs: expected a mapping"),
        ({"code": "x = 1", "inputs": {"not a name": 1}}, "inputs: names must be Python identifiers"),
        ({"code": "x = 1", "inputs": {"a": np.array(["s"])}}, r"inputs\['a'\]: arrays must be numeric"),
        ({"code": "x = 1", "inputs": {"a": object()}}, r"inputs\['a'\]: expected a numpy array"),
        ({"code": "x = 1", "inputs": {"a": float("inf")}}, r"inputs\['a'\]: expected a numpy array"),
    ],
)
def test_run_rejects_bad_arguments(kwargs: dict[str, object], match: str) -> None:
    sandbox = SandboxExecutor(layers=())  # validation comes before the supervisor starts
    try:
        with pytest.raises(InvalidArgumentError, match=match):
            sandbox.run(**kwargs)  # type: ignore[arg-type]
        assert sandbox.starts == 0
    finally:
        sandbox.close()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"layers": "landlock"}, "layers: expected a sequence of layer names"),
        ({"layers": ["firejail"]}, r"layers: unknown layer\(s\) \['firejail'\]"),
        ({"preload": "numpy"}, "preload: expected a sequence of module names"),
        ({"hidden": [""]}, "hidden: expected a sequence of module names"),
        ({"paths": "/usr"}, "paths: expected a sequence of paths"),
        ({"paths": ["/no/such/dir"]}, "paths: expected existing files or directories"),
        ({"paths": ["/"]}, "paths: '/' is too broad"),
        ({"paths": ["/tmp"]}, "paths: '/tmp' is too broad"),
        ({"base_dir": "/no/such/dir"}, "base_dir: expected an existing directory"),
    ],
)
def test_executor_rejects_bad_arguments(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        SandboxExecutor(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"memory_bytes": 0}, "Limits.memory_bytes: expected a positive integer"),
        ({"file_size_bytes": 1.5}, "Limits.file_size_bytes: expected a positive integer"),
        ({"open_files": True}, "Limits.open_files: expected a positive integer"),
        ({"cpu_s": -1}, "Limits.cpu_s: expected a positive number"),
        ({"processes": 0}, "Limits.processes: expected a positive integer or None"),
        ({"output_bytes": -5}, "Limits.output_bytes: expected a positive integer"),
    ],
)
def test_limits_reject_bad_values(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        Limits(**kwargs)  # type: ignore[arg-type]


def test_closed_executor_refuses_to_run() -> None:
    sandbox = SandboxExecutor(layers=(), preload=("numpy",))
    sandbox.close()
    with pytest.raises(AudereError, match="closed"):
        sandbox.run("x = 1")


def test_asking_for_a_missing_layer_names_the_reason(monkeypatch: pytest.MonkeyPatch) -> None:
    from audere.agent.sandbox import _host
    from audere.agent.sandbox._execution import LayerReport

    report = LayerReport(
        available={"landlock": True, "seccomp": False, "netns": True, "bwrap": True},
        details={"landlock": "ABI 7", "seccomp": "pyseccomp not installed", "netns": "ok", "bwrap": "ok"},
    )
    monkeypatch.setattr(_host, "_probe_cache", report)
    sandbox = SandboxExecutor(layers=["seccomp"])
    with pytest.raises(AudereError, match="seccomp: pyseccomp not installed"):
        _ = sandbox.applied_layers
    assert SandboxExecutor().applied_layers == ("landlock", "netns", "bwrap")
    assert report.missing == ("seccomp",)


def test_fake_executor_scripted_and_functional() -> None:
    timeout = Execution(status=ExecutionStatus.TIMEOUT, message="timed out")
    fake = FakeExecutor([timeout])
    assert isinstance(fake, Executor)
    assert fake.run("while True: pass", inputs={"k": 1}) is timeout
    assert fake.calls == [("while True: pass", {"k": 1})]
    with pytest.raises(AudereError, match="ran out of scripted executions after 1 run"):
        fake.run("x = 1")

    echo = FakeExecutor(lambda code, inputs: Execution(status=ExecutionStatus.OK, stdout=code))
    assert echo.run("print(1)").stdout == "print(1)"
    echo.close()
    assert echo.closed
    with pytest.raises(InvalidArgumentError, match="outcomes: expected Execution objects"):
        FakeExecutor(["ok"])  # type: ignore[list-item]


MY_API = '''\
from audere.apis import Result, register_api


@register_api("doubler", description="Doubles a number.", tags=("test",))
def doubler(x: float) -> Result:
    """Double a number.

    Parameters
    ----------
    x
        The number.

    Returns
    -------
    Result
        ``cost`` is twice ``x``.
    """
    return Result(status="solved", cost=2 * x)
'''


def test_a_users_registered_api_is_recorded(tmp_path: Path) -> None:
    (tmp_path / "my_api.py").write_text(MY_API)
    code = "from my_api import doubler\nresult = [doubler(2.0).cost]"
    with SandboxExecutor(preload=(*PRELOAD, "my_api"), paths=[str(tmp_path)]) as sandbox:
        execution = sandbox.run(code)
        assert "doubler" in sandbox.info["apis"]
    assert execution.status is ExecutionStatus.OK, execution.message
    assert execution.apis_called == ("doubler",)
    assert execution.result is not None
    np.testing.assert_array_equal(execution.result["result"], [4.0])
