"""What ``--help`` shows a reader: flags as flags, and every command's summary as one whole line."""

from __future__ import annotations

import re

import pytest
import typer.main
from typer.testing import CliRunner

from poro2d.cli.app import app, summary_line

RUNNER = CliRunner()
WIDE = {"COLUMNS": "400"}  # no wrapping: a line break in the output is the help's own


def command_paths() -> list[list[str]]:
    """Every command and group of the app, as the words that name it (the root is ``[]``)."""
    paths: list[list[str]] = []

    def walk(command, prefix: list[str]) -> None:
        paths.append(prefix)
        for name, sub in (getattr(command, "commands", None) or {}).items():
            walk(sub, [*prefix, name])

    walk(typer.main.get_command(app), [])
    return paths


def help_of(path: list[str], env: dict) -> str:
    result = RUNNER.invoke(app, [*path, "--help"], env=env)
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("path", command_paths(), ids=lambda p: " ".join(p) or "poro2d")
def test_flags_show_no_value(path):
    """A flag takes no value, so its row names no type; an option that takes one still does."""
    text = help_of(path, WIDE)
    assert "<bool>" not in text
    assert re.search(r"--help\s{2,}Show this message", text)


def test_valued_options_keep_their_type():
    text = help_of(["criterion"], WIDE)
    assert re.search(r"--seed\s+<int>", text)
    assert re.search(r"--quiet\s{2,}No progress bars", text)


def test_commands_listed_with_whole_summaries():
    """Each command's row in the list is its docstring's first paragraph, unbroken."""
    command = typer.main.get_command(app)
    rows = help_of([], WIDE)
    plot_rows = help_of(["plot"], WIDE)
    names = list(command.commands) + [f"plot {n}" for n in command.commands["plot"].commands]
    for name in names:
        sub = command
        for word in name.split():
            sub = sub.commands[word]
        summary = summary_line(sub.help)
        listed = plot_rows if name.startswith("plot ") else rows
        assert summary in " ".join(listed.split()), name
        assert re.search(rf"│ {re.escape(name.split()[-1])}\s+{re.escape(summary[:60])}", listed), name


def test_summary_line_joins_the_first_paragraph():
    doc = "Biaxial tests: peak and\n    critical-state angles.\n\nMore text."
    assert summary_line(doc) == "Biaxial tests: peak and critical-state angles."
    assert summary_line(None) is None
