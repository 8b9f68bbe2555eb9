"""Verification: simulations that read tool paths (the 5-axis z-map of the toroidal tool so far)."""
