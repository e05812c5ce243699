"""``ladartui voxelize SOURCE OUT``: a target model from a triangle mesh, optionally put into a
scene; or a scene model from a LAS/LAZ point cloud (``voxelize_cloud``)."""

from __future__ import annotations

import math
import os
import threading
import time

from ladartui.cli.flags import as_flags, check_file_names, check_scene_stem, voxel_size_flag
from ladartui.cli.progress import run_cancellable, sigterm_as_interrupt, voxelize_display
from ladartui.errors import Cancelled, FieldError, LadarError, check_cancelled
from ladartui.number_text import extent_metres, plural
from ladartui.textsafe import one_line, single_line


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "voxelize",
        help="make a target model from a mesh (.obj, .stl, .ply), optionally inserted into a scene; "
        "or a scene model from a point cloud (.las, .laz)",
        description="Voxelise a triangle mesh exactly: a voxel is set when the surface passes "
        "through its interior (a face lying on a voxel boundary counts for the voxel on its "
        "inner side), and with --solid also when its centre is inside the closed mesh. The mesh "
        "is in metres (see --scale), z up (see --up), its +y the vehicle's forward direction. "
        "Without --into, OUT is the target model (a comma-delimited voxel list). With --into "
        "SCENE.txt, the vehicle is added to that scene model and its SCENE_Target.txt, written "
        "together as OUT.txt and OUT_Target.txt (OUT may be SCENE itself). "
        "A point cloud (a survey, .las or .laz) is voxelised where it was surveyed into a scene "
        "model: OUT.txt holds a voxel for each voxel its points fall in, and OUT_Target.txt is "
        "written beside it empty (no vehicle yet: a scenario plans over it as it is, and "
        "'voxelize MESH OUT --into OUT.txt --at X,Y' adds one). Voxel (0, 0, 0) is centred on "
        "the cloud's lowest x, y and z; the command says where that is in the cloud's "
        "coordinates, and scene metres (--at, flight paths) count from there. A cloud in feet "
        "(as its coordinate system says) is read in metres. Points classed as noise (ASPRS 7, "
        "18) or flagged withheld are left out unless --keep-noise. The mesh flags (--at, "
        "--heading, --solid, --scale, --up, --id, --into) are refused with a point cloud.",
    )
    parser.add_argument(
        "mesh", metavar="SOURCE", help="mesh file (.obj, .stl or .ply), or point cloud (.las or .laz)"
    )
    parser.add_argument(
        "out",
        metavar="OUT",
        help="target model to write (.txt added when missing); with --into or a point cloud, the "
        "scene's stem (X writes X.txt and X_Target.txt)",
    )
    parser.add_argument(
        "--voxel-size", metavar="V", type=float, required=True, help="voxel size in metres (the scene's)"
    )
    parser.add_argument(
        "--at",
        metavar="X,Y[,Z]",
        help="where the middle of the mesh's footprint goes, metres in the scene; Z is the height "
        "of its lowest point above the ground (default 0). With --into it rests on the scene's "
        "ground under its footprint (each column's lowest voxel, up to the vehicle's height above "
        "the lowest nearby; higher ones are overhead): on the top of the highest; where none is "
        "found, as in a generated flat scene, on the floor (the bottom of voxel layer 0). The "
        "command says which. Without --at the mesh starts at voxel (0, 0, 0)",
    )
    parser.add_argument(
        "--heading", metavar="DEG", type=float, help="degrees clockwise from north (needs --at; default 0)"
    )
    parser.add_argument("--solid", action="store_true", help="fill the inside (needs a closed mesh)")
    parser.add_argument(
        "--into", metavar="SCENE", help="scene model (X.txt) to add the vehicle to, with X_Target.txt"
    )
    parser.add_argument(
        "--id",
        metavar="N",
        type=int,
        help="the vehicle's target id (1..65535): OUT is written as x,y,z,id lines; with --into the "
        "scene's targets keep their ids (a three-column target model is target 1) and N must be "
        "new. Without --id the vehicle joins a one-target model, or takes the next free id",
    )
    parser.add_argument(
        "--scale", metavar="S", type=float, help="metres per mesh unit (default 1; 0.001 for mm)"
    )
    parser.add_argument("--up", choices=("z", "y"), help="the mesh's up axis (default z)")
    parser.add_argument(
        "--keep-noise",
        action="store_true",
        help="point clouds: keep points classed as noise (ASPRS 7, 18) or flagged withheld",
    )
    parser.set_defaults(handler=run)
    return parser


# Flags that place, shape or label a mesh: a point cloud is voxelised where it was surveyed.
MESH_FLAGS = ("at", "heading", "solid", "scale", "up", "id")


def refuse_mesh_flags(args) -> None:
    """A mesh's flag given with a point cloud would be dropped without a word: refused,
    naming it; ``--into`` too (a survey is a scene of its own, vehicles go into it after)."""
    for name in MESH_FLAGS:
        if getattr(args, name) is not None and getattr(args, name) is not False:  # --heading 0 too
            flag = "--" + name
            raise LadarError(
                f"{flag} is for a mesh; {args.mesh} is a point cloud, voxelised where it was "
                f"surveyed as a whole scene: drop {flag}"
            )
    if args.into is not None:
        raise LadarError(
            f"--into adds a mesh's vehicle to a scene; {args.mesh} is a point cloud, voxelised as a "
            "scene of its own: drop --into, then add vehicles to that scene with "
            "'voxelize MESH OUT --into OUT.txt --at X,Y'"
        )


def mesh_defaults(args) -> None:
    """The mesh flags not given take their defaults (left None to tell a flag typed)."""
    for name, default in (("heading", 0.0), ("scale", 1.0), ("up", "z")):
        if getattr(args, name) is None:
            setattr(args, name, default)


def _position(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        values = ()
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise FieldError("--at", text, "X,Y or X,Y,Z in metres, e.g. 30,25")
    return values


def run(args) -> int:
    from pathlib import Path

    from ladartui.cli.console import CliConsole as Console
    from ladartui.fileprobe import other_file_kind
    from ladartui.outputset import check_writable
    from ladartui.scene.insertion import scene_model_paths
    from ladartui.scene.voxelize import CANCELLED, Placement
    from ladartui.scene.voxels import MAX_TARGET_ID

    check_file_names({"SOURCE": args.mesh, "OUT": args.out, "--into": args.into})
    voxel_size_flag(args.voxel_size)  # the scene's, so one a scenario takes
    cloud = other_file_kind(args.mesh) == "a LAS point cloud"  # .las or .laz, in any case
    if cloud:
        refuse_mesh_flags(args)
    elif args.keep_noise:
        raise LadarError(
            f"--keep-noise is for a point cloud (.las, .laz); {args.mesh} is a mesh: drop --keep-noise"
        )
    mesh_defaults(args)
    if not (args.scale > 0 and math.isfinite(args.scale)):
        raise FieldError("--scale", args.scale, "a positive number of metres per mesh unit")
    if not (math.isfinite(args.heading) and abs(args.heading) <= 360.0):
        raise FieldError("--heading", args.heading, "degrees clockwise from north, -360 to 360")
    if args.id is not None and not 1 <= args.id <= MAX_TARGET_ID:
        raise FieldError("--id", args.id, f"a target id from 1 to {MAX_TARGET_ID}")
    if args.at is None and (args.heading or args.into):
        flag = "--into" if args.into else "--heading"
        raise FieldError(flag, args.into or args.heading, "--at X,Y too: where the vehicle goes in the scene")
    placement = None
    if args.at is not None:
        x, y, *rest = _position(args.at)
        placement = Placement(x, y, rest[0] if rest else 0.0, args.heading)
    scene_out = bool(args.into) or cloud  # OUT is a scene's stem
    stem = "the scene's stem (X writes X.txt and X_Target.txt)"
    if args.out.endswith(("/", os.sep)) or Path(args.out).is_dir():  # not a stem: "models" + ".txt"
        wanted = stem if scene_out else "a target model's file name (X.txt)"
        raise FieldError("OUT", args.out, f"{wanted}, not a folder")
    out_kind = other_file_kind(args.out)
    if out_kind is not None:  # 'truck.las' wrote truck.las.txt
        wanted = stem if scene_out else "a voxel-list name ending in .txt"
        what = "a mesh" if out_kind == "a mesh" else f"a {Path(args.out).suffix} file name"
        raise FieldError("OUT", args.out, f"{wanted}, not {what}")
    outputs: tuple[Path, ...]
    if scene_out:
        outputs = scene_model_paths(args.out)
        check_scene_stem("OUT", args.out, outputs[0])
    if cloud:
        from ladartui.cli.voxelize_cloud import scene_from_cloud

        check_writable(*outputs)
        return scene_from_cloud(args, outputs)
    if args.into:
        into = Path(args.into)
        if into.stem.endswith("_Target"):  # a target model read as the scene
            name = into.stem.removesuffix("_Target")
            raise FieldError(
                "--into",
                args.into,
                f"a scene model, such as {name}.txt (its target model {into.name} is read "
                "beside it), not a target model",
            )
    else:
        target, beside = scene_model_paths(args.out)  # X.txt, and X_Target.txt were X a scene
        if target.is_file() and beside.is_file():  # --into forgotten: the scene would be lost
            raise FieldError(
                "OUT",
                args.out,
                f"a new target model's name, not the scene model {target.name} (its target model "
                f"{beside.name} is beside it); to add the vehicle to that scene, give --into {target.name}",
            )
        outputs = (target,)
    check_writable(*outputs)
    errors = Console(stderr=True)
    cancel = threading.Event()
    started = time.perf_counter()
    with sigterm_as_interrupt():
        mesh, result, insertion = run_cancellable(
            lambda: _work(args, placement, outputs, errors, cancel),
            cancel,
            "ladartui-voxelize",
            Cancelled(CANCELLED),
        )
    elapsed = time.perf_counter() - started
    _report(Console(), args, mesh, (result, insertion, placement), outputs, elapsed)
    return 0


def _work(args, placement, outputs, console, cancel):
    """Read, voxelise (with progress), insert and write; runs on the worker thread."""
    import numpy as np

    from ladartui.scene.insertion import insert_vehicle, load_scene_model, write_scene_model
    from ladartui.scene.model_files import save_model
    from ladartui.scene.voxelize import CANCELLED, load_mesh, voxelize

    with voxelize_display(console) as bar:
        task = bar.add_task(f"reading {args.mesh}", total=None, done="")
        mesh = load_mesh(args.mesh, scale=args.scale, up=args.up)
        for note in mesh.notes:
            console.print(
                one_line(f"note: {mesh.path}: {note}"), highlight=False, markup=False, soft_wrap=True
            )
        if args.into:  # a bad scene file is found before the work
            bar.update(task, description=f"reading {args.into}")
            scene, target, target_ids, had_target = load_scene_model(args.into)
        bar.update(task, description="voxelising", total=1.0, completed=0.0)

        units = {
            "surface": "triangles",
            "inside": "triangles",
            "filling": "slabs",
            "collecting": "slabs",
            "writing": "voxels",
        }

        def report(stage: str, done: int, total: int) -> None:
            bar.update(
                task,
                description=stage,
                completed=done / total,
                done=f"{done:,}/{total:,} {units.get(stage, '')}",
            )

        with as_flags(_typed(args)):
            result = voxelize(mesh, args.voxel_size, placement, args.solid, progress=report, cancel=cancel)
        check_cancelled(cancel, CANCELLED)
        if not args.into:
            ids = None if args.id is None else np.full(len(result.voxels), args.id, dtype=np.int32)
            save_model(outputs[0], result.voxels, cancel, report, ids)
            return mesh, result, None
        with as_flags(_typed(args)):
            insertion = insert_vehicle(
                scene, target, result.voxels, args.voxel_size, had_target, args.into, target_ids, args.id
            )
        write_scene_model(args.out, insertion, cancel, report)
        return mesh, result, insertion


def _typed(args) -> dict:
    """The flags whose values the core checks (``at``: the text typed, not the position)."""
    return {"at": args.at, "voxel_size": args.voxel_size, "id": args.id}


def _report(console, args, mesh, done, outputs, elapsed) -> None:
    result, insertion, placement = done
    vs = args.voxel_size
    kind = "solid" if result.solid else "surface"
    detail = f"{result.surface:,} on the surface"
    if result.solid:
        detail += f", {result.inside:,} with their centre inside"
    say = lambda text: console.print(single_line(text), highlight=False, markup=False, soft_wrap=True)  # noqa: E731
    say(
        f"{mesh.path}: {plural(len(mesh.faces), 'triangle')}, "
        f"{'closed' if mesh.closed else 'not closed'}; "
        f"{kind} model of {plural(len(result.voxels), 'voxel')} at {vs:g} m ({detail}) in {elapsed:.2f} s"
    )
    if len(result.voxels):
        low, high = result.voxels.min(axis=0), result.voxels.max(axis=0)
        if insertion is not None:  # where it went in the scene
            low, high = low + [0, 0, insertion.resting.lift], high + [0, 0, insertion.resting.lift]
        say(
            "voxels "
            + ", ".join(f"{n} {lo}..{hi}" for n, lo, hi in zip("xyz", low, high))
            + f" ({extent_metres(high - low + 1, vs)} m)"
        )
    if insertion is None:
        say(f"wrote {outputs[0]}" + (f" (target {args.id})" if args.id is not None else ""))
        return
    scene_path, target_path = outputs
    say(
        f"wrote {scene_path} ({plural(len(insertion.scene), 'voxel')}, {insertion.added:,} new) and "
        f"{target_path} ({plural(len(insertion.target), 'voxel')}"
        + (", a new target model" if insertion.new_target else "")
        + (
            f"; the vehicle is target {insertion.vehicle_id}, one of "
            f"{len(set(insertion.target_ids.tolist()))} targets"
            if insertion.target_ids is not None
            else ""
        )
        + ")"
    )
    assert placement is not None  # --into needs --at
    resting = insertion.resting
    say(resting.describe(vs, placement.z))  # Z of X,Y[,Z]: its height over the ground
    if resting.buried:
        say(resting.warning(vs))
    if resting.beneath:
        say(resting.beneath_warning(vs, (placement.x, placement.y)))
    if insertion.occupied:
        say(
            f"note: {insertion.occupied:,} of the vehicle's voxels were already in the scene "
            "(ground, plants or another vehicle)"
        )
