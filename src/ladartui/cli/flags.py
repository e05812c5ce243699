"""Core field errors named as the flags the user typed.

The core names a field as the scenario file does (``simulation.backend``,
``detection.n_ref``, ``at``); a command that passed a flag's value on says
``--backend``, ``--n-ref``, ``--at`` instead, with the value as typed.
"""

from __future__ import annotations

import contextlib

from ladartui.errors import FieldError


@contextlib.contextmanager
def as_flags(typed: dict):
    """Re-raise a FieldError whose field ends in one of ``typed``'s names (``n_ref``) as
    that flag (``--n-ref``) with the value typed; names whose value is None were not
    typed and pass the error on as it is."""
    try:
        yield
    except FieldError as error:
        name = error.field.rpartition(".")[2]
        if typed.get(name) is None:
            raise
        raise FieldError("--" + name.replace("_", "-"), typed[name], error.expected) from None
