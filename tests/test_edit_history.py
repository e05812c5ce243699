"""Undo and redo over immutable states, and the modified mark they drive."""

from __future__ import annotations

import pytest

from ladartui.edit_history import EditHistory


def test_undo_and_redo_walk_the_edits_and_a_new_edit_clears_redo():
    history = EditHistory("a")
    history.edit("b", "a -> b")
    history.edit("c", "b -> c")
    assert history.undo().label == "b -> c" and history.current == "b"
    assert history.undo().label == "a -> b" and history.current == "a"
    assert history.undo() is None and history.current == "a"
    assert history.redo().label == "a -> b" and history.current == "b"
    history.edit("d", "b -> d")
    assert history.redo() is None and history.redo_label is None
    assert history.undo_label == "b -> d"


def test_modified_compares_with_the_saved_state_so_undo_back_to_it_clears_the_mark():
    history = EditHistory("a")
    assert not history.modified
    history.edit("b", "edit")
    assert history.modified
    history.undo()
    assert not history.modified
    history.redo()
    history.mark_saved("b")
    assert not history.modified
    history.undo()
    assert history.modified and history.current == "a"


def test_an_edit_that_changes_nothing_is_not_recorded():
    history = EditHistory(1)
    history.edit(1, "same")
    assert history.undo_label is None and not history.modified


def test_reset_forgets_every_step_and_the_depth_bounds_the_stack():
    history = EditHistory(0, depth=3)
    for n in range(1, 6):
        history.edit(n, f"to {n}")
    undone = []
    while (step := history.undo()) is not None:
        undone.append(step.after)
    assert undone == [5, 4, 3] and history.current == 2
    history.reset(9)
    assert history.undo() is None and history.redo() is None and not history.modified
    with pytest.raises(ValueError):
        EditHistory(0, depth=0)
