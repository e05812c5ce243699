"""Problems found at start-up (keys.toml, settings.toml) come in one notice that fits
an 80 x 24 screen, each problem on its own line, so the first can be read whole."""

from __future__ import annotations

from textual.widgets._toast import Toast

from ladartui.tui.actions import BY_ID
from tui_support import LadarApp, make_scenario, wait_until


def write_config(home):
    (home / "config").mkdir(parents=True)
    (home / "config" / "keys.toml").write_text('[keys]\nbogus = "f5"\nrun = 12\nlayoutx = "ctrl+r"\n')
    settings = home / "config" / "settings.toml"
    settings.write_text('[display]\ngraphics = "neon"\n')
    return (
        f"{settings}:2: display.graphics = 'neon': expected one of auto, halfblocks, "
        "characters, sixel, kitty, iterm; using auto"
    )


async def shown_toasts(app, pilot):
    await wait_until(pilot, lambda: app.screen.query(Toast), timeout=30.0)  # before they expire
    await pilot.pause()
    return list(app.screen.query(Toast))


async def test_several_start_up_problems_come_in_one_notice_that_fits_80_by_24(
    tmp_path, scene_files, monkeypatch
):
    """Four notices stacked up and ran off the top: the first one's start was unread."""
    home = tmp_path / "home"
    graphics = write_config(home)
    monkeypatch.setenv("LADARTUI_HOME", str(home))
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path, graphics_problems=[graphics])
    async with app.run_test(size=(80, 24), notifications=True) as pilot:
        toasts = await shown_toasts(app, pilot)
        assert len(toasts) == 1
        toast = toasts[0]
        assert toast.region.y >= 0 and toast.region.bottom <= 24, toast.region
        text = toast.render().plain
        assert text.startswith("4 problems at start-up, in ") and str(home / "config") in text
        lines = [" ".join(line.split()) for line in text.split("\n")]
        assert "keys.toml:2: keys.bogus: no such command" in lines
        assert "keys.toml:4: keys.layoutx: no such command" in lines
        assert any(line.startswith("keys.toml:3: keys.run = 12: expected a key name") for line in lines)
        assert any(line.startswith("settings.toml:2: display.graphics = 'neon'") for line in lines)
        assert lines[-1].startswith("Command ids: see docs/tui.md")  # no room for them all
        # every problem whole in the record, as each was told before
        assert sum(m.startswith("Key not remapped: ") for m in app.messages) == 3
        assert f"Settings: {graphics}" in app.messages


async def test_the_command_ids_are_told_once_where_the_notice_has_room(tmp_path, scene_files, monkeypatch):
    home = tmp_path / "home"
    graphics = write_config(home)
    monkeypatch.setenv("LADARTUI_HOME", str(home))
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path, graphics_problems=[graphics])
    async with app.run_test(size=(120, 40), notifications=True) as pilot:
        toasts = await shown_toasts(app, pilot)
        assert len(toasts) == 1 and toasts[0].region.y >= 0
        text = " ".join(toasts[0].render().plain.split())
        assert text.count("zoom-target") == 1 and f"Command ids: {', '.join(sorted(BY_ID))}" in text
