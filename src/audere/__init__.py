"""audere: robot planning and control driven by language models.

``import audere`` is cheap: heavy backends (torch, casadi, ompl, cvxpy, control, litellm)
are imported by the modules that use them.
"""

from __future__ import annotations

__version__ = "0.1.0.dev0"

__all__ = ["__version__"]
