"""Tests of ``poro2d.calibration``: ``poro2d calibrate``."""
