"""What the multipoint positioner found at a footprint point: the kernel's status codes and their names (two
contacts, one contact, failed). Read by the strategy, its refinement between positions and the pictures."""
STATUS_TWO, STATUS_ONE, STATUS_FAILED = 0, 1, 2
STATUS_NAMES = ("two", "one", "failed")
