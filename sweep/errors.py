"""Errors a user can cause and fix. The CLI prints their message as one line and exits 2.

Messages quote what the user wrote (keys, values, file names), which may hold terminal escapes
or be megabytes long: `one_line` makes any message safe to print as one short line.
"""

from __future__ import annotations

import re

MAX_QUOTED = 80
"""Longest quoted item (characters, after escaping) `one_line` prints whole."""
MAX_LINE = 2000
"""Longest line (characters) `one_line` returns; a longer one loses its middle."""

# A quoted item ('...' or "..."), or a run of non-space characters.
_ITEM = re.compile(r"'[^']*'|\"[^\"]*\"|\S+")


class UserError(ValueError):
    """A mistake in the user's input: a scene key, a file, a command-line option.

    The message is one line: what (key or file), what is wrong, how to fix it.
    """


class SceneError(UserError):
    """A scene file, a built-in scene name or an override is invalid."""


class CableSweepWarning(UserWarning):
    """Something the user should know about a run that still goes ahead (one line)."""


def escape(text: str) -> str:
    """``text`` with every non-printable character (line breaks, tabs, ESC and other control
    characters, format characters such as bidi overrides, lone surrogates) written as its
    Python escape (``\\n``, ``\\x1b``, ``\\u202e``, ``\\udcff``); printable text is kept."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _shorten(item: str, limit: int) -> str:
    """An (escaped) item of at most about ``limit`` characters: its head, '...', its tail (a
    path's tail is its file name), then its length."""
    if len(item) <= limit:
        return item
    quote = item[0] if item[0] in "'\"" and item[-1] == item[0] and len(item) > 1 else ""
    body = item[len(quote):len(item) - len(quote)]
    head = (limit - 20) // 3
    tail = limit - 20 - head
    return f"{quote}{body[:head]}...{body[-tail:]}{quote} ({len(body):,} characters)"


def one_line(message: object) -> str:
    """A message as one safe, short line: non-printable characters escaped (`escape`), each
    quoted item or word longer than MAX_QUOTED characters cut to its head and its longer tail
    with '...' between and its full length, and the whole at most about MAX_LINE characters
    (head and tail kept)."""
    text = escape(" ".join(str(message).replace("\r\n", "\n").split("\n")))
    if len(text) > MAX_QUOTED:
        text = _ITEM.sub(lambda m: _shorten(m.group(0), MAX_QUOTED), text)
    if len(text) > MAX_LINE:
        text = f"{text[:MAX_LINE // 2]} ... {text[-MAX_LINE // 2:]}"
    return text
