"""Every command in the CLI's table has its module: none can vanish quietly."""

from __future__ import annotations

import importlib

import pytest

from ladartui import cli


def test_every_command_module_exists_and_adds_its_parser():
    parser = cli.build_parser()
    choices = next(a for a in parser._actions if a.dest == "command").choices
    assert set(choices) == set(cli.COMMANDS)


def test_a_missing_command_module_is_an_error_not_a_missing_command(monkeypatch):
    monkeypatch.setitem(cli.COMMANDS, "ghost", "ghost_command_that_does_not_exist")
    with pytest.raises(ModuleNotFoundError):
        cli.build_parser()


def test_the_study_package_offers_only_names_that_resolve():
    study = importlib.import_module("ladartui.study")
    for name in study.__all__:
        assert getattr(study, name) is not None, name
