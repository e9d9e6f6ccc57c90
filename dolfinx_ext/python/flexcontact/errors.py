"""The errors flexcontact raises, under one base class.

``except flexcontact.FlexcontactError`` catches every error of the library: bad input
(``InputError``, also a ValueError; ``InputTypeError``, also a TypeError), a solve that
fails (``SolveError``, also a RuntimeError, the base of the compiled module's
ConvergenceError, SingularStiffnessError, MumpsError and PetscError), and the specific ones
(ContactZoneError, ContactMemoryError, NoEquilibriumError, the sweep's ConfigError and
TableError). Each keeps its built-in base, so code that catches ValueError or RuntimeError
goes on working.
"""
from __future__ import annotations


class FlexcontactError(Exception):
    """Base of every error flexcontact raises."""


class InputError(FlexcontactError, ValueError):
    """A parameter, tag or value that cannot be used; the message names it and its value."""


class InputTypeError(FlexcontactError, TypeError):
    """An argument of the wrong kind; the message names it and what was expected."""


class SavedFileError(FlexcontactError, ValueError):
    """A saved file (a factor, a model) that is missing, truncated, altered or of another
    format or version; the message names the file and what does not match."""


class SolveError(FlexcontactError, RuntimeError):
    """A factorization, a contact solve or another computation that failed."""
