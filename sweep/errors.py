"""Errors a user can cause and fix. The CLI prints their message as one line and exits 2."""


class UserError(ValueError):
    """A mistake in the user's input: a scene key, a file, a command-line option.

    The message is one line: what (key or file), what is wrong, how to fix it.
    """


class SceneError(UserError):
    """A scene file, a built-in scene name or an override is invalid."""


class CableSweepWarning(UserWarning):
    """Something the user should know about a run that still goes ahead (one line)."""
