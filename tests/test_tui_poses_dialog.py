"""The manual poses dialog reads as the segment forms do: "(new)" in its title for a
new segment, and its fields' units in their labels, so a refusal gives its limits in
metres or degrees."""

from __future__ import annotations

from ladartui.flight import FlightPlan, Manual, ScanPose
from ladartui.tui.poses_screen import PosesScreen
from tui_support import make_scenario, opened, type_into, wait_until


def title_of(screen) -> str:
    return str(screen.query_one(".dialog").border_title)


async def test_the_poses_dialog_says_new_and_gives_its_fields_units(tmp_path, scene_files):
    """Its title was 'Manual scan poses' for a new segment too, and 'x: abc is not
    allowed; expected a number from -1000000 to 1000000' had no unit."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_manual_poses()
        await wait_until(
            pilot, lambda: isinstance(app.screen, PosesScreen) and app.screen.query("#p-x"), timeout=10.0
        )
        screen = app.screen
        assert title_of(screen) == "Manual scan poses (new)"
        labels = [str(label.render()) for label in screen.query("#pose-fields Label")]
        assert labels == ["x m", "y m", "z m", "Heading deg", "Sensor az deg", "Depression deg"]
        await type_into(pilot, screen.query_one("#p-x"), "abc", commit="tab")
        said = str(screen.query_one("#poses-message").render())
        assert said == "x m: abc is not allowed; expected a number from -1000000 to 1000000 m", said
        await type_into(pilot, screen.query_one("#p-depression"), "200", commit="tab")
        said = str(screen.query_one("#poses-message").render())
        assert said.startswith("Depression deg: 200 is not allowed") and said.endswith(" deg"), said


async def test_the_poses_dialog_for_a_manual_segment_is_not_new(tmp_path, scene_files):
    scenario = make_scenario(tmp_path, scene_files)
    segments = (Manual((ScanPose(0.0, 0.0, 40.0),)),)
    scenario = scenario.with_changes(flight=FlightPlan(None, segments)).save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_manual_poses()  # the selected segment is the manual one
        await wait_until(
            pilot, lambda: isinstance(app.screen, PosesScreen) and app.screen.query("#p-x"), timeout=10.0
        )
        assert title_of(app.screen) == "Manual scan poses"


async def test_the_poses_dialog_takes_altitudes_up_to_the_flight_limit(tmp_path, scene_files):
    """The dialog took z = 50000 (its limit was 100000 m), where the start field, the
    segment forms and New allow at most 20000 m up."""
    scenario = make_scenario(tmp_path, scene_files)
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_manual_poses()
        await wait_until(
            pilot, lambda: isinstance(app.screen, PosesScreen) and app.screen.query("#p-z"), timeout=10.0
        )
        screen = app.screen
        await type_into(pilot, screen.query_one("#p-z"), "50000", commit="tab")
        said = str(screen.query_one("#poses-message").render())
        assert said == "z m: 50000 is not allowed; expected a number greater than 0 and at most 20000 m", said
        assert screen.query_one("#p-z").has_class("-bad")
        await type_into(pilot, screen.query_one("#p-z"), "20000", commit="tab")
        assert str(screen.query_one("#poses-message").render()) == ""


async def test_a_row_applied_keeps_the_values_of_the_fields_left_as_shown(tmp_path, scene_files):
    """Applying a row after typing its z wrote x and y as the fields show them, to six
    digits: y = -53.934467 came back -53.9345."""
    scenario = make_scenario(tmp_path, scene_files)
    exact = ScanPose(12.3456789, -53.93446712, 40.0, 33.3333333, 0.0, 61.7777777)
    scenario = scenario.with_changes(flight=FlightPlan(None, (Manual((exact,)),))).save()
    async with opened(scenario, size=(80, 24)) as (app, pilot):
        app.action_manual_poses()
        await wait_until(
            pilot, lambda: isinstance(app.screen, PosesScreen) and app.screen.query("#p-z"), timeout=10.0
        )
        screen = app.screen
        assert screen.query_one("#p-y").value == "-53.9345"  # shown to six digits
        await type_into(pilot, screen.query_one("#p-z"), "45", commit="enter")
        assert screen.poses == [ScanPose(exact.x, exact.y, 45.0, exact.heading, 0.0, exact.depression)]
        await type_into(pilot, screen.query_one("#p-y"), "-53.9", commit="enter")  # typed: as typed
        assert screen.poses[0].y == -53.9 and screen.poses[0].x == exact.x
