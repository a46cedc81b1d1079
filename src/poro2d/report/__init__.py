"""Figures and reports: force chains, direct shear overlays, the paper report."""
