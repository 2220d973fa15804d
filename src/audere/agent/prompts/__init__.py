"""The packaged prompt templates the agent sends to models (``$name`` placeholders).

Each template is a Markdown file in this package; :func:`render` fills one in. The texts the model
reads about the task and the APIs are not kept here: they come from ``Task.describe()``, the task's
JSON, and the API registry (``catalog``, ``api_card``, ``api_source``).
"""

from __future__ import annotations

import functools
import string
from importlib import resources

from audere.errors import InvalidArgumentError

__all__ = ["PROMPT_VERSION", "render", "template_names"]

PROMPT_VERSION = "1"
"""Version of the prompt set; recorded in every solve result. Bump it when a template changes."""


@functools.cache
def _template(name: str) -> string.Template:
    path = resources.files(__name__).joinpath(f"{name}.md")
    if not path.is_file():
        raise InvalidArgumentError(
            f"name: expected one of the prompt templates {template_names()}, got {name!r}"
        )
    return string.Template(path.read_text(encoding="utf-8"))


def template_names() -> list[str]:
    """The names of the packaged templates, sorted."""
    return sorted(p.name[:-3] for p in resources.files(__name__).iterdir() if p.name.endswith(".md"))


def render(name: str, **fields: object) -> str:
    """Fill in the template ``name`` with ``fields``.

    Parameters
    ----------
    name
        Template name, e.g. ``"use_api_select"``.
    **fields
        A value for every ``$placeholder`` of the template.

    Returns
    -------
    str
        The prompt text, without trailing blank lines.

    Raises
    ------
    InvalidArgumentError
        For an unknown template or a missing field.
    """
    try:
        text = _template(name).substitute({key: str(value) for key, value in fields.items()})
    except KeyError as error:
        raise InvalidArgumentError(f"render({name!r}): missing the field {error.args[0]!r}") from None
    return text.rstrip() + "\n"
