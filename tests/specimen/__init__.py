"""Tests of ``poro2d.specimen``: gradings, placement, compaction, porosity regions, jamming."""
