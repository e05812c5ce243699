"""Undo and redo over a scenario under edit.

A ``Scenario`` is immutable, so an edit is just the next scenario: the
history keeps the scenarios before and after each edit with a short label
("Sensor grid n 32 -> 64"), and undo or redo hands one back whole. Whether
the scenario is modified is a comparison with the one last saved or
loaded, so undoing back to it clears the modified mark.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Generic, TypeVar

State = TypeVar("State")

DEFAULT_DEPTH = 200  # edits kept for undo; older ones are forgotten


@dataclass(frozen=True)
class Step(Generic[State]):
    """One edit: the state before it, the state after it and what it was."""

    before: State
    after: State
    label: str


class EditHistory(Generic[State]):
    """The current state, the saved state and the undo and redo stacks."""

    def __init__(self, state: State, depth: int = DEFAULT_DEPTH):
        if depth < 1:
            raise ValueError("the history must keep at least one edit")
        self.depth = depth
        self.reset(state)

    def reset(self, state: State) -> None:
        """Start over from ``state`` (loaded or new): nothing to undo, not modified."""
        self.current = state
        self.saved = state
        self._undo: list[Step[State]] = []
        self._redo: list[Step[State]] = []

    def edit(self, state: State, label: str) -> None:
        """Make ``state`` current; the edit can be undone and clears what could be redone."""
        if state == self.current:
            return
        self._undo.append(Step(self.current, state, label))
        del self._undo[: -self.depth]
        self._redo.clear()
        self.current = state

    def mark_saved(self, state: State) -> None:
        """``state`` was written where it was loaded from: the unmodified reference.

        (Saving under another name changes what every undo step would save
        to, so Save As starts the history over with ``reset`` instead.)
        """
        self.current = state
        self.saved = state

    @property
    def modified(self) -> bool:
        return self.current != self.saved

    @property
    def undo_label(self) -> str | None:
        return self._undo[-1].label if self._undo else None

    @property
    def redo_label(self) -> str | None:
        return self._redo[-1].label if self._redo else None

    def undo(self) -> Step[State] | None:
        """Go back one edit; the step undone, or None when there is nothing to undo."""
        if not self._undo:
            return None
        step = self._undo.pop()
        self._redo.append(step)
        self.current = step.before
        return step

    def redo(self) -> Step[State] | None:
        """Apply the last undone edit again; None when there is nothing to redo."""
        if not self._redo:
            return None
        step = self._redo.pop()
        self._undo.append(step)
        self.current = step.after
        return step
