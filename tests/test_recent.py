"""The recent-scenarios list: newest first, no duplicates, bounded, never fatal."""

from __future__ import annotations

from ladartui.recent import RECENT_LIMIT, config_folder, recent_scenarios, remember_scenario


def test_the_newest_comes_first_without_duplicates_and_the_list_is_bounded(tmp_path, monkeypatch):
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    files = []
    for n in range(RECENT_LIMIT + 3):
        path = tmp_path / f"s{n}.toml"
        path.write_text("")
        files.append(path)
        remember_scenario(path)
    remember_scenario(files[5])
    listed = recent_scenarios()
    assert len(listed) == RECENT_LIMIT
    assert listed[0] == files[5].resolve()
    assert listed[1] == files[-1].resolve()
    assert len(set(listed)) == len(listed)
    assert (config_folder() / "recent.json").is_file()


def test_files_gone_from_disk_are_left_out_and_a_damaged_list_is_empty(tmp_path, monkeypatch):
    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    kept, gone = tmp_path / "kept.toml", tmp_path / "gone.toml"
    kept.write_text("")
    remember_scenario(gone)
    remember_scenario(kept)
    assert recent_scenarios() == [kept.resolve()]
    (config_folder() / "recent.json").write_text("{not json")
    assert recent_scenarios() == []
    (config_folder() / "recent.json").write_text('{"a": 1}')
    assert recent_scenarios() == []


def test_a_config_folder_that_cannot_be_written_is_not_an_error(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("LADARTUI_HOME", str(blocker))  # config would be under a file
    scenario = tmp_path / "s.toml"
    scenario.write_text("")
    assert remember_scenario(scenario) == [scenario.resolve()]
    assert recent_scenarios() == []


def test_a_list_nested_too_deep_or_holding_an_overlong_name_is_not_fatal(tmp_path, monkeypatch):
    """recent.json nested 3000 deep raised RecursionError; an entry longer than a name may
    be raised 'File name too long' from exists() and ended the app (exit 0)."""
    import json

    monkeypatch.setenv("LADARTUI_HOME", str(tmp_path / "home"))
    kept = tmp_path / "kept.toml"
    kept.write_text("")
    remember_scenario(kept)
    recent = config_folder() / "recent.json"
    recent.write_text("[" * 3000 + "]" * 3000)
    assert recent_scenarios() == []
    recent.write_text(json.dumps({"scenarios": ["/tmp/" + "x" * 300 + ".toml", str(kept)]}))
    assert recent_scenarios() == [kept]
    assert remember_scenario(kept)[0] == kept.resolve()
