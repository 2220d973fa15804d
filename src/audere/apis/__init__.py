"""The API registry: what the agent chooses among, and the typed result every API returns."""

from audere.apis._registry import ApiInfo, register_api
from audere.apis._result import Result, Status

__all__ = ["ApiInfo", "Result", "Status", "register_api"]
