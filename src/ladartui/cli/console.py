"""The commands' rich console: a closed pipe ends the command as every other write does.

rich's own answer to a reader that has gone (``| head -1``) is to exit with status 1,
so a command that had done all its work reported a failure; here the pipe's error
reaches ``cli.main``, which ends quietly with 141, as a shell reports SIGPIPE.
"""

from __future__ import annotations

from rich.console import Console


class CliConsole(Console):
    def on_broken_pipe(self) -> None:
        raise BrokenPipeError
