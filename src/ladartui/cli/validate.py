"""``ladartui validate SCENARIO``: load and check a scenario and its model files, then describe it."""

from __future__ import annotations

from pathlib import Path

from ladartui.textsafe import single_line, visible


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "validate",
        help="check a scenario file and its model files, and summarise them",
        description="Load a scenario, check every field against its limits, read and check its "
        "scene and target model files, estimate the memory the tracing structures need, then "
        "print a summary (sensor, scans, path length, flight time, scene size, memory, "
        "outputs, and whether the outputs on disk came from this file's settings and its "
        "model files as they are now), with notes such as a flight path whose scans never "
        "look at the scene or at a target. A mistake "
        "is reported on one line with exit status 2. A sound scenario that a run would "
        "still refuse before tracing (a folder or a file of another kind where an output "
        "goes, more rays than LADARTUI_MAX_RAYS allows, another run writing its outputs now) "
        "gets its summary, a 'next run' "
        "line saying why, and exit status 1.",
    )
    parser.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="scenario file (.toml), or a bundled one by name (default, convoy)",
    )
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.cli.flags import check_scenario_name
    from ladartui.errors import OutputFileError
    from ladartui.scenario import load_scenario
    from ladartui.simulation import check_output_names, check_outputs_spare_inputs
    from ladartui.user_data import bundled_or_path

    check_scenario_name(args.scenario)
    scenario = load_scenario(bundled_or_path(args.scenario))
    if scenario.geiger:  # its firing is checked as a run traces its looks; the limit read now
        from ladartui.resources import max_bin_visits

        max_bin_visits()
    scene = scenario.load_scene()
    scene_lines = scene_summary(scenario, scene)
    check_output_names(scenario)  # too long: the scenario's own name is the mistake
    try:
        check_outputs_spare_inputs(scenario)  # what a run would refuse before tracing
        refused = None
    except OutputFileError as error:  # a file where an output goes: the scenario is sound
        refused = error
    print(visible(scenario.summary()))
    notes = [*flight_notes(scenario.flight), *reach_lines(scenario, scene), *detection_notes(scenario)]
    writer = run_writing(scenario)
    refusals = [*ray_limit_refusals(scenario), *next_run_refusals(scenario, refused, writer)]
    earlier = last_run_lines(scenario, scene, writable=not refusals, writer=writer)
    for line in [*scene_lines, *notes, *earlier, *refusals[:1]]:
        print(single_line(line))
    return 1 if refusals else 0  # a script must not take a run bound to be refused as ready


def flight_notes(flight) -> list[str]:
    """A start pose the path never flies from (the TUI greys its fields out), and a flight
    log whose heading disagrees with its direction of travel."""
    from ladartui.trajectory import heading_note

    logs = [seg for seg in flight.segments if seg.kind == "log"]
    notes = [f"note       {note}" for seg in logs if (note := heading_note(seg.log, Path(seg.file).name))]
    if flight.start is None or flight.uses_start:
        return notes
    first = flight.segments[0].kind
    return [
        f"note       [flight.start] is not used: the path starts at its first segment ({first}), "
        "which places its own scans",
        *notes,
    ]


def reach_lines(scenario, scene) -> list[str]:
    """A path none of whose scans looks at the scene, or at a target: a run covers nothing there."""
    from ladartui.view_reach import reach_notes

    return [f"note       {note}" for note in reach_notes(scenario, scene)]


def detection_notes(scenario) -> list[str]:
    """Geiger-mode keys set under the ideal model: a run uses none of them, though
    ``ladartui pulses`` (which forces the model to geiger) does, so they are not refused."""
    import tomllib

    from ladartui.toml_lines import key_lines_from_text

    if scenario.detection is None or scenario.detection.geiger:
        return []
    text = scenario.path.read_text(encoding="utf-8-sig")
    table = tomllib.loads(text).get("detection", {})
    unused = [f"detection.{key}" for key in table if key != "model"]
    if not unused:
        return []
    lines = key_lines_from_text(text)
    line = lines.get(unused[0], lines.get("detection"))  # a dotted key outside [detection]: no line
    where = f"{scenario.path}:{line}" if line else str(scenario.path)
    model = 'model "ideal"' + ("" if "model" in table else " (the default)")
    keys = "a Geiger-mode key" if len(unused) == 1 else "Geiger-mode keys"
    return [
        f"note       {where}: {', '.join(unused)}: {keys} that {model} does not use "
        f'(model = "geiger" runs {"it" if len(unused) == 1 else "them"}; ladartui pulses reads '
        f"{'it' if len(unused) == 1 else 'them'} as {'it is' if len(unused) == 1 else 'they are'})"
    ]


def ray_limit_refusals(scenario) -> list[str]:
    """The work limit a run checks first, as its refusal (none when the rays are within it)."""
    from ladartui.resources import RayLimitError
    from ladartui.scenario import check_work

    try:
        check_work(scenario)
    except RayLimitError as error:
        return [f"next run   {error}; the run is refused before it traces"]
    return []


def run_writing(scenario) -> str | None:
    """What says that a run (the TUI's, another ``ladartui run``) holds ``scenario``'s
    output set now, naming its pid; None when none does."""
    from ladartui.outputset import lock_holder
    from ladartui.simulation import output_lock

    holder = lock_holder(output_lock(scenario))
    return None if holder is None else f"another run (pid {visible(holder)}) is writing this output set now"


def next_run_refusals(scenario, refused=None, writer: str | None = None) -> list[str]:
    """Why the next run would be refused before it traces, for its outputs' paths
    (``refused``: the ``OutputFileError`` its first check gave, if any; ``writer``: the
    run holding the set now, as ``run_writing`` says it)."""
    from ladartui.outputset import output_problem
    from ladartui.simulation import output_paths

    refusals = [] if writer is None else [f"next run   {writer}: a run is refused until it ends"]
    refusals += [
        f"next run   {path.name} {problem}: it is refused before it traces"
        for path in output_paths(scenario).values()
        if (problem := output_problem(path))
    ]
    if refused is not None:
        name = Path(refused.path).name
        refusals.insert(0, f"next run   {name}: {refused.reason}; the run is refused before it traces")
    return refusals


def last_run_lines(scenario, scene, writable: bool = True, writer: str | None = None) -> list[str]:
    """Whether the outputs on disk came from this file's settings and its model files as
    they are now (``scene``, as just loaded), from the run record; ``writable``: whether
    the next run can write its outputs; ``writer``: the run holding the set now, if one
    does (``run_writing``: until its swap the files are the earlier run's)."""
    from ladartui.errors import LadarError
    from ladartui.run_record import (
        changes_text,
        earlier_las,
        missing_outputs,
        read_run_record,
        setting_changes,
    )
    from ladartui.simulation import swap_interrupted

    if swap_interrupted(scenario) and writer is not None:  # its swap, under way
        return [f"last run   {writer}: until it ends the files on disk are part earlier, part new"]
    if swap_interrupted(scenario):  # a swap a killed run left (outputset)
        return [
            "last run   was stopped while it replaced the outputs: the next run puts the earlier set "
            "back first, so the files now on disk are not to be read"
        ]
    missing = missing_outputs(scenario)
    if missing:
        names = ", ".join(path.name for path in missing)
        advice = "; a run writes the whole set again" if writable else ""
        return [f"last run   outputs incomplete: {names} missing{advice}"]
    if not scenario.measures_file.is_file():
        return []  # not run yet
    record = scenario.run_record.name
    try:
        ran = read_run_record(scenario)
    except LadarError as error:  # the scenario is still valid: say so, and why not the rest
        return [f"last run   settings not read: {error}"]
    if ran is None:
        return [
            f"last run   settings not recorded: no {record} beside the outputs "
            "(removed since, or written before runs kept records)"
        ]
    changes = setting_changes(ran, scenario)
    if not changes:
        lines = [f"last run   made the outputs with this file's settings ({record})"]
    else:
        shown = changes_text(changes)
        lines = [
            f"last run   made the outputs with other settings than this file: {shown}; they are in {record}"
        ]
    lines.extend(f"last run   {line}" for line in _input_lines(scenario, scene))
    lines.extend(f"last run   {line}" for line in _output_lines(scenario))
    left = earlier_las(scenario)
    if left:
        names = " and ".join(path.name for path in left)
        verb = "are" if len(left) > 1 else "is"
        lines.append(
            f"last run   wrote no LAS: {names} {verb} from an earlier run (run --las writes them again)"
        )
    return lines


def _output_lines(scenario) -> list[str]:
    """The outputs replaced since their run wrote them (a record that says how it wrote them)."""
    from ladartui.errors import LadarError
    from ladartui.run_record import outputs_changed

    try:
        return outputs_changed(scenario)
    except LadarError as error:
        return [f"outputs of the run not read: {error}"]


def _input_lines(scenario, scene) -> list[str]:
    """The model files and flight logs changed since the run, by their fingerprints."""
    from ladartui.errors import LadarError
    from ladartui.run_record import inputs_changed

    try:
        changes = inputs_changed(scenario, scene)
    except LadarError as error:
        return [f"model files of the run not read: {error}"]
    if changes is None:
        return ["the record does not say which model files the run read (written before records did)"]
    return changes


def scene_summary(scenario, scene) -> list[str]:
    """Size the tracing structures of ``scenario``'s ``scene`` (its model files, read)."""
    import numpy as np

    from ladartui.number_text import extent_metres, plural
    from ladartui.resources import available_memory, gib

    nx, ny, nz = scene.shape
    vs = scene.voxel_size
    ids = scene.target_id_list if len(scene.target) else []
    in_targets = f" in {len(ids)} targets" if len(ids) > 1 else ""
    lines = [
        f"scene      {plural(len(scene.voxels), 'voxel')}, "
        f"target {plural(len(scene.target), 'voxel')}{in_targets}; "
        f"extent {nx} x {ny} x {nz} voxels = {extent_metres(scene.shape, vs)} m"
    ]
    lines.extend(target_notes(scenario, scene))
    unused = [i for i, _ in scenario.target_names if i not in ids]
    if unused:  # a name for an id the target model does not hold: likely a typo
        listed = ", ".join(map(str, unused[:-1])) + (" and " if len(unused) > 1 else "") + str(unused[-1])
        named = f"id {listed}, which is" if len(unused) == 1 else f"ids {listed}, which are"
        lines.append(
            f"note       [targets] names {named} not in "
            f"{scenario.target_file.name} (its ids: {', '.join(map(str, ids)) or 'none'})"
        )
    need = scene.tracing_bytes()
    need += scene.voxels.nbytes + scene.target.nbytes + np.dtype(np.int32).itemsize
    available = available_memory()
    # Each structure is refused alone when too large; together they may still not fit.
    short = ": more than this machine has; a run may fail for want of memory" if need > available else ""
    lines.append(
        f"memory     about {gib(need)} for the scene and its tracing structures "
        f"({gib(available)} available){short}"
    )
    return lines


def target_notes(scenario, scene) -> list[str]:
    """Notes on a target model that will not give measures: empty, or voxels that the
    scene model lacks (a target voxel is part of the scene: the scene run sees it there)."""

    from ladartui.number_text import plural
    from ladartui.scene.keys import count_inside

    name = scenario.target_file.name
    if not len(scene.target):
        return [f"note       {name} holds no voxels: the target measures will be undefined"]
    missing = len(scene.target) - count_inside(scene.target, scene.voxels)
    if not missing:
        return []
    is_, them = ("is", "it") if missing == 1 else ("are", "them")
    return [
        f"note       {missing:,} of {plural(len(scene.target), 'target voxel')} {is_} "
        f"not in the scene model {scenario.scene_file.name}: the scene run cannot see {them}"
    ]
