"""Tests of ``poro2d.sand``: ``poro2d sand``."""
