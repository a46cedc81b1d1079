"""CLI commands for the 3D-to-2D porosity conversions (filled in by the conversions work)."""

from __future__ import annotations

import typer


def register(app: typer.Typer) -> None:
    """Attach the conversion commands to the root app."""
