"""What a solve produced: every model call, every round, the verdict; saved to and loaded from JSON."""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from audere.agent._categories import ErrorCategory
from audere.tasks import CheckReport, Solution, Task

__all__ = ["ModelCall", "Round", "SolveResult", "SolveStatus"]

SolveStatus = Literal["solved", "failed", "model_error", "invalid_task"]


class ModelCall(BaseModel):
    """One call to the model: what was sent (the new messages), what came back, and its cost."""

    model_config = ConfigDict(frozen=True)

    purpose: str = Field(description="select, code, revise, predict or parse.")
    prompt: str = Field(
        description="The text of the messages new in this call (the full prompt on the first)."
    )
    response: str = Field("", description="The reply's text.")
    tool_calls: list[tuple[str, str]] = Field(
        default_factory=list, description="(name, arguments) of each call."
    )
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cost: float | None = Field(None, description="USD, where LiteLLM knows the model's price.")
    latency_s: float = 0.0
    attempts: int = 1
    error: str | None = Field(None, description="The provider error, when the call failed after retries.")


class Round(BaseModel):
    """One round of the loop: the model's answer, how it ran, and the checker's verdict."""

    model_config = ConfigDict(frozen=True, arbitrary_types_allowed=True)

    index: int = Field(description="1-based.")
    calls: list[ModelCall] = Field(default_factory=list)
    selected_apis: list[str] = Field(default_factory=list, description="The APIs chosen so far (use-api).")
    plan: str | None = None
    code: str | None = Field(None, description="The code extracted from the answer, as run.")
    prediction: dict[str, list[Any]] | None = Field(None, description="The numbers of a predict answer.")
    execution: dict[str, Any] | None = Field(None, description="The sandbox's Execution, as a dict.")
    apis_called: list[str] = Field(default_factory=list, description="Registered APIs the code called.")
    category: ErrorCategory
    feedback: str = Field("", description="What went back to the model (empty after a success).")
    solution: Solution | None = None
    report: CheckReport | None = None
    wall_s: float = 0.0
    model_s: float = Field(0.0, description="Time spent waiting for the model in this round.")

    @property
    def overhead_s(self) -> float:
        """Everything but the model's own latency: prompts, parsing, the sandbox, the checker."""
        return max(0.0, self.wall_s - self.model_s)


class SolveResult(BaseModel):
    """The outcome of :meth:`audere.agent.Agent.solve`: the verdict and the whole transcript.

    Save it with :meth:`save` and read it back with :meth:`load`; it renders as text
    (``str(result)``) and, in notebooks, as HTML with a plot of the final trajectory.
    """

    model_config = ConfigDict(frozen=True, arbitrary_types_allowed=True)

    status: SolveStatus
    message: str
    task: Task | None = Field(None, description="The task solved (parsed from the text, when given text).")
    task_text: str | None = Field(None, description="The free text the task was parsed from.")
    method: str
    model: str
    model_label: str
    temperature: float
    api_provision: str
    max_rounds: int
    prompt_version: str
    tool_calls: bool = Field(description="Whether answers came as typed tool calls (else plain text).")
    parse_calls: list[ModelCall] = Field(default_factory=list, description="Calls turning text into a task.")
    rounds: list[Round] = Field(default_factory=list)
    solution: Solution | None = None
    report: CheckReport | None = None
    wall_s: float = 0.0

    @property
    def success(self) -> bool:
        """Whether the task was solved."""
        return self.status == "solved"

    @property
    def calls(self) -> list[ModelCall]:
        """Every model call, the task parsing and the API selection included, in order."""
        return [*self.parse_calls, *(c for r in self.rounds for c in r.calls)]

    @property
    def rounds_to_success(self) -> int | None:
        """The round that succeeded (the paper's count), or ``None``."""
        return self.rounds[-1].index if self.success and self.rounds else None

    @property
    def selected_apis(self) -> list[str]:
        """The APIs chosen in the last round."""
        return list(self.rounds[-1].selected_apis) if self.rounds else []

    @property
    def apis_called(self) -> list[str]:
        """The registered APIs the last round's code actually called."""
        return list(self.rounds[-1].apis_called) if self.rounds else []

    @property
    def prompt_tokens(self) -> int:
        """Prompt tokens over every call."""
        return sum(c.prompt_tokens for c in self.calls)

    @property
    def completion_tokens(self) -> int:
        """Completion tokens over every call."""
        return sum(c.completion_tokens for c in self.calls)

    @property
    def cost(self) -> float | None:
        """Cost in USD over every call, ``None`` when LiteLLM knows no price for the model."""
        costs = [c.cost for c in self.calls]
        return None if not costs or any(c is None for c in costs) else float(sum(c for c in costs if c))

    @property
    def categories(self) -> list[ErrorCategory]:
        """The outcome of each round, in order."""
        return [r.category for r in self.rounds]

    # --- files ------------------------------------------------------------------------------

    def save(self, path: str | Path) -> Path:
        """Write the result as JSON to ``path``; return the path."""
        target = Path(path)
        target.write_text(self.model_dump_json(indent=1), encoding="utf-8")
        return target

    @classmethod
    def load(cls, path: str | Path) -> SolveResult:
        """Read a result written by :meth:`save`."""
        return cls.model_validate_json(Path(path).read_text(encoding="utf-8"))

    # --- rendering ----------------------------------------------------------------------------

    def summary(self) -> str:
        """One line: verdict, rounds, calls, tokens."""
        cost = "" if self.cost is None else f", ${self.cost:.4f}"
        return (
            f"{self.status}: {self.message} [{self.method}, {self.model_label}; {len(self.rounds)} round(s), "
            f"{len(self.calls)} model call(s), {self.prompt_tokens}+{self.completion_tokens} tokens{cost}, "
            f"{self.wall_s:.1f} s]"
        )

    def __str__(self) -> str:
        lines = [self.summary()]
        if self.task is not None:
            lines.append(f"task: {self.task.name or self.task.kind}")
        for r in self.rounds:
            apis = f" apis={','.join(r.selected_apis)}" if r.selected_apis else ""
            called = f" called={','.join(r.apis_called)}" if r.apis_called else ""
            verdict = r.report.summary() if r.report is not None else (r.feedback.splitlines() or [""])[0]
            lines.append(f"  round {r.index}: {r.category.value}{apis}{called}: {verdict[:160]}")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        def cells(r: Round) -> str:
            verdict = r.report.summary() if r.report else (r.feedback.splitlines() or [""])[0][:200]
            values = [str(r.index), r.category.value, ", ".join(r.selected_apis), ", ".join(r.apis_called)]
            values += [verdict, f"{r.wall_s:.2f} s"]
            return "".join(f"<td>{html.escape(v)}</td>" for v in values)

        head = "".join(f"<th>{h}</th>" for h in ("round", "outcome", "selected", "called", "verdict", "time"))
        rows = "".join(f"<tr>{cells(r)}</tr>" for r in self.rounds)
        table = f"<table><tr>{head}</tr>{rows}</table>"
        return f"<div><p><b>{html.escape(self.summary())}</b></p>{table}{self._plot_html()}</div>"

    def _plot_html(self) -> str:
        if self.task is None:
            return ""
        last = self.rounds[-1] if self.rounds else None
        solution = self.solution or (last.solution if last else None)
        report = self.report or (last.report if last else None)
        try:
            from audere.viz import plot

            figure = plot(self.task, solution, report)
            buffer = io.BytesIO()
            figure.savefig(buffer, format="png", dpi=80, bbox_inches="tight")
        except Exception as error:  # a plot must never break the rendering of a result
            return f"<p>(no plot: {html.escape(type(error).__name__)}: {html.escape(str(error))})</p>"
        data = base64.b64encode(buffer.getvalue()).decode("ascii")
        return f'<img src="data:image/png;base64,{data}" alt="trajectory"/>'
