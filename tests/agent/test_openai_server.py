"""A real LiteLLM provider path: an OpenAI-compatible server on 127.0.0.1 (``model="openai/<name>"``).

The server is a small stdlib HTTP server that answers ``POST /v1/chat/completions`` with the offline
expert's replies, as vLLM, llama.cpp or any OpenAI-compatible server would: LiteLLM's OpenAI client
talks HTTP to it, tool calls included. Nothing leaves the machine.
"""

from __future__ import annotations

import json
import sys
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, ClassVar

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere.agent import Agent, ErrorCategory  # noqa: E402
from audere.agent._expert import answer  # noqa: E402


class _Handler(BaseHTTPRequestHandler):
    requests: ClassVar[list[dict[str, Any]]] = []
    fail_first: ClassVar[list[int]] = []

    def log_message(self, format: str, *args: object) -> None:  # keep the test output quiet
        pass

    def do_POST(self) -> None:
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        type(self).requests.append({"path": self.path, "auth": self.headers.get("Authorization"), **body})
        if self.fail_first:
            self.fail_first.pop()
            self._send(503, {"error": {"message": "overloaded, try again", "type": "server_error"}})
            return
        said = answer(body["messages"], body.get("tools"))
        message: dict[str, Any] = {"role": "assistant", "content": said.content}
        finish = "stop"
        if said.tool_call is not None:
            name, arguments = said.tool_call
            message["tool_calls"] = [
                {"id": "call_1", "type": "function", "function": {"name": name, "arguments": arguments}}
            ]
            finish = "tool_calls"
        self._send(
            200,
            {
                "id": "chatcmpl-local",
                "object": "chat.completion",
                "created": 0,
                "model": body["model"],
                "choices": [{"index": 0, "message": message, "finish_reason": finish}],
                "usage": {"prompt_tokens": 100, "completion_tokens": 20, "total_tokens": 120},
            },
        )

    def _send(self, status: int, payload: dict[str, Any]) -> None:
        data = json.dumps(payload).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


@pytest.fixture
def server() -> Iterator[str]:
    _Handler.requests = []
    _Handler.fail_first = []
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), _Handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}/v1"
    finally:
        httpd.shutdown()
        httpd.server_close()


@pytest.mark.parametrize("tool_calls", [True, False])
def test_agent_through_an_openai_compatible_server(server: str, tool_calls: bool) -> None:
    agent = Agent(
        "plan-hard",
        seed=2,
        model="openai/local-expert",
        api_base=server,
        api_key="sk-local",
        tool_calls=tool_calls,
    )
    result = agent.solve()
    assert result.success, str(result)
    assert result.categories == [ErrorCategory.SUCCESS]
    assert result.apis_called == ["astar"]
    assert result.prompt_tokens == 200  # the server's own usage counts
    sent = _Handler.requests
    assert [r["path"] for r in sent] == ["/v1/chat/completions"] * 2
    assert sent[0]["auth"] == "Bearer sk-local"
    assert sent[0]["model"] == "local-expert"
    assert sent[0]["temperature"] == 0.1
    assert ("tools" in sent[0]) is tool_calls


def test_server_errors_are_retried(server: str) -> None:
    _Handler.fail_first = [1]
    agent = Agent("track-lin", seed=1, model="openai/local-expert", api_base=server, api_key="sk-local")
    agent._client.sleep = lambda seconds: None
    result = agent.solve()
    assert result.success, str(result)
    assert result.calls[0].attempts == 2
