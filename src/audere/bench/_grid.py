"""The experiment grid: what one experiment is, its stable key, and the product of the grid's axes."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from audere.errors import InvalidArgumentError

__all__ = ["METHODS", "PROVISIONS", "Experiment", "make_grid", "parse_seeds"]

METHODS: tuple[str, ...] = ("use-api", "code", "predict")
PROVISIONS: tuple[str, ...] = ("on-demand", "all")


class Experiment(BaseModel):
    """One cell of the grid: a scenario seed solved by one model with one method and setting."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    scenario: str
    seed: int = Field(ge=0)
    method: Literal["use-api", "code", "predict"] = "use-api"
    model: str = "audere/expert"
    temperature: float = Field(0.1, ge=0.0, le=2.0)
    provision: Literal["on-demand", "all"] = "on-demand"
    max_rounds: int = Field(6, ge=1)
    timeout_s: float = Field(30.0, gt=0.0)

    @property
    def key(self) -> str:
        """A stable, readable id: equal for equal experiments, in every run and on every machine."""
        return (
            f"{self.scenario}/seed={self.seed}/{self.method}/{self.model}/t={self.temperature:g}"
            f"/{self.provision}/rounds={self.max_rounds}/timeout={self.timeout_s:g}"
        )


def parse_seeds(text: str) -> list[int]:
    """Seeds from the command line: ``"100"`` (the first 100: 0..99), ``"100-199"`` or ``"1,5,9"``.

    Raises
    ------
    InvalidArgumentError
        For anything else, or an empty or descending range.
    """
    cleaned = str(text).strip()
    try:
        if "," in cleaned:
            seeds = [int(part) for part in cleaned.split(",") if part.strip()]
        elif "-" in cleaned:
            low, _, high = cleaned.partition("-")
            seeds = list(range(int(low), int(high) + 1))
            if int(high) < int(low):
                raise ValueError("descending")
        else:
            seeds = list(range(int(cleaned)))
    except ValueError:
        raise InvalidArgumentError(
            f"seeds: expected a count ('100'), a range ('100-199') or a list ('1,5,9'), got {text!r}"
        ) from None
    if not seeds or min(seeds) < 0:
        raise InvalidArgumentError(f"seeds: expected at least one seed, none negative, got {text!r}")
    return list(dict.fromkeys(seeds))


def _names(field: str, values: Iterable[str], allowed: Sequence[str]) -> list[str]:
    out = list(dict.fromkeys(v.strip() for v in values if v.strip()))
    if not out:
        raise InvalidArgumentError(f"{field}: expected at least one value, got none")
    unknown = [v for v in out if v not in allowed]
    if unknown:
        raise InvalidArgumentError(f"{field}: unknown {unknown}; choose from {list(allowed)}")
    return out


def make_grid(
    *,
    scenarios: Sequence[str],
    seeds: Sequence[int],
    methods: Sequence[str] = ("use-api",),
    models: Sequence[str] = ("audere/expert",),
    temperatures: Sequence[float] = (0.1,),
    provisions: Sequence[str] = ("on-demand",),
    max_rounds: int = 6,
    timeout_s: float = 30.0,
) -> list[Experiment]:
    """Every combination of the axes, in a stable order; provision varies for ``use-api`` only.

    Parameters
    ----------
    scenarios
        Scenario names (:func:`audere.scenarios.list_scenarios`).
    seeds
        Scenario seeds.
    methods
        ``use-api``, ``code``, ``predict``.
    models
        LiteLLM model strings or offline models.
    temperatures
        Sampling temperatures.
    provisions
        ``on-demand``, ``all`` (only ``use-api`` has APIs to provide; the baselines run once).
    max_rounds
        Rounds per experiment.
    timeout_s
        Time limit of each run of generated code, seconds.

    Returns
    -------
    list of Experiment
        Without duplicates, scenario-major.

    Raises
    ------
    InvalidArgumentError
        For an unknown scenario, method or provision, or an empty axis.
    """
    from audere.scenarios import list_scenarios

    known = [info.name for info in list_scenarios()]
    scenario_names = _names("scenarios", scenarios, known)
    method_names = _names("methods", methods, METHODS)
    provision_names = _names("provisions", provisions, PROVISIONS)
    model_names = list(dict.fromkeys(m.strip() for m in models if m.strip()))
    if not model_names:
        raise InvalidArgumentError("models: expected at least one model string, got none")
    temps = list(dict.fromkeys(float(t) for t in temperatures))
    bad = [t for t in temps if not (math.isfinite(t) and 0.0 <= t <= 2.0)]
    if not temps or bad:
        raise InvalidArgumentError(f"temperatures: expected values in [0, 2], got {list(temperatures)!r}")
    if not seeds:
        raise InvalidArgumentError("seeds: expected at least one seed, got none")
    grid: dict[str, Experiment] = {}
    for scenario, seed, method, model, temperature, provision in itertools.product(
        scenario_names, seeds, method_names, model_names, temps, provision_names
    ):
        experiment = Experiment(
            scenario=scenario,
            seed=int(seed),
            method=method,
            model=model,
            temperature=temperature,
            provision=provision if method == "use-api" else "on-demand",
            max_rounds=max_rounds,
            timeout_s=timeout_s,
        )
        grid.setdefault(experiment.key, experiment)
    return list(grid.values())
