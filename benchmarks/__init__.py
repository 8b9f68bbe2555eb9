"""Benchmarks and research experiments (not shipped in the add-on)."""
