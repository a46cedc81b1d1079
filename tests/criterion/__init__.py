"""Tests of ``poro2d.criterion``: the Fig. 3 loop, its controllers and density arithmetic."""
