"""The user's keys.toml: each line checked, a problem named on its line and left out,
never a crash; no command takes a key the views keep."""

from __future__ import annotations


def test_keys_toml_problems_are_named_on_their_line_never_a_crash(tmp_path):
    """A keys.toml not in UTF-8 ended the app with a traceback, one nested 3000 deep in a
    RecursionError; two commands on one key, and a misspelt [keyz], passed without a word."""
    from ladartui.tui.actions import keys_in_force, load_keymap

    keys = tmp_path / "keys.toml"
    keys.write_bytes(b'[keys]\nrun = "\xe9"\n')
    keymap, problems = load_keymap(tmp_path)
    assert keymap == {} and len(problems) == 1 and "not UTF-8" in problems[0]
    keys.write_text("a = " + "[" * 3000 + "]" * 3000 + "\n")
    keymap, problems = load_keymap(tmp_path)
    assert keymap == {} and len(problems) == 1 and "nested too deep" in problems[0]
    keys.write_text('[keyz]\nrun = "f9"\n\n[keys]\n\nrun = "ctrl+s"\nlayout = "ctrl+l"\n')
    keymap, problems = load_keymap(tmp_path)
    assert problems[0] == f"{keys}:1: [keyz]: no such table; expected [keys]"
    assert (
        problems[1].startswith(f"{keys}:6: keys.run = 'ctrl+s': also the key of ") and "save" in problems[1]
    )
    assert keymap == {"layout": "ctrl+l"}  # the clash is left out: the default stays
    # a remap refused puts its default back, which may clash with one taken before it
    keys.write_text('[keys]\nhelp = "escape"\ncancel = "f5"\n')
    keymap, problems = load_keymap(tmp_path)
    in_force = keys_in_force(keymap)
    used = [key.strip() for keys_of in in_force.values() for key in keys_of.split(",")]
    assert len(used) == len(set(used)), in_force
    assert len(problems) == 2 and "help" not in keymap and "cancel" not in keymap


def test_a_key_the_views_take_is_refused_in_keys_toml(tmp_path):
    """docs/tui.md's own example, threshold = "t", was taken without a word, and the help
    said t opens the threshold 'Anywhere'; in a 3D or top view t zooms to the target, so
    there it never did. A remap onto a view's key is now refused on its line, naming the
    view's action, and the command keeps its default key."""
    from ladartui.tui.actions import keys_in_force, load_keymap

    keys = tmp_path / "keys.toml"
    keys.write_text('[keys]\nthreshold = "t"\nrun = "f5,w"\nmeasures = "ctrl+t"\n')
    keymap, problems = load_keymap(tmp_path)
    assert keymap == {"measures": "ctrl+t"}
    assert len(problems) == 2
    assert problems[0].startswith(f"{keys}:2: keys.threshold = 't': in the views t is ")
    assert "Zoom to target" in problems[0]
    assert problems[1].startswith(f"{keys}:3: keys.run = 'f5,w': in the views w is ")
    assert keys_in_force(keymap)["threshold"] == "f8"
    # a command that does in every view what the view's key does there may take it
    keys.write_text('[keys]\nzoom-target = "t"\nfit-scene = "f"\ngrey = "g"\n')
    keymap, problems = load_keymap(tmp_path)
    assert problems == [] and keymap == {"zoom-target": "t", "fit-scene": "f", "grey": "g"}
    # "=" and "-" are bound as equals_sign and minus, the views' zoom keys: they passed
    keys.write_text('[keys]\nthreshold = "="\nrun = "-"\nundo = "equals_sign"\n')
    keymap, problems = load_keymap(tmp_path)
    assert keymap == {} and [p.split(": ")[1] for p in problems] == [
        "keys.threshold = '='",
        "keys.run = '-'",
        "keys.undo = 'equals_sign'",
    ]
    assert all("in the views" in p and "Zoom" in p for p in problems)


def test_an_unknown_command_id_in_keys_toml_is_told_with_every_id_there_is(tmp_path):
    """The ids to choose from were cut at the message's length limit, after save-as:
    zoom-target, threshold, undo and the tabs were never named. The id read from the
    file is still written safely and cut."""
    from ladartui.tui.actions import BY_ID, load_keymap

    keys = tmp_path / "keys.toml"
    keys.write_text('[keys]\nzoom-targt = "f9"\n"\\u001b[31m' + "x" * 500 + '" = "f9"\n')
    keymap, problems = load_keymap(tmp_path)
    ids = ", ".join(sorted(BY_ID))
    assert keymap == {} and len(problems) == 2
    assert problems[0] == f"{keys}:2: keys.zoom-targt: no such command; expected one of {ids}"
    assert "keys.\\x1b[31mxxx" in problems[1] and problems[1].endswith(ids)
    assert "more characters)" in problems[1] and "\x1b" not in problems[1]


def test_a_key_the_app_keeps_for_itself_is_refused_in_keys_toml(tmp_path):
    """run = "ctrl+q" was taken without a word: Ctrl+Q then ran the scenario and nothing
    quit, while the help still said Ctrl+Q quits; "ctrl+p" lost the command palette, and
    "tab" (or "ctrl+i", the terminal's Tab) the way between controls. Such a remap is
    refused on its line, naming what the key does, and the command keeps its default."""
    from ladartui.tui.actions import keys_in_force, load_keymap

    keys = tmp_path / "keys.toml"
    keys.write_text(
        '[keys]\nrun = "ctrl+q"\nmeasures = "ctrl+p"\ncompare = "f10,tab"\n'
        'threshold = "ctrl+c"\nstudy = "shift+tab"\nsweep = "ctrl+i"\nlayout = "ctrl+l"\n'
    )
    keymap, problems = load_keymap(tmp_path)
    assert keymap == {"layout": "ctrl+l"}
    assert [p.split(": ", 2)[1] for p in problems] == [
        "keys.run = 'ctrl+q'",
        "keys.measures = 'ctrl+p'",
        "keys.compare = 'f10,tab'",
        "keys.threshold = 'ctrl+c'",
        "keys.study = 'shift+tab'",
        "keys.sweep = 'ctrl+i'",
    ]
    assert problems[0] == f"{keys}:2: keys.run = 'ctrl+q': Ctrl+Q quits the app; choose another key"
    assert "Ctrl+P opens the command palette" in problems[1]
    assert "Tab moves to the next control" in problems[2]
    assert "Ctrl+I is the terminal's Tab" in problems[5]
    assert keys_in_force(keymap)["run"] == "f5"


async def test_the_screen_is_drawn_again_after_a_suspend_and_fg(tmp_path, scene_files):
    """After Ctrl+Z at the shell's level (SIGTSTP) and fg, Textual went back to the
    terminal's alternate screen, which starts blank, and drew nothing until something
    changed: the interface stayed an empty terminal. The whole screen is drawn again."""
    from textual._compositor import LayoutUpdate

    from tui_support import make_scenario, opened

    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        await pilot.pause()
        drawn = []
        display = app._display
        app._display = lambda screen, update: (drawn.append(update), display(screen, update))[1]
        app.app_resume_signal.publish(app)  # what the driver does once the app is in the foreground
        await pilot.pause()
        await pilot.pause()
        full = [u for u in drawn if isinstance(u, LayoutUpdate) and u.region == app.screen.region]
        assert full, drawn
