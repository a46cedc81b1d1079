"""Figures of poro2d (matplotlib, Agg backend, no pyplot state)."""
