"""Errors of a sweep's set-up, raised before anything is computed."""


class ConfigError(ValueError):
    """A bad sweep config: the message names the key and its value."""


class TableError(RuntimeError):
    """A results table that cannot be resumed (another config, a corrupt row)."""
