"""The scene layer's one-line messages: `_fail` raises ``WHERE: PROBLEM (FIX)`` as a
SceneError; `_show` quotes a user's value; `_close`, `_suggestion` and `_guess_key` say what a
misspelt name most likely meant (difflib).

A leaf: it imports only the schema and the errors, so the model rules (sweep/models/rules.py)
word their refusals the same way without importing the rest of the scene package.
"""

from __future__ import annotations

import difflib
from typing import Any, NoReturn

from .. import schema
from ..errors import SceneError


def _fail(where: str, problem: str, fix: str) -> NoReturn:
    """Raise a one-line SceneError: ``WHERE: PROBLEM (FIX)``."""
    message = f"{where}: {problem} ({fix})"
    raise SceneError(message.replace("\r", "\\r").replace("\n", "\\n"))


def _close(word: str, candidates: Any) -> str | None:
    """The closest candidate to a misspelt word, or None."""
    matches = difflib.get_close_matches(word, list(candidates), n=1)
    return matches[0] if matches else None


def _suggestion(guess: str | None, fallback: str) -> str:
    return f"did you mean '{guess}'?" if guess else fallback


def _show(value: Any) -> str:
    """A short repr of a user's value for a message."""
    try:
        text = repr(value)
    except (ValueError, RecursionError):         # an int of > 4300 digits, deep nesting
        text = f"<a {type(value).__name__} too large to show>"
    return text if len(text) <= 60 else text[:57] + "..."


def _guess_key(name: str, section: str | None = None) -> str | None:
    """The dotted key a misspelt ``name`` most likely means: first in ``section``, then anywhere.

    E.g. ('lenght', 'cable') -> 'cable.length'; ('amplitude', 'cable') -> 'load.amplitude'.
    """
    if section is not None:
        in_section = _close(name, [k.name for k in schema.KEYS if k.section == section])
        if in_section:
            return f"{section}.{in_section}"
    anywhere = _close(name, [k.name for k in schema.KEYS])
    return next((k.dotted for k in schema.KEYS if k.name == anywhere), None)


def _section_not_table(section: str, value: Any) -> NoReturn:
    _fail(f"scene key '{section}'", f"must be a table ([{section}] section), got {_show(value)}",
          f"write [{section}] on a line of its own, with its keys below it")
