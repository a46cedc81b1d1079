"""``python -m poro2d.cli``: the same as the ``poro2d`` console command."""

from poro2d.cli.app import main

if __name__ == "__main__":  # pragma: no cover
    # A process the command spawns (a Dask worker, a pool worker) re-runs the command's main
    # module before anything else, unless that module is a package's __main__, which spawn
    # skips. Seen as a plain file, this one is re-run: its first import, poro2d.cli, makes
    # the worker ignore Ctrl-C from its start, as under the console command (which is a file).
    __spec__ = None
    main()
