"""The public surface: pinned names, lazy heavy backends, actionable missing-backend errors, docstrings."""

from __future__ import annotations

import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import audere.dynamics
from audere.dynamics import Dynamics, get_dynamics, list_dynamics


def _run(code: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env.pop("PYTHONWARNINGS", None)
    return subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=120,
        check=False,
    )


def test_public_names_are_pinned() -> None:
    assert audere.dynamics.__all__ == [
        "BackendOps",
        "DoubleIntegrator",
        "Dynamics",
        "IntegrationMethod",
        "Pendulum",
        "SingleIntegrator",
        "TwoLinkArm",
        "Unicycle",
        "get_dynamics",
        "list_dynamics",
    ]


def test_numpy_use_imports_neither_torch_nor_casadi(tmp_path: Path) -> None:
    code = """
import sys
from audere.dynamics import get_dynamics, list_dynamics
for name in list_dynamics():
    m = get_dynamics(name)
    s = m.rollout([0.0] * m.n_x, [[0.1] * m.n_u] * 3, 0.1, method="rk4")
    m.linearize(s[1], [0.1] * m.n_u, 0.1)
    m.position(s)
    m.describe()
print(sorted(k for k in ("torch", "casadi") if k in sys.modules))
"""
    done = _run(code, tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
    assert done.stderr == ""


@pytest.mark.parametrize(
    ("blocked", "call", "extra"),
    [
        ("torch", "m.f_torch([0.0, 0.0, 0.0, 1.0], [0.0, 0.0])", "torch"),
        ("casadi", "m.casadi_function(0.1)", "casadi"),
        ("casadi", "m.f_casadi([0.0, 0.0, 0.0, 1.0], [0.0, 0.0])", "casadi"),
    ],
)
def test_missing_backend_names_the_install_command(
    tmp_path: Path, blocked: str, call: str, extra: str
) -> None:
    code = f"""
import sys
sys.modules[{blocked!r}] = None  # simulate a missing optional package
from audere.dynamics import get_dynamics
from audere.errors import MissingDependencyError
m = get_dynamics("unicycle")
try:
    {call}
except MissingDependencyError as exc:
    print(exc)
"""
    done = _run(code, tmp_path)
    assert done.returncode == 0, done.stderr
    assert f"pip install 'audere[{extra}]'" in done.stdout
    assert blocked in done.stdout


def _documented_parameters(doc: str) -> set[str]:
    """Names listed in the numpydoc ``Parameters`` section."""
    match = re.search(
        r"Parameters\n\s*-+\n(.*?)(?:\n\s*\n\s*(?:Returns|Raises|Yields|Examples|Notes)\n|\Z)", doc, re.S
    )
    if match is None:
        return set()
    return set(re.findall(r"^\s*(\w+)\s*$", match.group(1), re.M))


def _public_callables() -> list[tuple[str, object]]:
    items: list[tuple[str, object]] = [("get_dynamics", get_dynamics), ("list_dynamics", list_dynamics)]
    for name, member in inspect.getmembers(Dynamics):
        if not name.startswith("_") and inspect.isfunction(member):
            items.append((f"Dynamics.{name}", member))
    return items


@pytest.mark.parametrize(
    ("qualname", "func"), _public_callables(), ids=lambda v: v if isinstance(v, str) else ""
)
def test_every_parameter_and_return_is_documented(qualname: str, func: object) -> None:
    doc = inspect.getdoc(func) or ""
    params = [p for p in inspect.signature(func).parameters if p != "self"]  # type: ignore[arg-type]
    assert set(params) <= _documented_parameters(doc), f"{qualname}: undocumented parameters"
    assert "Returns\n-------" in doc, f"{qualname}: no Returns section"
    for p in inspect.signature(func).parameters.values():  # type: ignore[arg-type]
        assert p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD), f"{qualname}: *args/**kwargs"


@pytest.mark.parametrize("name", list_dynamics())
def test_model_classes_document_their_parameters(name: str) -> None:
    cls = type(get_dynamics(name))
    documented = _documented_parameters(inspect.getdoc(cls) or "")
    assert set(get_dynamics(name).params) == documented
