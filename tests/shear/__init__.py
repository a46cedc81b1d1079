"""Tests of ``poro2d.shear``: direct shear tests, series, replicates and strength studies."""
