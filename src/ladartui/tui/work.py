"""The one way the interface runs slow work: a thread worker per job, and two messages.

``start_job(node, job, task)`` runs ``task(cancel, progress)`` in a Textual
thread worker (exclusive in its group, so a new job of the same name
replaces the old one). The task gets the worker's own ``cancelled_event``
as ``cancel`` (the core checks ``cancel.is_set()``), and ``progress(fraction,
text, detail=None, keep=False)`` posts a ``JobProgress``: a newer one
replaces an older one still queued (unless that one was kept), so a fast
task never floods the interface. When the task
ends, a ``JobDone`` says how: its result, cancelled, or the error as one
line. Every failure, expected or not, arrives that way (``exit_on_error`` is
off): nothing a task raises can close the app. Cancelling is
``worker.cancel()``; leaving the app cancels every worker.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeGuard

from textual.message import Message
from textual.worker import Worker, get_current_worker

from ladartui.errors import Cancelled, InputFileError, LadarError, OutputFileError
from ladartui.textsafe import one_line


# bubble=False: for the node that started the job only (Textual sets ``bubble`` from
# the class's arguments as it makes the class: a class attribute would be overwritten).
@dataclass
class JobProgress(Message, bubble=False):
    """How far job ``job`` has come: ``fraction`` 0..1 (None: unknown) and a line of text.

    ``detail`` is whatever else the job reports (a live view, a progress record).
    """

    job: str
    fraction: float | None
    text: str
    detail: Any = None
    keep: bool = False  # a report that must arrive (a finished row), never replaced

    def can_replace(self, message: Message) -> bool:
        """Whether newer ``message``, queued behind this report, may take its place:
        Textual asks the older message (its docstring reads the other way round).
        Not for a kept report; a report with a detail (a live view) only by one with one."""
        return (
            isinstance(message, JobProgress)
            and message.job == self.job
            and not self.keep
            and (self.detail is None or message.detail is not None)
        )


@dataclass
class JobDone(Message, bubble=False):
    """Job ``job`` ended: with ``result``, or ``cancelled``, or ``error`` (one line);
    ``error_path``: the file the error is about, where it names one (an input or output
    file's error)."""

    job: str
    result: Any = None
    cancelled: bool = False
    error: str | None = None
    error_path: str | None = None


Task = Callable[[Any, Callable[..., None]], Any]


def start_job(node, job: str, task: Task) -> Worker:
    """Run ``task(cancel, progress)`` in a thread worker; messages go to ``node``."""

    def body():
        worker = get_current_worker()

        def progress(fraction: float | None, text: str, detail: Any = None, keep: bool = False) -> None:
            node.post_message(JobProgress(job, fraction, text, detail, keep))

        try:
            result = task(worker.cancelled_event, progress)
        except Cancelled:
            node.post_message(JobDone(job, cancelled=True))
        except LadarError as error:
            node.post_message(JobDone(job, error=str(error), error_path=_file_of(error)))
        except Exception as error:  # unexpected: say what broke, keep the app open
            node.post_message(JobDone(job, error=one_line(f"{type(error).__name__}: {error}")))
        else:  # a task that finished did its work, even if cancel came too late to stop it
            node.post_message(JobDone(job, result))

    return node.run_worker(body, name=job, group=job, thread=True, exclusive=True, exit_on_error=False)


def _file_of(error: LadarError) -> str | None:
    return error.path if isinstance(error, (InputFileError, OutputFileError)) else None


def running(worker: Worker | None) -> TypeGuard[Worker]:
    """Whether ``worker`` exists and has not finished (used from any thread)."""
    return worker is not None and not worker.is_finished
