"""A scripted executor for tests of code that only needs *an* executor (it runs nothing)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from audere.agent.sandbox._execution import Execution, Limits
from audere.errors import AudereError, InvalidArgumentError

__all__ = ["FakeExecutor"]


class FakeExecutor:
    """An :class:`~audere.agent.sandbox.Executor` that returns scripted executions and runs nothing.

    Parameters
    ----------
    outcomes
        Either the executions to return, in order (one per :meth:`run`; running out is an error),
        or a function ``(code, inputs) -> Execution`` called for every run.

    Attributes
    ----------
    calls
        Every ``(code, inputs)`` passed to :meth:`run`, in order.

    Examples
    --------
    >>> from audere.agent.sandbox import Execution, ExecutionStatus, FakeExecutor
    >>> fake = FakeExecutor([Execution(status=ExecutionStatus.TIMEOUT, message="timed out")])
    >>> fake.run("while True: pass").status.value
    'timeout'
    >>> len(fake.calls)
    1
    """

    def __init__(
        self, outcomes: Sequence[Execution] | Callable[[str, Mapping[str, object]], Execution]
    ) -> None:
        if callable(outcomes):
            self._function: Callable[[str, Mapping[str, object]], Execution] | None = outcomes
            self._queue: list[Execution] = []
        else:
            items = list(outcomes)
            bad = [type(item).__name__ for item in items if not isinstance(item, Execution)]
            if bad:
                raise InvalidArgumentError(f"outcomes: expected Execution objects or a function, got {bad}")
            self._function = None
            self._queue = items
        self.calls: list[tuple[str, dict[str, object]]] = []
        self.closed = False

    def run(
        self,
        code: str,
        *,
        inputs: Mapping[str, object] | None = None,
        timeout_s: float = 10.0,
        limits: Limits | None = None,
    ) -> Execution:
        """Record the call and return the next scripted execution.

        Parameters
        ----------
        code
            The code (recorded, not run).
        inputs
            The inputs (recorded).
        timeout_s
            Ignored.
        limits
            Ignored.

        Returns
        -------
        Execution
            The next scripted execution, or what the function returns.
        """
        given = dict(inputs or {})
        self.calls.append((code, given))
        if self._function is not None:
            return self._function(code, given)
        if not self._queue:
            raise AudereError(
                f"FakeExecutor ran out of scripted executions after {len(self.calls) - 1} run(s)"
            )
        return self._queue.pop(0)

    def close(self) -> None:
        """Mark the fake closed."""
        self.closed = True
