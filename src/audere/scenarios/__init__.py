"""Seeded generators of the benchmark tasks: the paper's five scenarios and one per other dynamics model.

>>> from audere.scenarios import list_scenarios, make
>>> [s.name for s in list_scenarios()][:5]
['track-lin', 'track-car', 'plan-easy', 'plan-hard', 'plan-stl']
>>> task = make("plan-easy", seed=3)
>>> task.name
'plan-easy/seed=3'

The same name and seed always give the same task; every task is valid and solvable by
construction. See ``docs/scenarios.md`` for the parameters of each scenario.
"""

from audere.scenarios._registry import ScenarioInfo, list_scenarios, make

__all__ = ["ScenarioInfo", "list_scenarios", "make"]
