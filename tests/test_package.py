"""The package surface: cheap and silent import, sorted and resolvable ``__all__``, version."""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

import audere

# Heavy or optional modules that `import audere` (and `import audere.<subpackage>`) must not import:
# each is imported inside the function that needs it.
HEAVY_MODULES = ("torch", "casadi", "ompl", "cvxpy", "control", "litellm", "matplotlib", "scipy.optimize")

# The public subpackages written so far or under way; the ones not yet present are skipped.
SUBPACKAGES = ("dynamics", "world", "stl", "tasks", "scenarios", "viz")

_REPORT_IMPORTED = """
import json, sys
import {module}
print(json.dumps(sorted(m for m in {heavy!r} if m in sys.modules)))
"""


def _run_python(code: str, *, cwd: Path) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a fresh interpreter with warnings as errors; return the finished process."""
    env = {**os.environ, "LITELLM_LOCAL_MODEL_COST_MAP": "True", "MPLBACKEND": "Agg"}
    env.pop("PYTHONWARNINGS", None)
    return subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=120,
        check=False,
    )


def _public_package(name: str) -> ModuleType:
    """Import ``audere.<name>``, skipping the test when the subpackage does not exist yet."""
    spec = importlib.util.find_spec(f"audere.{name}")
    if spec is None:
        pytest.skip(f"audere.{name} does not exist yet")
    if spec.origin is None or not spec.origin.endswith("__init__.py"):
        pytest.skip(f"audere.{name} has no __init__.py yet (no public surface declared)")
    return importlib.import_module(f"audere.{name}")


def _check_all(module: ModuleType) -> None:
    """Assert that ``module.__all__`` exists, is sorted without duplicates, and every name resolves."""
    assert hasattr(module, "__all__"), f"{module.__name__} declares no __all__"
    names = list(module.__all__)
    assert names, f"{module.__name__}.__all__ is empty"
    assert names == sorted(names), f"{module.__name__}.__all__ is not sorted: {names}"
    assert len(set(names)) == len(names), f"{module.__name__}.__all__ has duplicates: {names}"
    missing = {}
    for name in names:
        try:
            getattr(module, name)
        except (AttributeError, ImportError) as exc:  # lazy attributes import on first access
            missing[name] = f"{type(exc).__name__}: {exc}"
    assert not missing, f"{module.__name__}.__all__ names that do not resolve: {missing}"


def test_import_is_silent(tmp_path: Path) -> None:
    done = _run_python("import audere", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout == ""
    assert done.stderr == ""


@pytest.mark.parametrize("module", ["audere", *(f"audere.{name}" for name in SUBPACKAGES)])
def test_import_does_not_load_heavy_backends(module: str, tmp_path: Path) -> None:
    if module != "audere":
        _public_package(module.removeprefix("audere."))
    done = _run_python(_REPORT_IMPORTED.format(module=module, heavy=HEAVY_MODULES), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == [], f"`import {module}` imported heavy modules"


def test_top_level_all_is_sorted_and_resolves() -> None:
    _check_all(audere)


def test_version_matches_installed_metadata() -> None:
    assert audere.__version__ == importlib.metadata.version("audere")


@pytest.mark.parametrize("name", SUBPACKAGES)
def test_subpackage_all_is_sorted_and_resolves(name: str) -> None:
    module = _public_package(name)
    _check_all(module)
    private = [n for n in module.__all__ if n.startswith("_")]
    assert not private, f"audere.{name}.__all__ exports private names: {private}"
