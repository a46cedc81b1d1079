"""Tests of ``poro2d.paper``: the case study in one command."""
