"""The API registry: what the agent chooses among, and the typed result every API returns.

>>> from audere.apis import catalog, api_card, tool_schema
>>> print(catalog())  # doctest: +SKIP
>>> tool_schema("pid")["function"]["name"]  # doctest: +SKIP
'pid'
"""

from audere.apis._card import api_card, api_source, catalog
from audere.apis._registry import ApiInfo, get_api, list_apis, register_api
from audere.apis._result import Result, Status
from audere.apis._schema import tool_schema, validate_call

__all__ = [
    "ApiInfo",
    "Result",
    "Status",
    "api_card",
    "api_source",
    "catalog",
    "get_api",
    "list_apis",
    "register_api",
    "tool_schema",
    "validate_call",
]
