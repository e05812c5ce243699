"""How the views reach the terminal: the mode chosen from the terminal's environment,
the setting that forces it, the 256-colour fallback, and the image widget in the app."""

from __future__ import annotations

import io
import re
import time

import numpy as np
import pytest
from rich.console import Console

from ladartui.tui.graphics import Graphics, choose, read_setting
from ladartui.views import Picture

KITTY = {"TERM": "xterm-kitty", "KITTY_WINDOW_ID": "1", "COLORTERM": "truecolor"}


class Probe:
    """Stands in for asking the terminal; records whether it was asked."""

    def __init__(self, answer):
        self.answer = answer
        self.calls = 0

    def __call__(self):
        self.calls += 1
        return self.answer


@pytest.mark.parametrize(
    "env, answer, mode",
    [
        (KITTY, None, "kitty"),
        # ssh forwards TERM, not KITTY_WINDOW_ID
        ({"TERM": "xterm-kitty", "SSH_CONNECTION": "10.0.0.1 5 10.0.0.2 22"}, None, "kitty"),
        ({"TERM": "xterm-256color", "TERM_PROGRAM": "iTerm.app", "COLORTERM": "truecolor"}, None, "iterm"),
        # iTerm2 over ssh: LC_TERMINAL travels with the locale variables
        ({"TERM": "xterm-256color", "LC_TERMINAL": "iTerm2", "SSH_TTY": "/dev/pts/1"}, None, "iterm"),
        ({"TERM": "xterm-256color", "TERM_PROGRAM": "WezTerm"}, "sixel", "sixel"),
        ({"TERM": "foot"}, "sixel", "sixel"),
        ({"TERM": "xterm-256color", "SSH_CONNECTION": "x"}, "kitty", "kitty"),
        ({"TERM": "xterm-256color", "SSH_CONNECTION": "x"}, None, "halfblocks"),
        ({"TERM": "xterm-256color"}, None, "halfblocks"),
    ],
)
def test_auto_picks_images_only_where_the_terminal_shows_them(env, answer, mode):
    probe = Probe(answer)
    graphics = choose("auto", env, True, probe)
    assert graphics.mode == mode
    assert graphics.image == (mode != "halfblocks")


@pytest.mark.parametrize(
    "env",
    [
        {"TERM": "tmux-256color", "TMUX": "/tmp/tmux-0/default,1,0", "COLORTERM": "truecolor"},
        # tmux inside kitty: kitty's variables are inherited, its graphics are not passed
        {"TERM": "screen-256color", "TMUX": "/tmp/t,1,0", "KITTY_WINDOW_ID": "3", "TERM_PROGRAM": "tmux"},
        {"TERM": "screen", "STY": "1234.pts-0.host"},
        {"TERM": "tmux-256color"},  # tmux over ssh: TMUX is not forwarded, TERM is
    ],
)
def test_tmux_and_screen_get_half_blocks_without_asking_the_terminal(env):
    probe = Probe("sixel")
    graphics = choose("auto", env, True, probe)
    assert graphics.mode == "halfblocks"
    assert probe.calls == 0
    assert "tmux" in graphics.reason


def test_not_a_terminal_or_a_plain_console_gets_half_blocks_without_asking():
    probe = Probe("sixel")
    assert choose("auto", KITTY, False, probe).mode == "halfblocks"
    assert choose("auto", {"TERM": "linux"}, True, probe).mode == "halfblocks"
    assert probe.calls == 0


@pytest.mark.parametrize("term", ["vt220", "vt100", "dumb"])
def test_a_terminal_without_block_glyphs_gets_plain_characters_without_asking(term):
    probe = Probe("sixel")
    graphics = choose("auto", {"TERM": term}, True, probe)
    assert graphics.mode == "characters" and not graphics.image
    assert probe.calls == 0
    assert graphics.describe().startswith("plain characters, 256 colours")


def test_plain_characters_draw_each_pixel_as_two_coloured_spaces():
    from ladartui.tui.canvas import character_strips

    rgb = np.zeros((2, 3, 3), np.uint8)
    rgb[0, 0] = (255, 0, 0)
    rgb[1, 2] = (0, 0, 255)
    mask = np.zeros((2, 3), bool)
    mask[0, 0] = mask[1, 2] = True
    strips = character_strips(Picture(rgb, mask))
    assert [strip.cell_length for strip in strips] == [6, 6]
    assert all(seg.text.strip() == "" for strip in strips for seg in strip)  # no glyphs at all
    coloured = [
        (row, seg.style.bgcolor.triplet.hex)
        for row, strip in enumerate(strips)
        for seg in strip
        if seg.style is not None and seg.style.bgcolor is not None
    ]
    assert coloured == [(0, "#ff0000"), (1, "#0000ff")]
    # where the pixel sits: two cells per pixel, so the blue one starts at cell 4
    assert strips[1].crop(4, 6).text == "  " and strips[1].crop(0, 4).cell_length == 4
    text = _ansi(character_strips(Picture(rgb, mask), use_256=True), "256")
    assert "48;5;" in text and "48;2;" not in text and "\u2580" not in text


def test_colour_depth_follows_colorterm():
    assert choose("auto", {"TERM": "xterm-256color", "COLORTERM": "truecolor"}, True, Probe(None)).truecolor
    assert choose("auto", {"TERM": "xterm-256color", "COLORTERM": "24bit"}, True, Probe(None)).truecolor
    assert not choose("auto", {"TERM": "xterm-256color"}, True, Probe(None)).truecolor
    assert not choose("auto", {"TERM": "tmux-256color", "TMUX": "x"}, True, Probe(None)).truecolor


@pytest.mark.parametrize("mode", ["halfblocks", "sixel", "kitty", "iterm"])
def test_a_forced_mode_wins_everywhere_without_asking(mode):
    probe = Probe("kitty")
    for env in (KITTY, {"TERM": "tmux-256color", "TMUX": "x"}, {}):
        graphics = choose(mode, env, True, probe)
        assert graphics.mode == mode
        assert graphics.reason == f"set to {mode}"
    assert probe.calls == 0


def test_the_setting_is_read_from_settings_toml(tmp_path):
    assert read_setting(tmp_path) == ("auto", [])
    (tmp_path / "settings.toml").write_text('# mine\n[display]\ngraphics = "Sixel"\n')
    assert read_setting(tmp_path) == ("sixel", [])


@pytest.mark.parametrize(
    "text, expected",
    [
        (
            '[display]\n\ngraphics = "retina"\n',
            r"settings\.toml:3: display\.graphics = .retina.: expected one of ",
        ),
        ("[display]\ngraphics = 3\n", r"settings\.toml:2: display\.graphics = 3: expected one of "),
        ('[display\ngraphics = "kitty"\n', r"settings\.toml:1: not valid TOML: [^(]*$"),
        ('display = "kitty"\n', r"settings\.toml:1: display must be a table"),
    ],
)
def test_a_bad_setting_is_one_line_naming_the_file_and_line(tmp_path, text, expected):
    (tmp_path / "settings.toml").write_text(text)
    setting, problems = read_setting(tmp_path)
    assert setting == "auto"
    assert len(problems) == 1 and "\n" not in problems[0]
    assert problems[0].startswith(str(tmp_path / "settings.toml"))
    assert re.search(expected, problems[0]), problems[0]


def _picture(rgb) -> Picture:
    rgb = np.asarray(rgb, np.uint8)
    return Picture(rgb, np.ones(rgb.shape[:2], bool))


def _ansi(strips, color_system):
    """What Textual writes for these strips to a terminal of that colour system."""
    console = Console(file=io.StringIO(), color_system=color_system, force_terminal=True)
    return "".join(strip.render(console) for strip in strips)


def test_the_256_colour_fallback_writes_no_truecolour_escapes():
    from ladartui.tui.canvas import picture_strips

    ramp = np.stack(np.meshgrid(np.arange(0, 256, 16), np.arange(0, 256, 32)), -1)
    rgb = np.concatenate([ramp, np.full(ramp.shape[:2] + (1,), 90)], -1)
    strips = picture_strips(_picture(rgb), use_256=True)
    text = _ansi(strips, "256")
    assert "38;5;" in text and "48;5;" in text
    assert "38;2;" not in text and "48;2;" not in text
    # the fallback keeps the picture readable: distinct colours stay distinct
    codes = set(re.findall(r"38;5;(\d+)", text))
    assert len(codes) >= 20
    # and 24-bit colour where the terminal has it
    assert "38;2;" in _ansi(picture_strips(_picture(rgb)), "truecolor")


async def _loaded(pilot):
    start = time.monotonic()
    while pilot.app.scene is None or pilot.app.busy is not None:
        assert time.monotonic() - start < 120, "the app did not load the scene"
        await pilot.pause(0.05)
    await pilot.pause(0.2)


async def _image_drawn_at_size(pilot, view):
    """Wait (up to 30 s) until ``view``'s image is drawn at its picture size."""
    start = time.monotonic()
    while True:
        image = view.image_view.image
        if image is not None and (image.height, image.width) == view.picture_size():
            return
        assert time.monotonic() - start < 30, "the view's image was not redrawn at its new size"
        await pilot.pause(0.05)


@pytest.mark.parametrize("mode", ["kitty", "sixel", "iterm", "halfblocks-24bit", "halfblocks-256"])
async def test_the_views_are_images_when_an_image_mode_is_forced_and_half_blocks_otherwise(
    tmp_path, scene_files, mode, monkeypatch
):
    from textual_image.widget import SixelImage, TGPImage

    from ladartui.tui.app import LadarApp, help_rows
    from ladartui.tui.canvas import PictureWidget
    from tui_support import make_scenario

    colours = None
    if mode.startswith("halfblocks"):
        mode, colours = mode.split("-")
        # the terminal's colour depth as rich (and so Textual) reads it
        monkeypatch.setenv("TERM", "xterm-256color")
        if colours == "24bit":
            monkeypatch.setenv("COLORTERM", "truecolor")
        else:
            monkeypatch.delenv("COLORTERM", raising=False)
    scenario = make_scenario(tmp_path, scene_files)
    graphics = Graphics(mode, True, f"set to {mode}")
    app = LadarApp(scenario.path, compile_in_child=False, graphics=graphics)
    async with app.run_test(size=(120, 40)) as pilot:
        await _loaded(pilot)
        app.action_layout(5)
        await pilot.pause(0.3)
        views = list(app.query(PictureWidget))
        assert len(views) == 3
        # the help screen says how the views are drawn and why
        assert ("Views", "settings.toml", "Drawn as " + graphics.describe()) in help_rows(app)
        for view in views:
            if mode == "halfblocks":
                assert view.image_view is None and not view.query(TGPImage) and not view.query(SixelImage)
                continue
            kind = {"kitty": TGPImage, "sixel": SixelImage, "iterm": SixelImage}[mode]
            assert isinstance(view.image_view, kind)
            assert (
                type(view.image_view).__name__
                == {"kitty": "TGPImage", "sixel": "Image", "iterm": "ITermImage"}[mode]
            )
        scene3d = app.query_one("#scene3d", PictureWidget)
        if mode == "halfblocks":  # the text path draws half-block cells
            rows = [scene3d.render_line(y) for y in range(scene3d.size.height)]
            assert sum("\u2580" in seg.text or "\u2584" in seg.text for row in rows for seg in row) > 20
            # what reaches the terminal: 24-bit colours only where COLORTERM says so
            written = "".join(row.render(app.console) for row in rows)
            assert ("38;2;" in written) == (colours == "24bit")
            assert ("38;5;" in written) == (colours == "256")
            return
        # the image is the view's picture at the terminal's pixels (10 x 20 a cell when
        # the terminal cannot be asked), not the half-block picture; on a busy machine
        # the new layout's image may come after the pause above
        await _image_drawn_at_size(pilot, scene3d)
        image = scene3d.image_view.image
        assert scene3d.image_view.display and image is not None
        width, height = scene3d.size
        assert (image.height, image.width) == scene3d.picture_size() == (height * 20, width * 10)
        rgb = np.asarray(image)
        picture = scene3d.make_picture(height * 20, width * 10)
        assert np.array_equal(rgb, picture.rgb)
        assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 20  # a real picture, not a blank
        # no half-block text under the image
        assert all(seg.text.strip() == "" for y in range(height) for seg in scene3d.render_line(y))
        # a change of framing draws a new image
        scene3d.post_message(PictureWidget.ViewRequest("fit_target"))
        await pilot.pause(0.3)
        assert not np.array_equal(np.asarray(scene3d.image_view.image), rgb)


async def test_the_views_draw_plain_characters_when_that_mode_is_forced(tmp_path, scene_files):
    from ladartui.tui.app import LadarApp
    from ladartui.tui.canvas import PictureWidget
    from tui_support import make_scenario

    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path, compile_in_child=False, graphics=Graphics("characters", False, "set"))
    async with app.run_test(size=(120, 40)) as pilot:
        await _loaded(pilot)
        app.action_layout(5)
        await pilot.pause(0.3)
        scene3d = app.query_one("#scene3d", PictureWidget)
        width, height = scene3d.size
        # one square pixel every two cells, a pixel row a cell row
        assert scene3d.picture_size() == (height, width // 2)
        rows = [scene3d.render_line(y) for y in range(height)]
        assert all(row.cell_length == width for row in rows)
        assert not any("\u2580" in seg.text or "\u2584" in seg.text for row in rows for seg in row)
        painted = sum(
            seg.cell_length for row in rows for seg in row if seg.style and seg.style.bgcolor is not None
        )
        assert painted > width * height // 10  # the scene is drawn, as coloured cells


def test_an_iterm2_image_is_the_pictures_png_stretched_over_its_cells():
    import base64

    from PIL import Image

    from ladartui.tui.terminal_image import iterm_sequence, to_pil

    rgb = np.zeros((40, 30, 3), np.uint8)
    rgb[5:10, 3:7] = (255, 0, 255)
    sequence = iterm_sequence(to_pil(rgb), cols=3, rows=2)
    assert sequence.startswith("\x1b]1337;File=inline=1;") and sequence.endswith("\x07")
    header, data = sequence[len("\x1b]1337;File=") : -1].split(":", 1)
    fields = dict(item.split("=") for item in header.split(";"))
    assert fields["width"] == "3" and fields["height"] == "2" and fields["preserveAspectRatio"] == "0"
    png = base64.b64decode(data)
    assert int(fields["size"]) == len(png)
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(png)).convert("RGB")), rgb)


def test_the_command_line_flag_forces_the_mode_for_one_session(monkeypatch, capsys):
    import ladartui.tui
    from ladartui import cli

    calls = []
    monkeypatch.setattr(ladartui.tui, "run_app", lambda path, graphics=None: calls.append((path, graphics)))
    monkeypatch.setattr("ladartui.cli.tui.on_a_terminal", lambda: True)
    assert cli.main(["--graphics", "kitty"]) == 0
    assert cli.main(["--graphics=halfblocks"]) == 0
    assert cli.main(["tui", "--graphics", "sixel"]) == 0
    assert calls == [(None, "kitty"), (None, "halfblocks"), (None, "sixel")]
    with pytest.raises(SystemExit) as stop:
        cli.main(["--graphics", "retina"])
    assert stop.value.code == 2
    error = capsys.readouterr().err.strip()
    assert "\n" not in error and "invalid choice: 'retina'" in error and "iterm" in error


def test_the_interface_without_a_terminal_is_refused_in_one_line(monkeypatch, capsys):
    """'ladartui S.toml > log' (or with no terminal at all) drew the interface's escape
    codes into the file and waited for keys that never came."""
    import sys

    import ladartui.tui
    from ladartui import cli

    calls = []
    monkeypatch.setattr(ladartui.tui, "run_app", lambda path, graphics=None: calls.append(path))
    monkeypatch.setattr(sys, "__stdout__", io.StringIO())  # a file or pipe: no terminal
    assert cli.main([]) == 2
    assert capsys.readouterr().err == (
        "ladartui: error: the terminal UI needs a terminal, and its input or output is a file "
        "or pipe; for a run without one: ladartui run SCENARIO\n"
    )
    assert calls == []


def test_detect_puts_the_flag_over_the_settings_file(tmp_path, monkeypatch):
    from ladartui.tui.graphics import detect

    (tmp_path / "settings.toml").write_text('[display]\ngraphics = "kitty"\n')
    graphics, problems = detect(folder=tmp_path)
    assert (graphics.mode, graphics.reason, problems) == ("kitty", "set to kitty", [])
    graphics, _ = detect("halfblocks", folder=tmp_path)
    assert graphics.mode == "halfblocks" and graphics.seconds >= 0.0
    (tmp_path / "settings.toml").write_text('[display]\ngraphics = "retina"\n')
    monkeypatch.setenv("TMUX", "/tmp/tmux-0/default,1,0")  # auto never asks a terminal here
    graphics, problems = detect(folder=tmp_path)
    assert graphics.mode == "halfblocks"  # auto
    assert len(problems) == 1 and "settings.toml:2:" in problems[0]


def test_a_misspelt_setting_or_a_file_nested_too_deep_is_reported(tmp_path):
    """'graphic = "sixel"' and [displays] were ignored without a word; a file nested 3000
    deep printed a RecursionError traceback of 3000 lines."""
    path = tmp_path / "settings.toml"
    path.write_text('[displays]\nx = 1\n\n[display]\ngraphic = "sixel"\n')
    setting, problems = read_setting(tmp_path)
    assert setting == "auto"
    assert problems == [
        f"{path}:1: [displays]: no such table; expected [display]",
        f"{path}:5: display.graphic: no such setting; expected graphics",
    ]
    path.write_text("a = " + "[" * 3000 + "]" * 3000 + "\n")
    assert read_setting(tmp_path) == ("auto", [f"{path}: nested too deep to read"])


@pytest.mark.parametrize("mode", ["halfblocks", "characters"])
async def test_the_views_draw_in_greys_where_no_color_is_set(tmp_path, scene_files, monkeypatch, mode):
    """NO_COLOR (Textual reads it) turns every colour grey; the app opened with it had
    stopped on its first frame with a traceback, the views' blank cells having no style."""
    from textual.geometry import Region

    from ladartui.tui.app import LadarApp
    from ladartui.tui.canvas import PictureWidget
    from tui_support import make_scenario

    monkeypatch.setenv("NO_COLOR", "1")
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path, compile_in_child=False, graphics=Graphics(mode, False, "set"))
    async with app.run_test(size=(120, 40)) as pilot:
        assert app.no_color
        await _loaded(pilot)
        for layout in (1, 2, 3, 4, 5):  # each view drawn, the output's placeholder too
            app.action_layout(layout)
            await pilot.pause(0.2)
        for view in app.query(PictureWidget):
            width, height = view.size
            # the view's lines as they reach the terminal, NO_COLOR's filter applied
            strips = view.render_lines(Region(0, 0, width, height))
            colours = {
                colour.get_truecolor()
                for strip in strips
                for seg in strip
                if seg.style is not None
                for colour in (seg.style.color, seg.style.bgcolor)
                if colour is not None
            }
            assert all(r == g == b for r, g, b in colours), view.id
            if view.id != "output3d":  # nothing run: the output view is its placeholder
                assert len(colours) > 5, view.id  # the picture is drawn, in several greys
    assert app.return_code in (None, 0)


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_the_interface_with_standard_error_sent_to_a_file_is_refused_in_one_line(monkeypatch, capsys):
    """'ladartui 2>errors.log' (or 2>/dev/null) opened the interface on a blank terminal:
    Textual draws on standard error, so its screens went into the file while it waited
    for keys typed blind."""
    import sys

    import ladartui.tui
    from ladartui import cli

    calls = []
    monkeypatch.setattr(ladartui.tui, "run_app", lambda path, graphics=None: calls.append(path))
    monkeypatch.setattr(sys, "__stdin__", _Terminal())
    monkeypatch.setattr(sys, "__stdout__", _Terminal())
    monkeypatch.setattr(sys, "__stderr__", io.StringIO())  # 2>errors.log
    assert cli.main([]) == 2
    assert capsys.readouterr().err == (
        "ladartui: error: the terminal UI draws on standard error, and it is a file or pipe "
        "(2>FILE); run it with standard error on the terminal, or for a run without one: "
        "ladartui run SCENARIO\n"
    )
    assert calls == []
    monkeypatch.setattr(sys, "__stderr__", _Terminal())  # all three on the terminal: it opens
    assert cli.main([]) == 0 and calls == [None]
