"""Tests of ``poro2d.measure``: porosities, the specimen's porosity and state, stress, coordination."""
