"""Errors that are the user's input, not designopt's fault: worded as one line naming where and why.

``<file>: <key or line>: <reason>`` -- the CLI prints exactly that and exits with code 2. Anything else
that escapes is a bug in designopt.
"""

from __future__ import annotations

from pathlib import Path


class InputError(Exception):
    """Bad input: ``file`` is the file to fix, ``key`` the config key or the line in it, ``reason`` why."""

    def __init__(self, file: str | Path, key: str, reason: str):
        self.file, self.key, self.reason = str(file), key, reason
        super().__init__(f"{file}: {key}: {reason}")


class InputWarning(UserWarning):
    """An input designopt repaired (e.g. a repeated CSV point dropped): worth telling the user, not fatal."""


def read_text(path: str | Path, error: type[InputError] = InputError) -> str:
    """A user's text file (a config, a toolpath): its content, or one-line ``error`` saying why not."""
    path = Path(path)
    try:
        return path.read_text()
    except FileNotFoundError:
        raise error(path, "(file)", "no such file") from None
    except UnicodeDecodeError:
        raise error(path, "(file)", "not a text file") from None
    except OSError as exc:
        raise error(path, "(file)", f"cannot read: {exc.strerror or exc}") from None
