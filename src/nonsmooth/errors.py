"""Exceptions raised by the public API.

Every error the user can cause derives from :class:`NonsmoothError`; the CLI turns it into a
one-line message and a non-zero exit code (no traceback).
"""


class NonsmoothError(Exception):
    """Base class of all user-facing errors."""


class ParameterError(NonsmoothError, ValueError):
    """A parameter or option has an invalid value or name. The message names the field."""


class OutputError(NonsmoothError, OSError):
    """A result file or figure cannot be written, or a result file cannot be read."""


class IntegrationError(NonsmoothError, RuntimeError):
    """A single trajectory failed (status from a kernel); sweeps record it instead of raising."""
