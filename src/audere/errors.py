"""Errors raised to people using audere.

Every error audere raises on purpose derives from :class:`AudereError` and from the built-in
exception a Python user would expect (``ValueError`` for a bad value, ``ImportError`` for a
missing backend), so ``except ValueError`` keeps working. Messages name the argument, what was
expected and what was received.

Feedback meant for a language model (checker diagnostics) is *not* an exception: see
:class:`audere.tasks.CheckReport`.
"""

from __future__ import annotations

__all__ = ["AudereError", "InvalidArgumentError", "MissingDependencyError"]


class AudereError(Exception):
    """Base class of every error audere raises on purpose."""


class InvalidArgumentError(AudereError, ValueError):
    """An argument has the wrong shape, type or value."""


class MissingDependencyError(AudereError, ImportError):
    """An optional backend is not installed; the message carries the install command."""
