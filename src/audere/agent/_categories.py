"""How a round ended: the paper's error taxonomy, made precise, plus infrastructure kept apart."""

from __future__ import annotations

from enum import StrEnum

__all__ = ["ErrorCategory"]


class ErrorCategory(StrEnum):
    """The outcome of one round of the agent loop.

    ``parsing`` … ``task_failure`` are the model's failures (the paper's taxonomy, with runtime
    errors apart from syntax errors); ``model_error`` and ``sandbox_error`` are infrastructure
    trouble, which never counts as the model's failure.
    """

    SUCCESS = "success"
    """The checker accepted the solution."""
    PARSING = "parsing"
    """No usable answer: no code block or answer line, a malformed tool call, numbers that do not parse."""
    SYNTAX = "syntax"
    """The code does not compile, or it does not define the entry point ``solve(task)``."""
    RUNTIME = "runtime"
    """The code raised, crashed, or hit a resource limit while running."""
    TIMEOUT = "timeout"
    """The code ran past the time limit."""
    TASK_FAILURE = "task_failure"
    """The code ran (or the numbers parsed), but the checker says the task is not solved."""
    MODEL_ERROR = "model_error"
    """The model provider failed after retries (rate limits, outages, bad credentials)."""
    SANDBOX_ERROR = "sandbox_error"
    """The sandbox itself failed (its supervisor was lost): not the model's fault."""

    @property
    def is_infrastructure(self) -> bool:
        """Whether this is infrastructure trouble rather than a verdict on the model's answer."""
        return self in (ErrorCategory.MODEL_ERROR, ErrorCategory.SANDBOX_ERROR)
