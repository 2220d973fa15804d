"""Hypothesis strategies for the dynamics tests: models (with random valid parameters), states, inputs."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from audere.dynamics import Dynamics, get_dynamics, list_dynamics

# Random physical parameters per model, kept in ranges where the equations are well conditioned.
_PARAM_RANGES: dict[str, dict[str, tuple[float, float]]] = {
    "single_integrator": {},
    "double_integrator": {},
    "unicycle": {},
    "pendulum": {"length": (0.3, 2.0), "mass": (0.3, 3.0), "gravity": (0.0, 10.0), "damping": (0.0, 1.0)},
    "two_link_arm": {
        "l1": (0.3, 2.0),
        "l2": (0.3, 2.0),
        "m1": (0.3, 3.0),
        "m2": (0.3, 3.0),
        "gravity": (0.0, 10.0),
        "damping": (0.0, 1.0),
    },
}

methods = st.sampled_from(["euler", "rk4"])
dts = st.floats(min_value=0.01, max_value=1.0, allow_nan=False, allow_infinity=False)


def finite(bound: float) -> st.SearchStrategy[float]:
    """Finite floats in ``[-bound, bound]``."""
    return st.floats(min_value=-bound, max_value=bound, allow_nan=False, allow_infinity=False)


def vectors(n: int, *, bound: float = 3.0, batch: tuple[int, ...] = ()) -> st.SearchStrategy[np.ndarray]:
    """Arrays of shape ``(*batch, n)`` with entries in ``[-bound, bound]``."""
    return hnp.arrays(np.float64, (*batch, n), elements=finite(bound))


@st.composite
def models(draw: st.DrawFn, *, random_params: bool = True) -> Dynamics:
    """A built-in model, with random valid parameters when it has any."""
    name = draw(st.sampled_from(list_dynamics()))
    if not random_params:
        return get_dynamics(name)
    params = {
        key: draw(st.floats(min_value=lo, max_value=hi, allow_nan=False))
        for key, (lo, hi) in _PARAM_RANGES[name].items()
    }
    return get_dynamics(name, params)


@st.composite
def model_state_input(
    draw: st.DrawFn, *, bound: float = 3.0, batch: tuple[int, ...] = ()
) -> tuple[Dynamics, np.ndarray, np.ndarray]:
    """A model with a state ``(*batch, n_x)`` and an input ``(*batch, n_u)``."""
    model = draw(models())
    x = draw(vectors(model.n_x, bound=bound, batch=batch))
    u = draw(vectors(model.n_u, bound=bound, batch=batch))
    return model, x, u


@st.composite
def model_rollout_case(
    draw: st.DrawFn, *, max_batch: int = 4, max_horizon: int = 6
) -> tuple[Dynamics, np.ndarray, np.ndarray]:
    """A model with batched initial states ``(B, n_x)`` and input sequences ``(B, horizon, n_u)``."""
    model = draw(models())
    size = draw(st.integers(min_value=1, max_value=max_batch))
    horizon = draw(st.integers(min_value=0, max_value=max_horizon))
    x0 = draw(vectors(model.n_x, batch=(size,)))
    inputs = draw(hnp.arrays(np.float64, (size, horizon, model.n_u), elements=finite(2.0)))
    return model, x0, inputs
