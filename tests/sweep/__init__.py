"""Tests of ``poro2d.sweep``: sweeps, the relation, the density mode and the sensitivity study."""
