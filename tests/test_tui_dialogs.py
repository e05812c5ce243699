"""The app's dialogs as an analyst meets them: what a refused value says and where.

Each test drives a real app on a tiny generated scene with Pilot.
"""

from __future__ import annotations

from ladartui.tui.screens import FormScreen, PosesScreen
from test_tui_flow import LadarApp, loaded, make_scenario, type_into, wait_until

SIZE = (100, 32)


def message(screen, selector="#form-message") -> str:
    return str(screen.query_one(selector).render())


async def test_a_segment_form_names_the_point_field_that_is_wrong(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        app.action_add_segment("orbit")
        await pilot.pause()
        form = app.screen
        assert isinstance(form, FormScreen)
        centre, radius = form.query_one("#f-centre"), form.query_one("#f-radius")
        await type_into(pilot, centre, "a,b,c", commit="tab")
        form.query_one("#form-ok").press()
        await pilot.pause()
        # refused, naming the centre and what was typed there; the radius is not blamed
        assert app.screen is form and app.focused is centre
        said = message(form)
        assert said.startswith("Centre x,y,z m: a,b,c is not allowed; expected ") and "Radius" not in said
        assert not radius.has_class("-bad") and centre.has_class("-bad")
        await type_into(pilot, centre, "1,2,3,4", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert message(form) == "Centre x,y,z m: 1,2,3,4 is not allowed; expected x, y, z in metres"
        await type_into(pilot, centre, "10, 20, 0", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is not form
        assert app.scenario.flight.segments[-1].centre == (10.0, 20.0, 0.0)


async def test_an_empty_list_field_says_empty(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_show_tab("flight")
        app.action_add_segment("standoff")
        await pilot.pause()
        form = app.screen
        await type_into(pilot, form.query_one("#f-standoffs"), "", commit=None)
        form.query_one("#form-ok").press()
        await pilot.pause()
        assert app.screen is form
        assert message(form).startswith("Standoffs m: empty is not allowed; expected ")


async def test_the_poses_dialog_keeps_a_refused_value_and_ok_applies_the_row(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    app = LadarApp(scenario.path)
    async with app.run_test(size=SIZE) as pilot:
        await wait_until(pilot, lambda: loaded(app))
        app.action_manual_poses()
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, PosesScreen)
        x = screen.query_one("#p-x")
        await type_into(pilot, x, "xyz", commit="tab")
        # left marked with the text kept, and OK refuses, saying why
        assert x.value == "xyz" and x.has_class("-bad")
        screen.query_one("#poses-ok").press()
        await pilot.pause()
        assert app.screen is screen and app.focused is x
        assert message(screen, "#poses-message") == "x: xyz is not allowed; expected a number"
        screen.query_one("#pose-apply").press()
        await pilot.pause()
        assert app.screen is screen and x.value == "xyz"
        # a good value typed and not applied is not lost: OK applies the row first
        await type_into(pilot, x, "12.5", commit=None)
        screen.query_one("#poses-ok").press()
        await pilot.pause()
        assert app.screen is not screen
        assert app.scenario.flight.segments[-1].kind == "manual"
        assert app.scenario.flight.segments[-1].poses[0].x == 12.5
