"""Seed 001 section 5.1 experiments: research code kept out of the add-on package."""
