"""The headless command line: ``ladartui COMMAND ...``; with no command, the TUI.

Each command is a module in this package with ``add_parser(subparsers)`` that
registers itself (``parser.set_defaults(handler=run)``). User mistakes become
one line on stderr and exit status 2; no traceback reaches the user. A run refused
because another is writing the same output set exits 75 (sysexits' EX_TEMPFAIL), so a
batch script can tell "try again later" from "fix the input".
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import difflib
import errno
import importlib
import os
import re
import signal
import sys
from pathlib import Path

from ladartui import __version__
from ladartui.cli.progress import reset_stop, stop_status
from ladartui.errors import Cancelled, LadarError, OutputSetBusy, os_reason
from ladartui.textsafe import one_line
from ladartui.threads import environment_problem

BUSY_STATUS = 75  # another run writes the output set: the same command may succeed later

# Command name -> module under ladartui.cli. Modules load only when needed.
COMMANDS = {
    "run": "run",
    "trace": "trace",
    "generate": "generate",
    "info": "info",
    "validate": "validate",
    "compare": "compare",
    "bench": "bench",
    "study": "study",
    "sweep": "sweep",
    "pulses": "pulses",
    "certs": "certs",
    "voxelize": "voxelize",
    "tui": "tui",
}


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # A word that starts like a negative number is a value ("--at -5,-5", "--heading
        # -1e1"): argparse's own test took all but "-5" and "-0.5" for an unknown flag.
        self._negative_number_matcher = re.compile(r"-\.?\d")

    def error(self, message):
        # One line naming the flag, no usage dump: the user asked for -h if they want it.
        # Arguments are echoed in the message: escape them like any user text.
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see '{self.prog} -h')\n")

    def parse_args(self, args=None, namespace=None):
        # argparse tells words left over at the top, whose help lists no command's flags:
        # the command's own parser tells them here, pointing at its help.
        words = list(sys.argv[1:] if args is None else args)
        parsed, extras = self.parse_known_args(words, namespace)
        if extras:
            command = getattr(parsed, "command", None)
            commands = next((a.choices for a in self._actions if a.dest == "command"), None)
            told_by = commands.get(command, self) if isinstance(commands, dict) else self
            if command in words and set(extras) & set(words[: words.index(command)]):
                told_by = self  # given before the command: a word of the top level
            told_by.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="ladartui",
        description="Plan airborne foliage-penetrating LADAR collections. "
        "With no command, opens the terminal UI on the default scenario.",
    )
    parser.add_argument("--version", action="version", version=f"ladartui {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for module in COMMANDS.values():
        # a missing command module is an error: a renamed module must not make its
        # command vanish quietly
        importlib.import_module(f"ladartui.cli.{module}").add_parser(sub)
    return parser


def _names_a_scenario(argument: str) -> bool:
    """Whether the TUI can take ``argument``: a file, a .toml name or a bundled scenario."""
    from ladartui.user_data import bundled_scenario_name

    return (
        Path(argument).exists()
        or argument.lower().endswith(".toml")
        or bundled_scenario_name(argument) is not None
    )


def _unknown_command(word: str) -> str:
    close = difflib.get_close_matches(word, COMMANDS, n=1)
    if close:
        return one_line(f"unknown command {word!r}; did you mean {close[0]!r}?")
    return one_line(
        f"unknown command {word!r}; expected one of {', '.join(COMMANDS)}, or a scenario file (.toml)"
    )


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    # `ladartui`, `ladartui SCENARIO.toml` and `ladartui --graphics MODE` open the TUI.
    tui_flag = bool(argv) and argv[0].split("=")[0] == "--graphics"
    if not argv or tui_flag or (argv[0] not in COMMANDS and not argv[0].startswith("-")):
        if argv and not tui_flag and not _names_a_scenario(argv[0]):
            print(f"ladartui: error: {_unknown_command(argv[0])} (see 'ladartui -h')", file=sys.stderr)
            return 2
        argv = ["tui", *argv]
    if sys.stdout is None:  # started with it closed (`>&-`): print() would drop every line
        print(
            "ladartui: error: standard output is closed; expected it open (> /dev/null drops the output)",
            file=sys.stderr,
        )
        return 1
    reset_stop()
    try:
        parser = build_parser()  # (imports every command: a Ctrl-C can land here)
        args = parser.parse_args(argv)
        if getattr(args, "handler", None) is None:
            parser.print_help()
            return 2
        problem = environment_problem()  # before numba fails on it mid-command
        if problem:
            raise LadarError(problem)
        return int(args.handler(args) or 0)
    except LadarError as error:
        print(f"ladartui: error: {one_line(error)}", file=sys.stderr)
        return BUSY_STATUS if isinstance(error, OutputSetBusy) else 2
    except Cancelled as error:  # its message says what was (not) written
        _say(f"ladartui: {one_line(error)}")
        return stop_status()
    except KeyboardInterrupt:
        _say("ladartui: interrupted")
        return stop_status()
    except ImportError as error:
        # a Ctrl-C inside an extension module's start (matplotlib's, as a chart is drawn)
        # reaches here as the import's failure, the interrupt its cause
        if not isinstance(error.__cause__, KeyboardInterrupt):
            raise
        print("ladartui: interrupted", file=sys.stderr)
        return stop_status()
    except BrokenPipeError:
        return _reader_gone()
    except OSError as error:
        # Standard output on a full disk (`> out.json`, `> /dev/full`): print() names no
        # file. An error naming one, or of another kind, is no failed write: raised as it is.
        if error.filename is not None or error.errno not in _WRITE_ERRORS:
            raise
        if _while_stopping(error):  # a hangup took the terminal the stop was to be told on
            _reader_gone()
            return stop_status()
        what = "numba's cache of the compiled kernels" if _in_numba(error) else "the output"
        print(f"ladartui: error: could not write {what}: {os_reason(error)}", file=sys.stderr)
        _reader_gone()  # no second failure as Python flushes standard output at exit
        return 1


_WRITE_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO}


def _say(line: str) -> None:
    """``line`` on standard error, unless it cannot be written there (the terminal an SSH
    connection took with it as its hangup stopped the command): the exit status tells."""
    with contextlib.suppress(OSError, ValueError):
        print(line, file=sys.stderr)


def _while_stopping(error: BaseException) -> bool:
    """Whether ``error`` came as the command stopped (a Ctrl-C, SIGTERM or SIGHUP being
    handled): the progress bar's last draw on a terminal that has gone."""
    seen = error.__context__
    while seen is not None:
        if isinstance(seen, (Cancelled, KeyboardInterrupt)):
            return True
        seen = seen.__context__
    return False


def _in_numba(error: BaseException) -> bool:
    """Whether ``error`` came from numba's own code: a first run's kernels written to its
    cache (beside the modules, or NUMBA_CACHE_DIR) on a full disk, not the command's output."""
    import traceback

    numba = sys.modules.get("numba")
    if numba is None or numba.__file__ is None:
        return False  # never imported: none of its code ran
    package = os.path.dirname(numba.__file__) + os.sep  # its own files, not any folder named numba
    return any(frame.filename.startswith(package) for frame in traceback.extract_tb(error.__traceback__))


def _reader_gone() -> int:
    """Output piped into a reader that has gone (``| head -1``): end quietly, as a
    shell reports a program ended by SIGPIPE, and never flush into that pipe again."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    return 128 + signal.SIGPIPE


def entry() -> None:
    """The ``ladartui`` command and ``python -m ladartui``: ``main``, then an exit that a
    Ctrl-C can no longer turn into a failure (status 130, or killed by SIGINT): the
    command's work is done and said, only Python's shutting down is left."""
    # Python takes its own handlers away before its modules are torn down (a Ctrl-C then
    # killed the process): after every other exit handler (they run newest first, so
    # this one, registered first, runs last), a Ctrl-C is ignored
    atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)
    status = main()
    for stream in (sys.stdout, sys.stderr):  # all it printed, before any quick exit
        if stream is not None:  # (started with it closed: main said so, or could not)
            with contextlib.suppress(OSError, ValueError):
                stream.flush()

    def finished(signum, frame) -> None:  # threads joined, exit handlers run: end at once
        os._exit(status)

    signal.signal(signal.SIGINT, finished)
    raise SystemExit(status)
