"""Reading a text file that roto was told about (a plan, a config, a summary, a page) with one-line
errors that name what the file is for, the path and what is wrong with it."""

from __future__ import annotations

import pathlib


def read_text(path: str | pathlib.Path, what: str, form: str = "") -> str:
    """The UTF-8 text of ``path``; ``what`` names the file's role in errors ("plan", "page"), ``form``
    its format ("JSON") where a binary file is refused.

    Raises:
        FileNotFoundError when ``path`` does not exist; ValueError naming ``what`` and the path when it
        is a folder, cannot be read, or is not UTF-8 text (with the first byte that is not).
    """
    path = pathlib.Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise ValueError(f"{what} {str(path)!r} cannot be read: it is a folder; give a file") from None
    except OSError as error:
        raise ValueError(f"{what} {str(path)!r} cannot be read: {error.strerror or error}") from None
    except UnicodeDecodeError as error:
        text = f"{form} text" if form else "text"
        byte = error.object[error.start]
        raise ValueError(
            f"{what} {str(path)!r} is not {text}: byte {error.start} ({byte:#04x}) is not UTF-8; is it a binary file?"
        ) from None
