"""``python -m poro2d.cli``: the same as the ``poro2d`` console command."""

from poro2d.cli.app import main

if __name__ == "__main__":  # pragma: no cover
    main()
