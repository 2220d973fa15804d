"""Solve benchmark scenarios with the agent, offline, and look at what happened in each round.

Run it with ``python examples/solve_with_agent.py``. With no model configured the agent uses the
offline expert (a rule-based strategist, not an LLM); set ``AUDERE_MODEL=gpt-4o`` (or any LiteLLM
model string, with its API key in the environment) to let a real model choose the APIs.
"""

from __future__ import annotations

from audere.agent import Agent
from audere.viz import plot


def main() -> None:
    for scenario in ("track-car", "plan-hard", "plan-stl"):
        result = Agent(scenario, seed=4).solve()
        print(result)  # the verdict and one line per round: outcome, selected APIs, APIs called
        last = result.rounds[-1]
        print(f"  the code of the last round ({len(last.code or '')} characters) called {last.apis_called}")
        if result.task is not None:
            plot(result.task, result.solution, result.report).savefig(f"{scenario}.png", dpi=100)
            print(f"  wrote {scenario}.png")
        result.save(f"{scenario}.json")  # the whole transcript: prompts, replies, code, executions
        print(f"  wrote {scenario}.json")


if __name__ == "__main__":
    main()
