"""Look up the built-in models by name."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from audere.dynamics._base import Dynamics
from audere.dynamics._models import DoubleIntegrator, Pendulum, SingleIntegrator, TwoLinkArm, Unicycle
from audere.errors import InvalidArgumentError

__all__ = ["get_dynamics", "list_dynamics"]

_MODELS: dict[str, type[Dynamics]] = {
    cls.name: cls for cls in (SingleIntegrator, DoubleIntegrator, Unicycle, Pendulum, TwoLinkArm)
}


def list_dynamics() -> list[str]:
    """Names of the built-in dynamics models, in order of increasing complexity.

    Returns
    -------
    list of str
        ``["single_integrator", "double_integrator", "unicycle", "pendulum", "two_link_arm"]``.
    """
    return list(_MODELS)


def get_dynamics(name: str, params: Mapping[str, float] | None = None) -> Dynamics:
    """Build a built-in dynamics model by name.

    Parameters
    ----------
    name
        One of :func:`list_dynamics`, e.g. ``"unicycle"``.
    params
        Model parameters overriding the defaults, e.g. ``{"length": 0.5}`` for the pendulum;
        ``None`` or an empty mapping keeps the defaults.

    Returns
    -------
    Dynamics
        The (immutable) model.

    Raises
    ------
    InvalidArgumentError
        For an unknown name, an unknown parameter or an invalid parameter value.
    """
    if not isinstance(name, str) or name not in _MODELS:
        raise InvalidArgumentError(f"name must be one of {', '.join(repr(n) for n in _MODELS)}, got {name!r}")
    cls = _MODELS[name]
    if params is not None and not isinstance(params, Mapping):
        raise InvalidArgumentError(
            "params must be a mapping from parameter name to value or None, "
            f"got {type(params).__name__}: {params!r}"
        )
    given = dict(params) if params is not None else {}
    accepted = [field.name for field in dataclasses.fields(cls)]
    unknown = sorted(str(k) for k in given if k not in accepted)
    if unknown:
        allowed = ", ".join(repr(a) for a in accepted) if accepted else "no parameters"
        raise InvalidArgumentError(
            f"params for {name!r} accept {allowed}, got unknown {', '.join(repr(k) for k in unknown)}"
        )
    return cls(**given)
