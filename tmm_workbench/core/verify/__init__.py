"""Verification the product runs on its own tool paths: 3-axis moves checked against the model between
their points (linear_moves). The independent checks the tests use (the Python z-map, the machine's view of
Tarus G-code, tool depth in a face) live in tests/core/."""
