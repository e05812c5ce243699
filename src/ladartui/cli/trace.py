"""``ladartui trace``: trace a file of rays against a scene model, write the hits.

RAYS.npy is an (N, 6) float array: origin x, y, z (metres) and unit direction.
HITS.npy is (N, 5) float64: kind (0 miss, 1 voxel, 2 ground), i, j, k, range
in metres (inf for a miss). The output is written atomically.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from ladartui.atomic import atomic_path, write_errors_named
from ladartui.checks import MAX_COORDINATE
from ladartui.errors import Cancelled, FieldError, InputFileError, ResourceLimitError
from ladartui.fileprobe import no_such_file, refuse_special_file
from ladartui.number_text import plural
from ladartui.textsafe import single_line
from ladartui.tracing.backend import METHODS, PRECISIONS

# Rays a trace call: the bar moves, and Ctrl-C is seen, between calls (a second or so).
TRACE_BLOCK = 1 << 20


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "trace",
        help="trace rays (.npy) against a scene model and write the hits (.npy)",
        description="Trace an (N, 6) array of rays (origin and unit direction, metres) against "
        "a voxel scene model; write an (N, 5) array: kind (0 miss, 1 voxel, 2 ground), i, j, k, "
        "range in metres.",
    )
    parser.add_argument("--scene", required=True, metavar="X.txt", help="scene model voxel list")
    parser.add_argument("--rays", required=True, metavar="RAYS.npy", help="(N, 6) float array")
    parser.add_argument("--out", required=True, metavar="HITS.npy", help="output (N, 5) float64")
    parser.add_argument("--backend", default="auto", help="backend name or 'auto' (default)")
    parser.add_argument("--method", default=METHODS[0], help=" or ".join(METHODS) + " (default: exact)")
    parser.add_argument(
        "--step",
        type=float,
        default=None,
        help="the march's step in voxels (default 0.5; needs --method march)",
    )
    parser.add_argument(
        "--voxel-size", type=float, help="metres per voxel (1 when not given, and the summary says so)"
    )
    parser.add_argument(
        "--precision",
        default=PRECISIONS[0],
        choices=PRECISIONS,
        help="arithmetic of the trace: f64 (default) or f32, as in the API; "
        "a backend without f32 kernels (numba) traces in f64, and one without f64 (a wgpu adapter "
        "lacking float64) in f32; the summary then names both",
    )
    parser.set_defaults(handler=run)


# Memory a traced ray takes on the way: the file's row, its float64 copy, the
# origins and directions handed to the tracer, the answers and the hits written.
BYTES_PER_TRACED_RAY = 48 * 4 + 24 + 40


def check_rays_header(path) -> None:
    """What a .npy file holds, from its header, before any of it is read: InputFileError
    for a file that is no .npy array of (N, 6) numbers, ResourceLimitError for more rays
    than the work or memory limit allows. An .npz archive is left to the loader."""
    import numpy.lib.format as npy

    from ladartui.resources import RAISE_BY_ENV, available_memory, check_rays, gib

    refuse_special_file(path, "expected a NumPy .npy array")
    try:
        with open(path, "rb") as handle:
            start = handle.read(len(npy.MAGIC_PREFIX) + 2)
            if start.startswith(b"PK\x03\x04"):  # a zip: an .npz archive
                return
            # Other bytes, however few, are no .npy file; only the magic's own start is one cut short.
            if not npy.MAGIC_PREFIX.startswith(start[: len(npy.MAGIC_PREFIX)]):
                raise InputFileError(path, "not a NumPy .npy file (no .npy header)")
            if len(start) < len(npy.MAGIC_PREFIX) + 2:
                raise InputFileError(path, "empty or cut short: expected a NumPy .npy array")
            handle.seek(0)
            version = npy.read_magic(handle)
            read = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
            shape, _, dtype = read(handle)
    except FileNotFoundError:
        raise InputFileError(path, f"{no_such_file(path)}; expected a NumPy .npy array") from None
    except OSError as error:
        raise InputFileError(path, f"cannot be read ({error.strerror or error})") from None
    except ValueError as error:
        raise InputFileError(path, f"not a NumPy .npy array (its header: {error})") from None
    if dtype.hasobject:
        raise InputFileError(path, "holds Python objects: expected an (N, 6) array of numbers")
    if dtype.kind not in "fiu":
        raise InputFileError(path, f"dtype {dtype}: expected numbers")
    if len(shape) != 2 or shape[1] != 6:
        raise InputFileError(
            path, f"array of shape {shape}: expected (N, 6): origin x, y, z and direction dx, dy, dz per row"
        )
    rows = int(shape[0])
    check_rays(rows, str(path), raise_with=RAISE_BY_ENV)  # trace has no --max-rays
    need, limit = rows * BYTES_PER_TRACED_RAY, available_memory()
    if need > limit:
        raise ResourceLimitError(
            f"{path}: {rows:,} rays need about {gib(need)} to trace, more than the "
            f"{gib(limit)} of memory available; trace them in parts"
        )


def load_rays(path) -> np.ndarray:
    """The (N, 6) float64 rays of a .npy file; InputFileError naming what is wrong."""
    check_rays_header(path)  # what it holds: an (N, 6) array of numbers, not too many
    try:
        rays = np.load(path, allow_pickle=False)
    except EOFError:
        raise InputFileError(path, "empty or cut short: expected a NumPy .npy array") from None
    except (ValueError, OSError) as error:  # a body that does not match its header
        raise InputFileError(path, f"not a NumPy .npy array ({error})") from None
    if not isinstance(rays, np.ndarray):  # an .npz archive of arrays
        rays.close()
        raise InputFileError(path, "a NumPy .npz archive: expected one (N, 6) array in a .npy file")
    rays = rays.astype(np.float64)
    if not np.all(np.isfinite(rays)):
        row = int(np.flatnonzero(~np.all(np.isfinite(rays), axis=1))[0])
        raise InputFileError(path, f"{_row(row)} is not finite: expected finite numbers")
    zero = np.flatnonzero(~np.any(rays[:, 3:] != 0, axis=1))
    if len(zero):
        raise InputFileError(path, f"{_row(int(zero[0]))} has a zero direction: expected a unit vector")
    far = np.flatnonzero(np.abs(rays[:, :3]).max(axis=1) > MAX_COORDINATE)
    if len(far):  # past it f64 cell coordinates lose the voxels (wrong hits, then none)
        row = int(far[0])
        raise InputFileError(
            path,
            f"{_row(row)} has its origin {np.abs(rays[row, :3]).max():.3g} m from the scene's "
            f"origin: expected within {MAX_COORDINATE:,.0f} m, as a scenario's points",
        )
    return rays


def _row(index: int) -> str:
    """A row counted from 1, as file lines are, with the index that finds it in numpy."""
    return f"row {index + 1} (index {index})"


def run(args):
    from ladartui.cli.flags import check_file_names, refuse_step_without_march, voxel_size_flag
    from ladartui.cli.progress import sigterm_as_interrupt

    check_file_names({"--scene": args.scene, "--rays": args.rays, "--out": args.out})
    # A scene list holds no voxel size: without the flag, 1 m, said in the summary.
    voxel_size = 1.0 if args.voxel_size is None else voxel_size_flag(args.voxel_size)
    if args.method in METHODS:  # (another method is refused as the trace starts)
        refuse_step_without_march(args.step, args.method, f"this trace is --method {args.method}")
    if args.step is not None:
        from ladartui.checks import number_field
        from ladartui.scenario import MAX_STEP
        from ladartui.tracing.config import MIN_STEP

        number_field("--step", args.step, MIN_STEP, MAX_STEP)  # the limits run holds a step to
    from ladartui.outputset import check_writable

    out = Path(args.out)
    if not out.parent.is_dir():  # a mistyped folder is not made
        raise FieldError("--out", args.out, "a file in an existing folder")
    if out.is_dir():
        raise FieldError("--out", args.out, "a file name, not a folder")
    for flag, read in (("--rays", args.rays), ("--scene", args.scene)):
        if out.exists() and Path(read).exists() and out.samefile(read):
            raise FieldError("--out", args.out, f"a file other than {flag}")
    check_writable(out)  # before the trace, not after it
    earlier = _identity(out)
    try:
        with sigterm_as_interrupt():
            _trace_and_write(args, voxel_size)
    except KeyboardInterrupt:
        # The hits replace --out in one rename: a new file there means they were written.
        if _identity(out) != earlier:
            raise Cancelled(f"interrupted after the trace; it wrote {args.out}") from None
        unchanged = f", {args.out} is unchanged" if earlier is not None else ""
        raise Cancelled(f"trace cancelled; nothing was written{unchanged}") from None
    return 0


def _identity(path) -> tuple[int, int] | None:
    """Which file ``path`` is (device, inode); None where there is none."""
    try:
        status = os.stat(path)
    except OSError:
        return None
    return status.st_dev, status.st_ino


def _shown(text: str) -> str:
    """A file name in the bar: one line, its markup ("[red]") shown as typed. The bar
    names a file without its folder, so a long path leaves room for the count."""
    from rich.markup import escape

    from ladartui.textsafe import one_line

    return escape(one_line(text))


def _trace_and_write(args, voxel_size: float) -> None:
    """Read the rays and the scene, trace, write the hits, say what was traced; a bar on
    a terminal shows each step, and the rays traced."""
    from rich.progress import TextColumn, TimeElapsedColumn

    import ladartui.tracing as tracing
    from ladartui.cli.console import CliConsole
    from ladartui.cli.flags import as_flags
    from ladartui.cli.progress import progress_display
    from ladartui.scene.occupancy import Occupancy
    from ladartui.scene.voxels import load_voxels

    console = CliConsole(stderr=True)
    after = (TextColumn("{task.fields[done]}"), TimeElapsedColumn())
    with progress_display(console, after, transient=True, disable=not console.is_terminal) as bar:
        task = bar.add_task(_shown(f"reading {Path(args.rays).name}"), total=None, done="")
        rays = load_rays(args.rays)
        bar.update(task, description=_shown(f"reading {Path(args.scene).name}"))
        voxels = load_voxels(args.scene)
        occupancy = Occupancy.build(voxels, source=str(args.scene))
        bar.update(task, description="tracing", total=max(len(rays), 1), completed=0)
        typed = {
            "backend": args.backend,
            "method": args.method,
            "step": args.step,
            "precision": args.precision,
        }
        results = []
        with as_flags(typed):  # name the flag typed, not trace()'s parameter
            for start in range(0, max(len(rays), 1), TRACE_BLOCK):
                block = rays[start : start + TRACE_BLOCK]
                results.append(
                    tracing.trace(
                        occupancy,
                        block[:, :3],
                        block[:, 3:],
                        backend=args.backend,
                        method=args.method,
                        step=args.step,
                        precision=args.precision,
                        voxel_size=voxel_size,
                    )
                )
                done = start + len(block)
                bar.update(task, completed=done, done=f"{done:,}/{len(rays):,} rays")
        bar.update(task, description=_shown(f"writing {Path(args.out).name}"))
        with write_errors_named(args.out), atomic_path(args.out) as tmp:
            _save_npy(tmp, np.concatenate([result.as_array() for result in results]))
    counts = np.bincount(np.concatenate([result.kind for result in results]), minlength=3)
    result = results[-1]
    backends = ", ".join(dict.fromkeys(r.backend for r in results))  # auto may choose by block
    used = _precisions_used(
        [(r.info.get("precision", args.precision), len(r.kind)) for r in results], args.precision
    )
    size = f"voxel size {voxel_size:g} m" + (
        " (assumed; --voxel-size sets it)" if args.voxel_size is None else ""
    )
    print(
        single_line(
            f"{plural(len(rays), 'ray')} ({backends}, {result.method}, {used}), {size}: "
            f"{plural(counts[1], 'voxel hit')}, {plural(counts[2], 'ground hit')}, "
            f"{plural(counts[0], 'miss', 'misses')} -> {args.out}"
        ),
        file=sys.stderr,
    )


def _save_npy(path, array: np.ndarray) -> None:
    """``array`` as a .npy file, its bytes written by Python's file object: a failed write
    then says why ("File too large"), where numpy's own says only how many bytes it wrote."""
    from numpy.lib import format as npy

    array = np.ascontiguousarray(array)  # the header then says C order, as the bytes are
    with open(path, "wb") as handle:
        npy.write_array_header_1_0(handle, npy.header_data_from_array_1_0(array))
        handle.write(array.data)


def _precisions_used(blocks: list[tuple[str, int]], asked: str) -> str:
    """The arithmetic the blocks were traced in, "f64", or each with its rays where auto
    chose backends of different arithmetic by block, "f64 for 4 rays, f32 for 1"; then
    whether a backend lacked the arithmetic asked for."""
    rays: dict[str, int] = {}
    for precision, count in blocks:
        rays[precision] = rays.get(precision, 0) + count
    (first, count), *rest = rays.items()
    text = first if not rest else f"{first} for {plural(count, 'ray')}"
    text = ", ".join([text, *(f"{precision} for {n:,}" for precision, n in rest)])
    return text if asked in rays else f"{text}, not the {asked} asked for"
