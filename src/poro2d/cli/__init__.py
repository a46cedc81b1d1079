"""The ``poro2d`` command line: the top floor, one module per command or family of commands.

Each command module only parses its options, calls the Python function of the layer below
and prints the answer; :mod:`poro2d.cli.app` registers them all and holds :func:`main`, the
console entry point.
"""

from poro2d.cli.app import app, main

__all__ = ["app", "main"]
