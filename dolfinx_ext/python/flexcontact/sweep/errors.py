"""Errors of a sweep's set-up, raised before anything is computed."""
from ..errors import FlexcontactError, InputError


class ConfigError(InputError):
    """A bad sweep config: the message names the key and its value."""


class TableError(FlexcontactError, RuntimeError):
    """A results table that cannot be resumed (another config, a corrupt row)."""
