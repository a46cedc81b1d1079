"""The console and table of every poro2d command: whole rows in a terminal, a file or a pipe.

rich draws for the width of the terminal. Written to a file or a pipe it assumes 80
columns, squeezes a wider table into them and cuts what still does not fit with
``…``: a log would read ``0.95…`` for 0.9571. :class:`OutputConsole` keeps the
terminal's width on a terminal and, anywhere else, takes :data:`FILE_WIDTH` columns:
more than any table of poro2d needs, so each row of a table (and each message) is
one line, written in full. A width set explicitly (``width=`` or the ``COLUMNS``
environment variable) is kept.

:class:`Table` folds a cell that is too wide for its column onto the next line
instead of cutting it, for terminals too narrow for the whole table.
"""

from __future__ import annotations

import unicodedata

from rich.console import Console, ConsoleDimensions
from rich.markup import escape
from rich.table import Table as _RichTable

FILE_WIDTH = 1000  # columns when writing to a file or a pipe: no row or message is wrapped


class OutputConsole(Console):
    """A rich console that does not narrow its output to 80 columns when it is not a terminal."""

    @property
    def size(self) -> ConsoleDimensions:
        size = super().size
        if self._width is None and not self.is_terminal:  # no width asked for, and no terminal to fit
            return ConsoleDimensions(FILE_WIDTH, size.height)
        return size

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        Console.size.fset(self, new_size)  # type: ignore[attr-defined]


class Table(_RichTable):
    """A rich table whose cells wrap (a number folds onto the next line) rather than end in ``…``.

    Columns that must stay on one line (``no_wrap=True``) keep rich's own handling.
    """

    def add_column(self, *args, **kwargs) -> None:
        kwargs.setdefault("overflow", "ellipsis" if kwargs.get("no_wrap") else "fold")
        super().add_column(*args, **kwargs)


def shown(text: str) -> str:
    """``text`` as a console prints it literally: rich markup escaped, and control and format
    characters written as escapes (``\\x1b``), so that a name from a user's file can neither
    style the output nor steer the terminal (colours, cursor moves, a reversed line)."""
    safe = "".join(
        c.encode("unicode_escape").decode("ascii") if unicodedata.category(c) in ("Cc", "Cf") else c
        for c in str(text)
    )
    return escape(safe)
