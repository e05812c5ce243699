"""The commands' rich console: a closed pipe ends the command as every other write does.

rich's own answer to a reader that has gone (``| head -1``) is to exit with status 1,
so a command that had done all its work reported a failure; here the pipe's error
reaches ``cli.main``, which ends quietly with 141, as a shell reports SIGPIPE.
"""

from __future__ import annotations

from rich.console import Console


class CliConsole(Console):
    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        if self.width < 1:  # COLUMNS=0: rich drew every line 0 wide, so nothing at all
            self.width = 80  # as rich takes a terminal that reports no size

    def on_broken_pipe(self) -> None:
        raise BrokenPipeError
