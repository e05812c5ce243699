"""``ladartui voxelize SURVEY.las OUT``: a scene model from a LAS/LAZ point cloud.

OUT.txt gets the cloud's voxels and OUT_Target.txt is written beside it empty, the two
as one set (a scenario needs the target model beside its scene; an empty one is a
scene with no vehicle yet, and ``voxelize MESH OUT --into OUT.txt`` adds one).
"""

from __future__ import annotations

import threading

from ladartui.cli.flags import as_flags
from ladartui.cli.progress import run_cancellable, sigterm_as_interrupt, voxelize_display
from ladartui.errors import Cancelled, check_cancelled
from ladartui.number_text import extent_metres, plural
from ladartui.textsafe import single_line


def scene_from_cloud(args, outputs) -> int:
    """Voxelise ``args.mesh`` (a point cloud) at ``args.voxel_size`` into ``outputs``
    (OUT.txt, OUT_Target.txt, checked writable), with progress, cancelled by Ctrl-C."""
    from ladartui.cli.console import CliConsole as Console
    from ladartui.scene.voxelize import CANCELLED

    errors = Console(stderr=True)
    cancel = threading.Event()
    with sigterm_as_interrupt():
        cloud = run_cancellable(
            lambda: _work(args, outputs, errors, cancel), cancel, "ladartui-voxelize", Cancelled(CANCELLED)
        )
    _report(args, cloud, outputs)
    return 0


def _work(args, outputs, console, cancel):
    """Read and voxelise the cloud, then write the scene and its empty target model as
    one set; on the worker thread."""
    import numpy as np

    from ladartui.scene.las import AllNoise, voxelize_cloud
    from ladartui.scene.model_files import write_model_pair
    from ladartui.scene.voxelize import CANCELLED, merge_voxels

    with voxelize_display(console) as bar:
        task = bar.add_task(f"reading {args.mesh}", total=None, done="")
        units = {"reading": "points", "writing": "voxels"}

        def report(stage: str, done: int, total: int) -> None:
            shown = f"{done:,}/{total:,} {units[stage]}" if stage in units else ""
            label = f"reading {args.mesh}" if stage == "reading" else stage
            bar.update(task, description=label, completed=done / max(total, 1), total=1.0, done=shown)

        try:
            # too fine for the cloud's extent: the flag, and the cloud
            with as_flags({"voxel_size": args.voxel_size}):
                cloud = voxelize_cloud(
                    args.mesh, args.voxel_size, keep_noise=args.keep_noise, progress=report, cancel=cancel
                )
        except AllNoise as error:  # say the flag that keeps them
            raise AllNoise(error.path, error.points, "--keep-noise") from None
        check_cancelled(cancel, CANCELLED)
        voxels = merge_voxels(cloud.voxels)  # sorted, as the project writes models
        scene_path, target_path = outputs
        nothing = np.zeros((0, 3), dtype=np.int32)  # no vehicle yet
        write_model_pair(scene_path, target_path, voxels, nothing, None, cancel, report)
        return cloud


def _report(args, cloud, outputs) -> None:
    """One line: what was written, the scene's size, and where its voxel (0, 0, 0) lies in
    the cloud's own coordinates; a note of the points left out as noise."""
    from ladartui.cli.console import CliConsole as Console
    from ladartui.scene.las_crs import unit_words

    console = Console()
    say = lambda text: console.print(single_line(text), highlight=False, markup=False, soft_wrap=True)  # noqa: E731
    scene_path, target_path = outputs
    vs = args.voxel_size
    shape = cloud.voxels.max(axis=0) + 1
    horizontal, vertical = cloud.metres_per_unit
    x, y, z = cloud.origin / [horizontal, horizontal, vertical]
    across, up = unit_words(horizontal, cloud.unit), unit_words(vertical)
    if across == up:
        place = f"x {x:.3f}, y {y:.3f}, z {z:.3f} {across}"
    else:
        place = f"x {x:.3f}, y {y:.3f} {across}, z {z:.3f} {up}"
    say(
        f"wrote {scene_path} ({plural(len(cloud.voxels), 'voxel')}, {extent_metres(shape, vs)} m "
        f"at {vs:g} m) and "
        f"{target_path} (empty: no vehicle yet); voxel 0,0,0 is centred at {place} in the "
        f"coordinates of {args.mesh} (scene metres count from there)"
    )
    if cloud.left_out:
        say(
            f"note: {cloud.left_out:,} of {plural(cloud.points, 'point')} left out as noise or withheld "
            "(--keep-noise keeps them)"
        )
