"""Isolated execution of model-written code.

Generated code is untrusted. :class:`SandboxExecutor` runs it in a separate, hardened process: a
warm supervisor (started with a minimal environment, pre-importing numpy, scipy, casadi, torch,
OMPL and audere's APIs) forks one child per execution. The child runs in its own session, in a fresh
scratch directory, under rlimits (address space, CPU, file size, open files), and, where this machine
supports them, under Landlock, seccomp, a network namespace and bubblewrap. On timeout or end the
child's process group is killed and every remaining descendant swept. Results come back as JSON and
``.npy`` arrays, type- and size-checked; nothing is unpickled.

>>> from audere.agent.sandbox import SandboxExecutor
>>> with SandboxExecutor() as executor:  # doctest: +SKIP
...     execution = executor.run("result = [1.0, 2.0]")
>>> execution.status.value  # doctest: +SKIP
'ok'

:class:`FakeExecutor` returns scripted executions, for tests of code that only needs an executor.
"""

from __future__ import annotations

from audere.agent.sandbox._execution import (
    AGENT_FILENAME,
    ExceptionInfo,
    Execution,
    ExecutionStatus,
    Frame,
    LayerReport,
    Limits,
)
from audere.agent.sandbox._fake import FakeExecutor
from audere.agent.sandbox._host import (
    DEFAULT_HIDDEN,
    DEFAULT_PRELOAD,
    LAYERS,
    Executor,
    SandboxExecutor,
    probe_layers,
)

__all__ = [
    "AGENT_FILENAME",
    "DEFAULT_HIDDEN",
    "DEFAULT_PRELOAD",
    "LAYERS",
    "ExceptionInfo",
    "Execution",
    "ExecutionStatus",
    "Executor",
    "FakeExecutor",
    "Frame",
    "LayerReport",
    "Limits",
    "SandboxExecutor",
    "probe_layers",
]
