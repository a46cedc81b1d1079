"""The ``poro2d`` command line: the top floor, one module per command or family of commands.

Each command module only parses its options, calls the Python function of the layer below
and prints the answer; :mod:`poro2d.cli.app` registers them all and holds :func:`main`, the
console entry point.
"""

from poro2d.worker_signals import forget_unhandled_interrupt, ignore_interrupts_in_spawned_child

# a worker process of the command (a local Dask cluster's, a process pool's) imports this
# package first of all, before any signal handling of its own: Ctrl-C is the command's
ignore_interrupts_in_spawned_child()

try:
    from poro2d.cli.app import app, main
except KeyboardInterrupt:  # a Ctrl-C while the command still imports (a second or so): its one line
    import sys

    print("interrupted", file=sys.stderr)
    forget_unhandled_interrupt()
    raise SystemExit(130) from None

__all__ = ["app", "main"]
