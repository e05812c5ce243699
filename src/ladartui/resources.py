"""Up-front estimates of memory and work, and the limits they are checked against.

Work whose estimate exceeds the machine (memory) or the work limits (rays to
trace, Geiger-mode range-bin visits to fire) is refused with
``ResourceLimitError`` naming the input, the estimate and the limit, before
anything is allocated, traced or fired. ``LADARTUI_MAX_MEMORY`` (bytes),
``LADARTUI_MAX_RAYS`` and ``LADARTUI_MAX_BIN_VISITS`` override the limits;
``--max-rays`` on ``run`` too.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ladartui.errors import ResourceLimitError
from ladartui.number_text import plural

# Minutes of tracing at ~10 M rays/s, 5,000 times the bundled default run's 393,216
# rays: a mistyped scan count or sensor grid (2.7e12 rays, days) is refused, a real
# study stays well under.
DEFAULT_MAX_RAYS = 2 * 10**9
# Minutes of firing too: the bundled default scenario's pulse study at 1,000 pulses
# fires 5.8e9 detector range-bin visits, in about 12 s on two cores.
DEFAULT_MAX_BIN_VISITS = 5 * 10**10
# Content-sized parts of the occupancy build, per node (at most one per voxel, at most
# one per cell of its level over the extent): a brick's 16 words and block mask, and
# the int64 temporaries that work out the bricks' keys, order and cells (92 bytes a
# brick measured, 16 words allowed); a tile's or a region's 512 slots.
_BRICK_BYTES = 16 * 4 + 8 + 16 * 8
_NODE_BYTES = 512 * 4


def memory_override() -> int | None:
    """``LADARTUI_MAX_MEMORY`` in bytes, None when unset."""
    return _env_limit("LADARTUI_MAX_MEMORY", "a number of bytes >= 1")


def available_memory() -> int:
    """Bytes the run may allocate: ``LADARTUI_MAX_MEMORY``, else the least of the kernel's
    MemAvailable, the address space this process may still map (``ulimit -v``) and
    what its memory cgroup has left (a container's or a batch job's limit)."""
    override = memory_override()
    if override is not None:
        return override
    known = [v for v in (_free_memory(), _address_space_left(), _cgroup_left()) if v is not None]
    return max(0, min(known)) if known else 8 * 2**30


def _free_memory() -> int | None:
    available = _proc_kib("/proc/meminfo", "MemAvailable:")
    if available is not None:
        return available
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return None


def _address_space_left() -> int | None:
    """``RLIMIT_AS`` less the address space already mapped; None without a limit."""
    try:
        import resource
    except ImportError:  # not a POSIX system
        return None
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    return soft - (_proc_kib("/proc/self/status", "VmSize:") or 0)


def _proc_kib(path: str, key: str) -> int | None:
    """Bytes of the "``key`` N kB" line of a /proc file; None where it cannot be read."""
    try:
        with open(path, encoding="ascii") as lines:
            for line in lines:
                if line.startswith(key):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        pass
    return None


_CGROUP_ROOT = "/sys/fs/cgroup"
_PROC_CGROUP = "/proc/self/cgroup"
_NO_CGROUP_LIMIT = 2**60  # cgroup v1 writes "no limit" as a number near 2**63


def _cgroup_left() -> int | None:
    """The memory limit of this process's cgroup (v2 ``memory.max``, v1
    ``memory.limit_in_bytes``) less its usage; None without one. A container sees its
    own cgroup at the root of the mount, so the root is read where the path is not there.
    Usage counts the page cache, which the kernel gives back: its file pages are left out."""
    try:
        with open(_PROC_CGROUP, encoding="ascii") as groups:
            lines = groups.read().splitlines()
    except OSError:
        return None
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, path = parts
        if controllers == "":
            found = _cgroup_files(_CGROUP_ROOT, path, "memory.max", "memory.current", "")
        elif "memory" in controllers.split(","):
            found = _cgroup_files(
                os.path.join(_CGROUP_ROOT, "memory"),
                path,
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
                "total_",
            )
        else:
            continue
        if found is not None:
            return found
    return None


def _cgroup_files(mount: str, path: str, limit_name: str, usage_name: str, stat_prefix: str) -> int | None:
    """The least room left under a limit by the cgroup at ``path`` and every cgroup above
    it up to the mount (a batch job limits its job's group, not each task's); the mount
    alone where ``path`` is not there (a container's view). None without a limit."""
    root = os.path.normpath(mount)
    folder = os.path.normpath(os.path.join(root, path.lstrip("/")))
    if not (folder.startswith(root + os.sep) and os.path.isdir(folder)):
        folder = root
    least = None
    while True:
        room = _room_under_limit(folder, limit_name, usage_name, stat_prefix)
        if room is not None:
            least = room if least is None else min(least, room)
        if folder == root:
            return least
        folder = os.path.dirname(folder)


def _room_under_limit(folder: str, limit_name: str, usage_name: str, stat_prefix: str) -> int | None:
    """One cgroup's limit less its use (page cache aside); None without a limit."""
    try:
        with open(os.path.join(folder, limit_name), encoding="ascii") as handle:
            limit_text = handle.read().strip()
        with open(os.path.join(folder, usage_name), encoding="ascii") as handle:
            usage = int(handle.read().strip())
    except (OSError, ValueError):
        return None
    if limit_text == "max" or not limit_text.isdigit() or int(limit_text) >= _NO_CGROUP_LIMIT:
        return None
    cache = _cgroup_stat(folder, (stat_prefix + "inactive_file", stat_prefix + "active_file"))
    return int(limit_text) - max(0, usage - cache)


def _cgroup_stat(folder: str, keys: tuple[str, ...]) -> int:
    """The sum of ``keys`` in the cgroup's ``memory.stat`` (0 where unread)."""
    total = 0
    try:
        with open(os.path.join(folder, "memory.stat"), encoding="ascii") as handle:
            for line in handle:
                name, _, value = line.partition(" ")
                if name in keys and value.strip().isdigit():
                    total += int(value)
    except OSError:
        pass
    return total


_max_rays_flag: int | None = None


def set_max_rays(limit: int | None) -> None:
    """The work limit for this process (``--max-rays``); None goes back to the default."""
    global _max_rays_flag
    _max_rays_flag = limit


def max_rays() -> int:
    if _max_rays_flag is not None:
        return _max_rays_flag
    override = _env_limit("LADARTUI_MAX_RAYS", "a number of rays >= 1")
    return DEFAULT_MAX_RAYS if override is None else override


def max_bin_visits() -> int:
    override = _env_limit("LADARTUI_MAX_BIN_VISITS", "a number of visits >= 1")
    return DEFAULT_MAX_BIN_VISITS if override is None else override


def check_bin_visits(visits: int, source, what: str) -> None:
    """``ResourceLimitError`` when firing ``visits`` detector range-bin visits (detectors x
    range bins x pulses, over every look) would pass the work limit; ``what`` says
    where they come from."""
    limit = max_bin_visits()
    if visits > limit:
        raise ResourceLimitError(
            f"{source}: about {visits:.3g} detector range-bin visits to fire ({what}), more than "
            f"the limit of {limit:.3g}; use fewer pulses, fewer scans or a wider "
            "detection.bin_width_m, or raise the limit with LADARTUI_MAX_BIN_VISITS if this is meant"
        )


def _env_limit(name: str, expected: str) -> int | None:
    """The limit environment variable ``name`` sets (None when unset or empty);
    ResourceLimitError naming it when it is not a number >= 1: a typo must not lift a limit."""
    text = os.environ.get(name, "").strip()
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 1 <= value < math.inf:  # (not a FieldError: no scenario file holds it)
        raise ResourceLimitError(f"{name} = {text!r}: expected {expected}")
    return int(value)


# The extent-sized accelerations (column tops, empty cubes, halos) are built while they cost at most
# this, or ACCELERATION_SHARE times the content's nodes; a few voxels spread over a big
# box go without them (same answers, slower through the empty space), so memory follows
# what the scene holds.
ACCELERATION_FLOOR = 256 * 2**20
ACCELERATION_SHARE = 4
# Per voxel, a build without them sorts the voxels' brick keys (a key, its sorted copy,
# its brick number) in place of the grid of brick cells.
_SORTED_VOXEL_BYTES = 40
# The build's small arrays and objects, whatever the scene: a few voxels over a wide box
# peaked 316 bytes above an estimate of their root grid and nodes alone.
_BUILD_OVERHEAD = 4 * 2**10


def occupancy_bytes(lo, hi, count) -> int:
    """Estimated peak bytes to build the occupancy of ``count`` voxels spanning ``lo..hi``.

    The root grid is sized by the extent (coarsely); the column tops, empty cubes and
    halos too, when ``builds_columns`` and ``builds_accelerations`` say they are built.
    """
    lo, last = _corners(lo, hi)
    size = _BUILD_OVERHEAD + 4 * _cells(lo, last, 9)  # the root grid: a word a 512-voxel cell
    nodes = _node_bytes(lo, last, count)
    columns = _column_bytes(lo, last)
    if _affordable(columns, nodes):
        size += columns
    accelerations = _acceleration_bytes(lo, last)
    if _affordable(accelerations, nodes):
        return int(size + nodes + accelerations)
    return int(size + nodes + _SORTED_VOXEL_BYTES * int(count))


def builds_accelerations(lo, hi, count) -> bool:
    """Whether the occupancy of ``count`` voxels spanning ``lo..hi`` gets the empty cubes
    and halos: when they cost at most ACCELERATION_FLOOR or ACCELERATION_SHARE times the
    content's nodes."""
    lo, last = _corners(lo, hi)
    return _affordable(_acceleration_bytes(lo, last), _node_bytes(lo, last, count))


def builds_columns(lo, hi, count) -> bool:
    """Whether the occupancy of ``count`` voxels spanning ``lo..hi`` gets its column tops
    (4 bytes an 8 x 8 voxel column of the root grid), on the same terms as the cubes:
    two voxels 10^6 voxels apart on x and y would need 58 GiB of them."""
    lo, last = _corners(lo, hi)
    return _affordable(_column_bytes(lo, last), _node_bytes(lo, last, count))


def _column_bytes(lo, last) -> int:
    """4 bytes an 8 x 8 voxel column over the root grid's cells on x and y."""
    return 4 * 64 * 64 * _cells(lo[:2], last[:2], 9)


def _affordable(accelerations: int, nodes: int) -> bool:
    return accelerations <= max(ACCELERATION_FLOOR, ACCELERATION_SHARE * nodes)


def _corners(lo, hi):
    lo = np.asarray(lo, dtype=object)  # Python ints: extents near 2**31 overflow int64 products
    return lo, np.asarray(hi, dtype=object) - 1


def _acceleration_bytes(lo, last) -> int:
    cubes = [int(b >> 3) - int(a >> 3) + 1 for a, b in zip(lo, last)]
    cells4 = [int(b >> 2) - int(a >> 2) + 3 for a, b in zip(lo, last)]
    # the brick cells: a 0/1 grid (kept for the empty cubes' 4 octants) and a brick number each
    size = (1 + 4 + 4) * cubes[0] * cubes[1] * cubes[2]
    # halos: a bool grid, its grown copy and a temporary of the growing, then the bits
    size += 3 * (cubes[0] + 2) * (cubes[1] + 2) * (cubes[2] + 2)  # brick halo
    size += 3 * cells4[0] * cells4[1] * cells4[2]  # 4-voxel halo
    return size


def _node_bytes(lo, last, count) -> int:
    count = int(count)
    return _BRICK_BYTES * min(count, _cells(lo, last, 3)) + _NODE_BYTES * (
        min(count, _cells(lo, last, 6)) + min(count, _cells(lo, last, 9))
    )


def _cells(lo, last, shift) -> int:
    """Cells of ``2**shift`` voxels a side over the extent ``lo..last``."""
    out = 1
    for a, b in zip(lo, last):
        out *= int(b >> shift) - int(a >> shift) + 1
    return out


def check_occupancy(lo, hi, count, source="voxels") -> int:
    """The estimate, or ``ResourceLimitError`` when it exceeds the available memory."""
    need = occupancy_bytes(lo, hi, count)
    limit = available_memory()
    if need > limit:
        extent = " x ".join(str(int(b) - int(a)) for a, b in zip(lo, hi))
        raise ResourceLimitError(
            f"{source}: {int(count):,} voxels spanning {extent} voxels need about "
            f"{gib(need)} for the tracing structures, more than the {gib(limit)} of memory "
            "available; crop the scene or use a coarser voxel size"
        )
    return need


# How a scenario's ray limit is raised: validate reads the variable too, and has no
# --max-rays.
RAISE_RAYS = "LADARTUI_MAX_RAYS or run's --max-rays"
# work with no --max-rays of its own (trace, pulses, study)
RAISE_BY_ENV = "LADARTUI_MAX_RAYS"
# the TUI's process takes the variable from the shell that started it
RAISE_IN_TUI = "LADARTUI_MAX_RAYS, set before ladartui starts,"
# a sweep has no --max-rays; its workers, started from this process's environment, read the variable
SWEEP_RAISE_RAYS = "LADARTUI_MAX_RAYS (a sweep's workers read it)"


class RayLimitError(ResourceLimitError):
    """More rays than the work limit; keeps its figures so the advice can be given again."""

    def __init__(self, rays, source, limit, raise_with=RAISE_RAYS):
        self.rays, self.source, self.limit, self.raise_with = rays, source, limit, raise_with
        super().__init__(
            f"{source}: about {rays:.3g} rays to trace, more than the limit of {limit:.3g} "
            f"(raise it with {raise_with} if this is meant)"
        )

    def __reduce__(self):  # its own arguments, so it crosses to and from a worker process
        return RayLimitError, (self.rays, self.source, self.limit, self.raise_with)

    def advising(self, raise_with: str) -> RayLimitError:
        """The same refusal, saying ``raise_with`` is how to raise the limit."""
        return RayLimitError(self.rays, self.source, self.limit, raise_with)


def sweep_advice(error: Exception) -> str:
    """An error's message as a sweep can follow it: a ray limit names SWEEP_RAISE_RAYS."""
    if isinstance(error, RayLimitError):
        error = error.advising(SWEEP_RAISE_RAYS)
    return str(error)


def check_rays(rays, source, limit=None, raise_with=RAISE_RAYS) -> None:
    """``RayLimitError`` when ``rays`` exceeds the work limit; ``raise_with`` says how
    the caller's user raises the limit."""
    limit = max_rays() if limit is None else limit
    if rays > limit:
        raise RayLimitError(rays, source, limit, raise_with)


def gib(nbytes) -> str:
    """A size in words: TiB from 999.5 GiB up (whole ones past 999), GiB from 128 MiB up,
    then MiB, KiB, bytes ("1 byte")."""
    if nbytes >= 999.5 * 2**30:  # not "1e+03 GiB"
        tib = nbytes / 2**40
        return f"{tib:.3g} TiB" if tib < 1000 else f"{round(tib):,} TiB"
    if nbytes >= 2**27:
        return f"{nbytes / 2**30:.3g} GiB"
    if nbytes >= 2**20:
        return f"{nbytes / 2**20:.3g} MiB"
    if nbytes >= 2**10:
        return f"{nbytes / 2**10:.3g} KiB"
    return plural(int(nbytes), "byte")
