"""The segment dialogs as an analyst meets them: which field a refusal names, in what
order, and where the dialog stays while its message changes."""

from __future__ import annotations

from ladartui.tui.screens import FormScreen
from test_tui_dialogs import message
from tui_support import make_scenario, opened, screen_after, type_into, wait_until


async def edited_first_segment(app, pilot) -> FormScreen:
    app.action_show_tab("flight")
    await pilot.pause()
    return await screen_after(pilot, app.action_edit_segment, FormScreen)


async def pressed_ok(form, pilot) -> str:
    form.query_one("#form-ok").press()
    await pilot.pause()
    return message(form)


async def test_an_orbit_centred_past_the_limit_names_the_centre(tmp_path, scene_files):
    """Centre 1e6,1,2 said 'Radius m: 60 is not allowed; expected a radius that puts
    every scan within 1000000 m of the scene's origin': the radius was fine."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await edited_first_segment(app, pilot)
        centre, radius = form.query_one("#f-centre"), form.query_one("#f-radius")
        await type_into(pilot, centre, "1e6,1,2", commit="enter")
        said = message(form)
        assert said.startswith("Centre x,y,z m: 1e6,1,2 is not allowed; expected a centre"), said
        assert "Radius" not in said and app.focused is centre
        assert centre.has_class("-bad") and not radius.has_class("-bad")
        # a radius past the limit around a centre near the origin is still the radius's
        await type_into(pilot, centre, "1,1,2", commit=None)
        await type_into(pilot, radius, "1000000", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Radius m: 1000000 is not allowed;")


async def test_several_wrong_fields_are_named_top_first(tmp_path, scene_files):
    """A wrong radius was named before a wrong centre above it: the number fields were
    checked before the points."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await edited_first_segment(app, pilot)
        centre, radius = form.query_one("#f-centre"), form.query_one("#f-radius")
        await type_into(pilot, radius, "-7", commit=None)
        await type_into(pilot, form.query_one("#f-altitude"), "0", commit=None)
        await type_into(pilot, centre, "a,b,c", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Centre x,y,z m: a,b,c is not allowed;")
        assert app.focused is centre
        await type_into(pilot, centre, "1,1,2", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Radius m: -7 is not allowed;")
        assert app.focused is radius
        await type_into(pilot, radius, "30", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Altitude m: 0 is not allowed;")


async def added(app, pilot, kind: str) -> FormScreen:
    app.action_show_tab("flight")
    await pilot.pause()
    return await screen_after(pilot, lambda: app.action_add_segment(kind), FormScreen)


async def test_an_aim_point_with_a_sensor_pointing_is_refused_naming_both(tmp_path, scene_files):
    """Sensor az 3 and Depression 45 with Aim 1,2: OK took all three and the scans looked
    at the aim (az 114, dep 35), the pointing typed dropped without a word."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        for kind in ("straight", "turn"):
            form = await added(app, pilot, kind)
            aim = form.query_one("#f-aim_at")
            assert "z 0 if left out" in str(aim.placeholder)  # '1,2' is kept as 1, 2, 0
            await type_into(pilot, form.query_one("#f-azimuth"), "3", commit=None)
            await type_into(pilot, form.query_one("#f-depression"), "45", commit=None)
            await type_into(pilot, aim, "1,2", commit=None)
            said = await pressed_ok(form, pilot)
            assert said == (
                "Aim at x,y,z m: 1,2 is not allowed; expected no aim point while Sensor az deg "
                "and Depression deg are given (an aim point sets both)"
            )
            assert app.screen is form and app.focused is aim and len(app.scenario.flight.segments) == 1
            await type_into(pilot, form.query_one("#f-depression"), "", commit=None)
            assert (await pressed_ok(form, pilot)).endswith(
                "while Sensor az deg is given (an aim point sets both)"
            )
            await type_into(pilot, form.query_one("#f-azimuth"), "", commit=None)
            form.query_one("#form-ok").press()
            await pilot.pause()
            assert app.screen is not form
            segment = app.scenario.flight.segments[-1]
            assert segment.aim_at == (1.0, 2.0, 0.0) and segment.azimuth is None is segment.depression
            app.action_undo()
            await pilot.pause()


async def test_aim_all_leaves_no_sensor_pointing_beside_the_aim(tmp_path, scene_files):
    """Aim all gave a straight with a sensor pointing an aim point too: its form then
    refused its own values on OK."""
    from ladartui.flight import Straight
    from ladartui.tui import bridge

    scenario = make_scenario(tmp_path, scene_files)
    pointed = bridge.with_segments(scenario, [*scenario.flight.segments, Straight(50.0, 2, 10.0, 30.0)])
    aimed = bridge.aim_all(pointed, (1.0, 2.0, 0.0))
    straight = aimed.flight.segments[-1]
    assert straight.aim_at == (1.0, 2.0, 0.0) and straight.azimuth is None is straight.depression
    unpointed = bridge.with_segments(scenario, [*scenario.flight.segments, Straight(50.0, 2)])
    assert aimed.poses() == bridge.aim_all(unpointed, (1.0, 2.0, 0.0)).poses()  # the scans are the same


async def test_aim_all_clears_a_flight_log_s_own_pointing_too(tmp_path, scene_files):
    """A log's pointing beside an aim point is refused, as a manoeuvre's is, so aiming
    a log must clear it, not keep it for the scenario to refuse."""
    from ladartui.trajectory import LogSegment
    from ladartui.tui import bridge

    scenario = make_scenario(tmp_path, scene_files)
    (tmp_path / "log.csv").write_text("time,x,y,z,heading\n0,0,0,60,0\n1,10,0,60,0\n")
    log = LogSegment(str(tmp_path / "log.csv"), rate=1.0, azimuth=30.0, depression=45.0)
    aimed = bridge.aim_all(bridge.with_segments(scenario, [log]), (1.0, 2.0, 0.0))
    segment = aimed.flight.segments[0]
    assert segment.aim_at == (1.0, 2.0, 0.0) and segment.azimuth is None is segment.depression
    assert (
        aimed.poses()
        == bridge.aim_all(
            bridge.with_segments(scenario, [LogSegment(log.file, rate=1.0)]), (1.0, 2.0, 0.0)
        ).poses()
    )


async def test_a_segment_form_stays_put_as_its_message_changes(tmp_path, scene_files):
    """A two-line message, then a one-line one, moved the whole dialog up and down a row,
    so a click meant for one field landed on the next."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        form = await added(app, pilot, "straight")
        widgets = [*form.query(".form Input"), *form.query("Button")]

        def places():
            return [(w.id, w.region.x, w.region.y) for w in widgets]

        await pilot.pause()
        before = places()
        await type_into(pilot, form.query_one("#f-distance"), "-100", commit=None)
        said = await pressed_ok(form, pilot)
        assert len(said) > 72  # two lines in the dialog
        assert places() == before
        await type_into(pilot, form.query_one("#f-distance"), "100", commit=None)
        await type_into(pilot, form.query_one("#f-scans"), "0", commit=None)
        assert len(await pressed_ok(form, pilot)) < 72
        assert places() == before


async def test_enter_in_a_lower_wrong_field_names_the_upper_one_it_focuses(tmp_path, scene_files):
    """Distance -5 and Depression '[red]x', Enter in the depression: the cursor went to
    the distance while the message named the depression (the field it left said why
    over the refusal)."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await added(app, pilot, "straight")
        distance, depression = form.query_one("#f-distance"), form.query_one("#f-depression")
        await type_into(pilot, distance, "-5", commit=None)
        await type_into(pilot, depression, "[red]x", commit="enter")
        await pilot.pause()
        assert app.focused is distance
        assert message(form).startswith("Distance m: -5 is not allowed;"), message(form)
        assert distance.has_class("-bad") and depression.has_class("-bad")
        # the depression is named once the distance is right
        await type_into(pilot, distance, "50", commit="enter")
        await pilot.pause()
        assert app.focused is depression
        assert message(form) == "Depression deg: [red]x is not allowed; expected a number from 1 to 90 deg"


async def test_ok_on_a_segment_form_keeps_the_values_it_was_not_given(tmp_path, scene_files):
    """OK on an orbit's form, nothing typed, wrote every value as the form shows it, to
    six digits: a radius of 30.123456789 came back 30.1235, a centre 1.23456789 1.23457."""
    from ladartui.flight import FlightPlan, Orbit

    scenario = make_scenario(tmp_path, scene_files)
    exact = Orbit(centre=(1.23456789, 2.0, 0.5), radius=30.123456789, altitude=30.0, scans=6)
    scenario = scenario.with_changes(flight=FlightPlan(None, (exact,))).save()
    async with opened(scenario) as (app, pilot):
        form = await edited_first_segment(app, pilot)
        assert form.query_one("#f-radius").value == "30.1235"  # shown to six digits
        form.query_one("#form-ok").press()
        await wait_until(pilot, lambda: app.screen is not form, timeout=10.0)
        assert app.scenario.flight.segments[0] == exact
        form = await edited_first_segment(app, pilot)
        await type_into(pilot, form.query_one("#f-altitude"), "35", commit=None)
        await type_into(pilot, form.query_one("#f-centre"), "1.5, 2, 0.5", commit=None)
        form.query_one("#form-ok").press()
        await wait_until(pilot, lambda: app.screen is not form, timeout=10.0)
        orbit = app.scenario.flight.segments[0]
        assert (orbit.radius, orbit.altitude, orbit.centre) == (exact.radius, 35.0, (1.5, 2.0, 0.5))


async def test_a_refusal_is_cleared_once_its_field_is_put_right(tmp_path, scene_files):
    """After OK refused a distance of -100, typing 100 left 'Distance m: -100 is not
    allowed' under the form until the next OK, as if it still were."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario) as (app, pilot):
        form = await added(app, pilot, "straight")
        await type_into(pilot, form.query_one("#f-distance"), "-100", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Distance m: -100 is not allowed")
        await type_into(pilot, form.query_one("#f-distance"), "-5", commit=None)  # still wrong: still said
        assert message(form).startswith("Distance m: -100 is not allowed")
        await type_into(pilot, form.query_one("#f-distance"), "100", commit=None)
        assert message(form) == ""
        await type_into(pilot, form.query_one("#f-aim_at"), "1,", commit=None)
        assert (await pressed_ok(form, pilot)).startswith("Aim at x,y,z m: 1, is not allowed")
        await type_into(pilot, form.query_one("#f-aim_at"), "1, 2", commit=None)
        assert message(form) == ""
