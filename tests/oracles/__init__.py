"""Tests of ``poro2d.oracles``: the engine's NumPy reference step and the jamming reference."""
