"""A stand-in for the program that uses the sandbox: the tests run it as a separate "host" process.

Hostile snippets attack the process that owns the executor (they kill it, read its environment, scan
``/proc`` for it), so that process must never be the test runner. This script plays that part: it
builds one :class:`~audere.agent.sandbox.SandboxExecutor` and serves requests, one JSON object per
line on stdin, answering with one JSON object per line on stdout:

- ``{"id": ..., "code": ..., "timeout_s": ..., "limits": {...} | null, "inputs": {...} | null}`` runs
  the code: first ``{"event": "running", "id": ...}``, then ``{"event": "done", "id": ..., "elapsed_s":
  ..., "execution": execution.to_dict()}`` (big result arrays summarised), or ``{"event": "interrupted",
  ...}`` when a KeyboardInterrupt (Ctrl-C sent to this process) ended the run, or ``{"event": "error",
  ...}`` when ``run`` raised (it never should);
- ``{"id": ..., "op": "start"}`` starts the supervisor and answers ``{"event": "started", "info": ...}``.

On end of input it closes the executor, says ``{"event": "closed", ...}`` and exits with status 0.

Usage: ``python host_runner.py '<json>'`` with ``{"layers": null | [...], "preload": null | [...],
"base_dir": null | str, "sigint": "ignore" | "default"}``. The environment (set by the tests) carries
the fake secrets: ``AUDERE_FAKE_API_KEY=sk-FAKE-<tag>``, ``HOME=<fake home>``, ``AUDERE_TEST_TAG=<tag>``.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from typing import Any

_FULL_RESULT_ELEMENTS = 50_000


def _emit(event: dict[str, Any]) -> None:
    sys.stdout.write(json.dumps(event) + "\n")
    sys.stdout.flush()


def _summarise(execution: Any) -> dict[str, Any]:
    data: dict[str, Any] = execution.to_dict()
    result = execution.result
    if result is not None:
        data["result_shapes"] = {name: list(array.shape) for name, array in result.items()}
        if sum(array.size for array in result.values()) > _FULL_RESULT_ELEMENTS:
            data["result"] = None
            data["result_summarised"] = True
    return data


def main() -> None:
    """Serve run requests from stdin until end of input."""
    options = json.loads(sys.argv[1])
    # A host started from a non-interactive shell inherits SIGINT=SIG_IGN (notes §5.11): "ignore" keeps
    # that on purpose, "default" makes Ctrl-C raise KeyboardInterrupt as in an interactive program.
    if options.get("sigint", "ignore") == "ignore":
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    else:
        signal.signal(signal.SIGINT, signal.default_int_handler)

    from audere.agent.sandbox import Limits, SandboxExecutor

    kwargs: dict[str, Any] = {"layers": options.get("layers")}
    if options.get("preload") is not None:
        kwargs["preload"] = tuple(options["preload"])
    if options.get("base_dir") is not None:
        kwargs["base_dir"] = options["base_dir"]
    executor = SandboxExecutor(**kwargs)
    _emit({"event": "ready", "pid": os.getpid()})
    for line in sys.stdin:
        if not line.strip():
            continue
        request = json.loads(line)
        ident = request.get("id")
        if request.get("op") == "start":
            executor.start()
            _emit({"event": "started", "id": ident, "info": executor.info, "starts": executor.starts})
            continue
        limits = Limits(**request["limits"]) if request.get("limits") else None
        _emit({"event": "running", "id": ident})
        started = time.monotonic()
        try:
            execution = executor.run(
                request["code"],
                inputs=request.get("inputs"),
                timeout_s=float(request.get("timeout_s", 10.0)),
                limits=limits,
            )
        except KeyboardInterrupt:
            _emit({"event": "interrupted", "id": ident, "elapsed_s": time.monotonic() - started})
            continue
        except Exception as error:  # run() must never raise for what the code does: report it
            _emit({"event": "error", "id": ident, "error": f"{type(error).__name__}: {error}"})
            continue
        elapsed = time.monotonic() - started
        _emit(
            {
                "event": "done",
                "id": ident,
                "elapsed_s": elapsed,
                "starts": executor.starts,
                "execution": _summarise(execution),
            }
        )
    executor.close()
    _emit({"event": "closed"})


if __name__ == "__main__":
    main()
