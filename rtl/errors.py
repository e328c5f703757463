"""The errors of bad input to bumprtl (re-exported by rtl/config.py, where they are usually
imported from): one-line messages naming the parameter and its allowed range."""

__all__ = ["BumpError", "ConfigError"]


class BumpError(ValueError):
    """Bad input to bumprtl. The message is one line that names the parameter and its
    allowed range; the CLI prints it and exits with status 2, never a traceback. ``field``
    is the parameter's name (None when the error is not about one parameter), so tests and
    callers can tell which value was refused without parsing the wording."""

    def __init__(self, message, field=None):
        super().__init__(message)
        self.field = field


class ConfigError(BumpError):
    """A configuration value out of its allowed range. The message names the field."""
