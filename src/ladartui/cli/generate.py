"""``ladartui generate PRESET OUT``: write a synthetic forest scene and its target model."""

from __future__ import annotations

import os
import time
from pathlib import Path

from ladartui.errors import FieldError, LadarError
from ladartui.number_text import extent_metres, extent_ranges, plural
from ladartui.textsafe import single_line


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "generate",
        help="generate a synthetic forest scene with a vehicle under the canopy",
        description="Generate a forest scene (trees with gappy crowns, a vehicle under the "
        "canopy at the centre) and write OUT.txt and OUT_Target.txt, comma-delimited voxel "
        "lists. Presets: 'small' (60 m x 60 m at 0.25 m) and 'reference' (150 m x 150 m at "
        "0.1 m, the report's figure-11 scale: 1500 x 1500 voxels across, about "
        "3.8 M voxels). The same "
        "seed and options always give the same scene.",
    )
    parser.add_argument("preset", metavar="PRESET", help="small or reference")
    parser.add_argument(
        "out",
        metavar="OUT",
        help="output stem: dir/name or dir/name.txt (writes name.txt and name_Target.txt); "
        "a folder (dir/ or one that exists) gets PRESET.txt and PRESET_Target.txt",
    )
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument(
        "--density", type=float, help="share of each crown's surface covered by leaf clumps, 0 to 0.99"
    )
    parser.add_argument("--trees", type=int, help="number of trees")
    parser.add_argument("--voxel-size", type=float, help="voxel size in metres")
    parser.add_argument("--vehicles", type=int, help="number of vehicles, each its own target (id 1, 2, ...)")
    parser.add_argument("--no-target", action="store_true", help="no vehicle, empty target model")
    parser.add_argument("--terrain", action="store_true", help="gentle terrain instead of flat ground")
    parser.add_argument(
        "--camouflage", action="store_true", help="drape a camouflage net over the vehicle (scene only)"
    )
    parser.add_argument(
        "--las",
        action="store_true",
        help="also write OUT.laz and OUT_Target.laz (voxel centres; target ids as point source ids)",
    )
    parser.set_defaults(handler=run)
    return parser


def out_stem(out: str, preset: str) -> Path:
    """OUT as the stem to write: a folder (one that exists, or written with a
    trailing slash) gets PRESET.txt and PRESET_Target.txt inside it."""
    if out.endswith(("/", os.sep)) or Path(out).is_dir():
        return Path(out) / preset
    return Path(out)


def check_flags_used(args) -> None:
    """Refuse flags the scene would ignore, rather than drop them without a word."""
    if args.no_target and args.vehicles:
        raise LadarError(f"--no-target and --vehicles {args.vehicles} contradict each other: drop one")
    if args.camouflage and (args.no_target or args.vehicles == 0):
        raise LadarError("--camouflage: the net is draped over a vehicle, and there is none")


def overrides_from(args) -> dict:
    """Scene parameter overrides from the command's flags."""
    overrides = {}
    for flag, name in (
        ("density", "density"),
        ("trees", "trees"),
        ("voxel_size", "voxel_size"),
        ("vehicles", "vehicles"),
    ):
        value = getattr(args, flag)
        if value is not None:
            overrides[name] = value
    if args.no_target:
        overrides["vehicles"] = 0
    if args.terrain:
        overrides["terrain"] = True
    if args.camouflage:
        overrides["camouflage"] = True
    return overrides


def run(args) -> int:
    import threading

    from ladartui.cli.console import CliConsole as Console
    from ladartui.cli.flags import check_scene_stem
    from ladartui.cli.progress import run_cancellable, sigterm_as_interrupt
    from ladartui.errors import Cancelled
    from ladartui.fileprobe import other_file_kind
    from ladartui.outputset import check_writable
    from ladartui.scene.generate import GENERATE_CANCELLED, las_paths, output_paths

    check_flags_used(args)
    if not args.out.strip():
        raise FieldError("OUT", args.out, "a name such as dir/name or a folder")
    stem = out_stem(args.out, args.preset)
    if other_file_kind(stem) is not None:  # 'forest.toml' wrote forest.toml.txt
        raise FieldError(
            "OUT",
            args.out,
            "a stem such as dir/name or dir/name.txt (it writes name.txt and name_Target.txt), "
            f"not a {stem.suffix} file name",
        )
    scene_file, target_file = output_paths(stem)
    check_scene_stem("OUT", args.out, scene_file)
    las_files = list(las_paths(stem)) if args.las else []
    check_writable(scene_file, target_file, *las_files)
    cancel = threading.Event()
    errors = Console(stderr=True)

    def stopping() -> None:  # a stage of a large scene can run for a minute
        errors.print("stopping at the end of this step...", highlight=False, markup=False)

    with sigterm_as_interrupt():
        scene, scene_path, target_path, (generated, written) = run_cancellable(
            lambda: _work(args, stem, las_files, errors, cancel),
            cancel,
            "ladartui-generate",
            Cancelled(GENERATE_CANCELLED),
            stopping,
        )
    import numpy as np

    vs = scene.voxel_size
    nx, ny = scene.shape[:2]
    print(
        single_line(
            f"wrote {scene_path} ({plural(len(scene.voxels), 'voxel')}) and {target_path} "
            f"({plural(len(scene.target), 'voxel')})"
        )
    )
    if las_files:
        print(single_line(f"wrote {las_files[0]} and {las_files[1]} (voxel centres in metres)"))
    print(f"preset {scene.preset}, seed {scene.seed}, voxel size {vs:g} m")
    print(f"area {extent_metres((nx, ny), vs)} m ({nx} x {ny} voxels of {vs:g} m)")
    if len(scene.voxels):  # as the file reads back: a voxel list keeps no empty space
        from ladartui.scene.occupancy import column_bounds

        print(f"extent {extent_ranges(*column_bounds(scene.voxels))}")
    print("parts (before merging): " + ", ".join(f"{k} {v:,}" for k, v in scene.parts.items()))
    if scene.target_centre is not None:
        x, y, z = scene.target_centre
        targets = len(np.unique(scene.ids()))
        print(
            f"target centre ({x:.2f}, {y:.2f}, {z:.2f}) m" + (f", {targets} targets" if targets > 1 else "")
        )
    else:
        print("no target")
    print(f"generated in {generated:.2f} s, written in {written:.2f} s")
    left = [path for path in las_paths(stem) if path.exists()] if not las_files else []
    if left:  # LAS copies of an earlier scene, which this one no longer matches
        names = " and ".join(path.name for path in left)
        verb = "are" if len(left) > 1 else "is"
        print(
            single_line(f"note: {names} {verb} from an earlier scene, not this one (--las writes them again)")
        )
    return 0


def _work(args, stem, las_files, console, cancel):
    """Generate (with a stage bar on a terminal) and write the models, with their LAS
    copies when asked, as one set; on the worker thread."""
    from rich.progress import TextColumn, TimeElapsedColumn

    from ladartui.cli.flags import as_flags
    from ladartui.cli.progress import progress_display
    from ladartui.scene.generate import GENERATE_STAGES, generate_scene

    after = (TextColumn("{task.fields[done]}", markup=False), TimeElapsedColumn())
    with progress_display(console, after, transient=True, disable=not console.is_terminal) as bar:
        task = bar.add_task("generating", total=1.0, done="")

        steps = len(GENERATE_STAGES) + 1  # the stages, then writing

        def report(stage: str, done: int, total: int) -> None:
            if stage == "writing":  # rows of one file, then the other: the bar only moves on
                share = max(bar.tasks[0].completed, (steps - 1 + done / max(total, 1)) / steps)
                bar.update(task, description=stage, completed=share, done=f"{done:,}/{total:,} lines")
            else:  # stage ``done`` starts: the ones before it are over
                shown = f"stage {done} of {total}"
                bar.update(task, description=stage, completed=(done - 1) / steps, done=shown)

        started = time.perf_counter()
        names = ("preset", "seed", "density", "trees", "voxel_size", "vehicles")
        typed = {name: getattr(args, name) for name in names}
        with as_flags(typed, {"preset": "PRESET"}):  # name the flag the user typed, not the parameter
            scene = generate_scene(
                args.preset, seed=args.seed, progress=report, cancel=cancel, **overrides_from(args)
            )
        generated = time.perf_counter() - started
        started = time.perf_counter()
        scene_path, target_path = scene.write(stem, cancel, report, las=bool(las_files))
        written = time.perf_counter() - started
        return scene, scene_path, target_path, (generated, written)
