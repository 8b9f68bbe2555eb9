"""Errors the core raises; the App layer shows them on the operation."""


class TmmError(ValueError):
    """Bad input: the message names what is wrong (file, parameter, value)."""


class WorkLimitError(TmmError):
    """The work estimated from the parameters is above the machine's limits (core.limits): refused before
    anything is allocated."""


class Cancelled(Exception):
    """The user cancelled a long computation through the progress callback."""
