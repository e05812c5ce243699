"""User-facing errors: one line naming the file, line or field and what was expected."""


class LadarError(Exception):
    """A mistake in user input (file, scenario field, flag). Shown as one line, no traceback.

    Pickled as its message and attributes, not its constructor's arguments (a subclass's
    differ from ``args``), so one raised in a worker process (a process pool's, a Dask
    worker's) comes back as itself.
    """

    def __reduce__(self):
        return _remade, (type(self), self.args), {name: _picklable(v) for name, v in self.__dict__.items()}


def _picklable(value):
    """``value`` where it is plain data; else its description (an Event, a lock given
    where a number was expected could not be pickled), so the error crosses to another
    process either way. Plain by type, not by trying: a trial pickle of a live object
    (a client, its loop) may act on it."""
    if value is None or isinstance(value, str | bytes | int | float | complex | Described):
        return value
    if isinstance(value, list | tuple):
        items = [_picklable(v) for v in value]
        return items if isinstance(value, list) else tuple(items)
    if isinstance(value, dict):
        return {k: _picklable(v) for k, v in value.items()}
    if type(value).__module__.split(".")[0] in ("numpy", "pathlib"):
        return value
    told = described(value)
    return told if isinstance(told, Described) else Described(repr(value))


def _remade(cls, args):
    """An error of class ``cls`` holding ``args``, its ``__init__`` not run: unpickling
    then restores the attributes it had set."""
    return cls.__new__(cls, *args)


class InputFileError(LadarError):
    """A bad or missing input file; the message starts with ``path:line:`` where known."""

    def __init__(self, path, message, line=None):
        self.path = str(path)
        self.line = line
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class FieldError(LadarError):
    """A scenario, form or flag field outside its allowed values."""

    def __init__(self, field, value, expected, source=None, limits=None):
        self.field = field
        self.value = value
        self.expected = expected
        self.source = source  # the file (and line) it was read from, if any
        # (low, high, low_open, high_open) of a numeric range, so a form can say the
        # range in its own units; None for other checks
        self.limits = limits
        prefix = f"{source}: " if source else ""
        if value is None:  # never given: say so rather than "= None"
            super().__init__(f"{prefix}{field} is not set: expected {expected}")
        elif isinstance(value, Described):
            super().__init__(f"{prefix}{field} is {value.text}: expected {expected}")
        else:
            super().__init__(f"{prefix}{field} = {_shown(value)}: expected {expected}")


class Described:
    """A value told in words (an array by its shape, an object by its type) where
    quoting it would read as text the caller wrote: "scene is a Scenario", not
    "scene = 'Scenario'"."""

    def __init__(self, text: str):
        self.text = text

    def __repr__(self) -> str:
        return self.text


def described(value):
    """``value`` itself where its repr says what it is (None, text, a number, a list);
    else Described: an array by its shape, any other object by its type."""
    if getattr(value, "shape", None) == () and callable(getattr(value, "item", None)):
        return value.item()  # a numpy number (or a 0-d array): said as the value it holds
    if value is None or isinstance(value, str | int | float | complex | list | tuple | dict):
        return value
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple):
        return Described(f"an array of shape {shape}")
    name = type(value).__name__
    return Described(f"{'an' if name[:1].lower() in 'aeiou' else 'a'} {name}")


VALUE_CHARS = 60  # of a long list or text quoted in a FieldError: room is left for what was expected


def _shown(value) -> str:
    """``repr(value)``; a long list, table or text cut to its start with its size, so that
    the one-line message keeps what was expected (20,000 poses filled it)."""
    text = repr(value)
    if isinstance(value, list | tuple | dict) and len(text) > 2 * VALUE_CHARS:
        return f"{text[:VALUE_CHARS]}... ({len(value):,} {'item' if len(value) == 1 else 'items'})"
    if isinstance(value, str) and len(text) > 4 * VALUE_CHARS:
        return f"{text[:VALUE_CHARS]}... ({len(value):,} characters)"
    return text


class Cancelled(Exception):
    """A run stopped by its cancel event; nothing was written."""


def check_cancelled(cancel, message: str) -> None:
    """Raise ``Cancelled(message)`` once ``cancel`` (a threading.Event, or None) is set.

    The one cancel check of the core: long work calls it between its steps.
    """
    if cancel is not None and cancel.is_set():
        raise Cancelled(message)


def check_callbacks(progress=None, cancel=None) -> None:
    """FieldError for a ``progress`` that cannot be called or a ``cancel`` with no ``is_set``:
    long work checks both before it starts, not when it first reports or checks."""
    if progress is not None and not callable(progress):
        raise FieldError("progress", progress, "a function (or None)")
    if cancel is not None and not callable(getattr(cancel, "is_set", None)):
        raise FieldError("cancel", cancel, "a threading.Event (or None)")


class BackendUnavailable(LadarError):
    """A tracing backend that cannot run here, with the reason and what to install."""


class OutputFileError(LadarError):
    """An output path that cannot be written (a folder, a read-only folder, a locked set)."""

    def __init__(self, path, message):
        self.path = str(path)
        self.reason = message
        super().__init__(f"{self.path}: {message}")


class OutputSetBusy(OutputFileError):
    """Another run is writing the output set: nothing is wrong with the input, and the
    same command may succeed once that run ends (the CLI's exit status 75)."""


def os_reason(error: OSError) -> str:
    """An OSError's reason in words, without the path it names ("Permission denied")."""
    import os

    return os.strerror(error.errno) if error.errno else str(error)


class ResourceLimitError(LadarError):
    """Work refused up front: its estimated memory or rays exceed the limit."""
