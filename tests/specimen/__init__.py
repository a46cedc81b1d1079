"""Tests of ``poro2d.specimen``: gradings, placement, compaction, the box read back."""
