"""Tests of ``poro2d.dem``: the engine against its references and laws."""
