"""``ladartui info FILE`` and ``ladartui info --backends``: describe inputs and the machine."""

from __future__ import annotations

import time
from pathlib import Path

from ladartui.errors import LadarError
from ladartui.fileprobe import file_problem
from ladartui.number_text import extent_metres, extent_ranges, plural
from ladartui.textsafe import single_line, visible


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "info",
        help="describe a voxel list, a scenario, or the tracing backends",
        description="For a voxel list (X.txt): voxel count, extent, its target model "
        "X_Target.txt if present, and the memory and build time of the sparse occupancy "
        "structure. For a scenario (.toml): its summary. With --backends: each tracing "
        "backend, whether it can run here (or why not) and what runs the work.",
    )
    parser.add_argument(
        "file",
        metavar="FILE",
        nargs="?",
        help="voxel list (.txt), scenario (.toml) or a bundled one by name: default, convoy",
    )
    parser.add_argument("--backends", action="store_true", help="list the tracing backends")
    parser.add_argument(
        "--voxel-size",
        type=float,
        help="voxel size in metres, to show the extent and target centre in metres",
    )
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from ladartui.cli.flags import check_file_names

    check_file_names({"FILE": args.file}, "a voxel list (.txt) or a scenario (.toml)")
    if not args.backends and not args.file:
        raise LadarError("info needs a FILE (voxel list or scenario .toml) or --backends")
    if args.voxel_size is not None and not args.file:  # --backends alone: it would be dropped
        from ladartui.errors import FieldError

        raise FieldError("--voxel-size", args.voxel_size, "a FILE too: it sets a voxel list's size")
    if args.backends:
        print_backends()
    if args.file:
        from ladartui.user_data import bundled_or_path, bundled_scenario_name

        path = Path(args.file)
        if not path.exists() and bundled_scenario_name(args.file) is not None:
            path = bundled_or_path(args.file)  # "convoy", as run takes it
        if path.suffix.lower() == ".toml":
            if args.voxel_size is not None:
                from ladartui.errors import FieldError

                raise FieldError(
                    "--voxel-size",
                    args.voxel_size,
                    "no --voxel-size with a scenario: it gives its own (files.voxel_size); "
                    "the option is for a voxel list",
                )
            print_scenario(path)
        else:
            refuse_other_kinds(path)
            print_voxel_list(path, args.voxel_size)
    return 0


def refuse_other_kinds(path: Path) -> None:
    """A mesh, point cloud or measures file would be read as a voxel list and fail on its
    first line: say what it is, and for a mesh or a point cloud what to do."""
    from ladartui.fileprobe import other_file_kind

    what = other_file_kind(path)
    if what is not None:
        from ladartui.errors import InputFileError

        advice = {
            "a mesh": ": voxelise the mesh first with 'ladartui voxelize MESH OUT --voxel-size V'",
            "a LAS point cloud": (
                ": make a scene model of it with 'ladartui voxelize CLOUD OUT --voxel-size V'"
            ),
        }.get(what, "")
        raise InputFileError(
            path, f"{what} ({path.suffix}); info takes a voxel list (.txt) or a scenario (.toml){advice}"
        )


def print_scenario(path: Path) -> None:
    try:
        from ladartui.scenario import load_scenario
    except ModuleNotFoundError as error:
        if error.name != "ladartui.scenario":
            raise
        raise LadarError(
            f"{path}: scenario files cannot be read here (ladartui.scenario is not available)"
        ) from None
    print(visible(load_scenario(path).summary()))


def print_voxel_list(path: Path, voxel_size=None) -> None:
    from ladartui.errors import InputFileError
    from ladartui.fingerprint import Digest
    from ladartui.scene.keys import count_inside
    from ladartui.scene.model import target_path_for
    from ladartui.scene.occupancy import column_bounds
    from ladartui.scene.target_model import load_target
    from ladartui.scene.voxels import load_voxels_counted

    if voxel_size is not None:
        from ladartui.cli.flags import voxel_size_flag

        voxel_size_flag(voxel_size)  # as trace takes it: not inf, not 1e308
    ids = None
    record = _run_record_beside(path)
    is_target_model = path.stem.endswith("_Target") and record is None
    started = time.perf_counter()
    digest = Digest()  # the bytes hashed as they are read: an output is read once
    if is_target_model:  # x,y,z or x,y,z,id lines
        voxels, ids = load_target(path, digest)
        duplicates = 0
    else:
        try:
            voxels, duplicates = load_voxels_counted(path, digest=digest)
        except InputFileError as error:
            # x,y,z,id lines are a target model whatever the file's name (voxelize --id
            # writes OUT so): read as one, else the error as a voxel list stands
            target = _as_target_model(path) if record is None and error.line == 1 else None
            if target is None:
                raise
            (voxels, ids), duplicates, is_target_model = target, 0, True
    loaded = time.perf_counter() - started
    output = None if record is None else _run_output(path, record, digest.fingerprint())
    rows = [
        (
            "voxels",
            f"{len(voxels):,}" + (f" ({plural(duplicates, 'duplicate line')} dropped)" if duplicates else ""),
        )
    ]
    if ids is not None and len(ids):
        rows.append(("targets", _targets_text(ids)))
    rows.append(("read in", f"{loaded:.2f} s"))
    shape: tuple[int, ...] = (0, 0, 0)
    if len(voxels):
        lo, hi = column_bounds(voxels)
        shape = tuple(int(h) + 1 for h in hi)
        rows.append(("extent", extent_ranges(lo, hi)))
        if voxel_size:  # the span the ranges give, then the box from the origin validate gives
            span = f"{extent_metres(hi - lo + 1, voxel_size)} at {voxel_size:g} m"
            if lo.any():
                span += f" ({extent_metres(shape, voxel_size)} from the origin)"
            rows.append(("extent (m)", span))
    if output is not None:
        rows.append(("output", output))
    # A target model's own targets are counted above: it has no target model of its own;
    # a run's outputs are a pair of their own.
    target_path = None if is_target_model or output is not None else target_path_for(path)
    if target_path is not None and target_path.is_file():
        target, ids = load_target(target_path)
        text = f"{target_path.name}: {plural(len(target), 'voxel')}"
        if len(target):
            inside = count_inside(target, voxels)
            text += f", {inside:,} of them in the scene; {_targets_text(ids)}"
            centre = target.mean(axis=0)
            text += f"; centre ({centre[0]:.1f}, {centre[1]:.1f}, {centre[2]:.1f}) voxels"
            if voxel_size:
                m = centre * voxel_size
                text += f" = ({m[0]:.2f}, {m[1]:.2f}, {m[2]:.2f}) m"
            shape = tuple(max(s, int(t) + 1) for s, t in zip(shape, target.max(axis=0)))
        rows.append(("target", text))
    elif target_path is not None:  # not found, or a folder or a pipe of that name
        rows.append(("target", f"none ({target_path.name} {file_problem(target_path)})"))
    rows.append(("occupancy", _occupancy_text(voxels, shape, path)))
    print(single_line(f"{path}: voxel list"))
    width = max(len(name) for name, _ in rows)
    for name, text in rows:
        print(single_line(f"  {name:<{width}}  {text}"))


def _as_target_model(path: Path):
    """(voxels, ids) of ``path`` read as a target model; None when it is not one either."""
    from ladartui.scene.target_model import load_target

    try:
        return load_target(path)
    except LadarError:
        return None


def _run_record_beside(path: Path) -> Path | None:
    """The run record S_Run.toml beside a run's output S_Scene.txt or S_Target.txt; None
    for any other voxel list."""
    from ladartui.scenario_file import RECORD_SUFFIX, is_record

    for run in ("_Scene", "_Target"):
        if path.stem.endswith(run):
            record = path.with_name(path.stem.removesuffix(run) + RECORD_SUFFIX)
            return record if is_record(record) else None
    return None


def _run_output(path: Path, record: Path, fingerprint) -> str:
    """What the run output ``path`` (its bytes' ``fingerprint`` as just read) is, and
    whether it, or its fellow, changed since the run wrote it, as validate says."""
    import os

    from ladartui.run_record import replaced_outputs

    scene = path.stem.endswith("_Scene")
    stem = path.stem.removesuffix("_Scene" if scene else "_Target")
    what, others = ("scene", "target") if scene else ("target", "scene")
    fellow = path.with_name(f"{stem}{'_Target' if scene else '_Scene'}{path.suffix}")
    try:
        replaced = replaced_outputs(record, only=(path, fellow), known={path: fingerprint})
    except LadarError as error:
        return f"named as an output of a run of {stem}.toml, but {error}"
    changed = {os.path.abspath(output) for output in replaced}
    if os.path.abspath(path) in changed:
        return f"changed since the run of {stem}.toml wrote it ({record.name}): it is not the run's output"
    if not fellow.is_file():
        said = f"{fellow.name}, the {others} run's, is not there"
    elif os.path.abspath(fellow) in changed:
        said = f"{fellow.name}, the {others} run's, changed since"
    else:
        said = f"{fellow.name}: the {others} run's"
    return f"the {what} run's returns of a run of {stem}.toml ({record.name}); {said}"


def _targets_text(ids) -> str:
    """ "3 targets (ids 1, 2, 3)" or "1 target (id 1)"."""
    import numpy as np

    distinct = [int(i) for i in np.unique(ids)]
    if len(distinct) == 1:
        return f"1 target (id {distinct[0]})"
    shown = ", ".join(map(str, distinct[:8])) + (", ..." if len(distinct) > 8 else "")
    return f"{len(distinct)} targets (ids {shown})"


def _occupancy_text(voxels, shape, path) -> str:
    try:
        from ladartui.scene.occupancy import Occupancy
    except ModuleNotFoundError as error:
        if error.name != "ladartui.scene.occupancy":
            raise
        return "not available (ladartui.scene.occupancy is missing)"
    started = time.perf_counter()
    occupancy = Occupancy.build(voxels, shape, source=str(path))
    built = time.perf_counter() - started
    return (
        f"{occupancy.nbytes / 2**20:.1f} MiB ({plural(occupancy.n_bricks, 'brick')}, "
        f"{plural(occupancy.n_tiles, 'tile')}, {plural(occupancy.n_regions, 'region')}), "
        f"built in {built:.2f} s"
    )


def print_backends() -> None:
    from rich.table import Table

    from ladartui.cli.console import CliConsole as Console
    from ladartui.tracing import auto_summary
    from ladartui.tracing.backend import backend_status, get_backend

    table = Table(title="Tracing backends")
    table.add_column("backend")
    table.add_column("status")
    table.add_column("details")
    status = backend_status()
    for name, reason in status.items():
        if reason is None:
            backend = get_backend(name)
            details = ", ".join(f"{k}: {v}" for k, v in backend.describe().items())
            summary = getattr(backend, "summary", "")
            table.add_row(name, "available", f"{summary}\n{details}" if summary else details)
        else:
            table.add_row(name, "unavailable", reason)
    if any(reason is None for reason in status.values()):
        table.caption = f"auto: {auto_summary()}"
    Console().print(table)
