"""The one tool model (Cutter): the APT profile for drop queries, the torus view for multipoint and simulation."""
