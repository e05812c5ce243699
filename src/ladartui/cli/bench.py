"""``ladartui bench``: tracing speed of every available backend and method.

On the ``reference`` scene (generated into the cache folder when absent) with
a 128 x 128 sensor and 4 x 4 rays per detector, it measures rays per second
at 45 degrees depression and at nadir (median of several runs after a
warm-up until each backend's speed settles, ``warm_up``; backends take turns,
each turn an untimed run then a timed one),
the occupancy set-up time and its memory. Two views: ``wide`` (the sensor's
default 10 degree field of view from 85 m, both methods) and ``narrow`` (a 3
degree view from 150 m up, looking along bearing 60 degrees, exact only: the
geometry of the side-by-side comparison with Embree). Backends come from the
registry, so a new backend appears here by registering itself. Every row keeps
its median seconds by pass; ``--passes`` prints them (cli/bench_passes.py).
"""

from __future__ import annotations

import contextlib
import json
import math
import statistics
import time
from pathlib import Path

import numpy as np

from ladartui.atomic import atomic_path
from ladartui.cli.bench_passes import pass_medians, print_passes
from ladartui.cli.flags import MAX_RUNS, run_count
from ladartui.errors import BackendUnavailable
from ladartui.number_text import plural
from ladartui.tracing.backend import METHODS

DEPRESSIONS = (45.0, 90.0)
SLANT_RANGE_M = 85.0  # aircraft distance from the aimed target (the default orbit's minimum)
# The narrow view: a long lens from high up (the peer comparison's geometry).
NARROW_FOV = 3.0
NARROW_ALTITUDE_M = 150.0
NARROW_BEARING = 60.0  # compass bearing from the aircraft to the target
VIEWS = ("wide", "narrow")
# Timed runs (median quoted): a case, and a whole orbit; fewer with --quick.
RUNS, QUICK_RUNS = 7, 2
ORBIT_RUNS, QUICK_ORBIT_RUNS = 3, 1
# Before the first timed run each backend traces until its speed settles: its first
# calls compile kernels and try both orders, and a device may raise its clocks under
# load (an H200 that stayed at 345-525 MHz, not 1,980, traced at half the rays/s).
WARM_WINDOW_S = 0.25
WARM_MOST_S = 5.0


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "bench",
        help="measure tracing speed of every available backend and method",
        description="Trace the reference scene with a 128x128 sensor (4x4 rays per detector) "
        "at 45 degrees and at nadir, in a wide view (10 degrees from 85 m) and a narrow one "
        "(3 degrees from 150 m up, exact only); report rays/s, set-up time and occupancy memory.",
    )
    parser.add_argument(
        "--quick", action="store_true", help="fewer runs and a 64x64 sensor (a smoke test, not a measurement)"
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument(
        "--runs",
        type=int,
        default=None,
        help=f"timed runs per case, 1 to {MAX_RUNS}, median quoted (default {RUNS}, "
        f"{QUICK_RUNS} with --quick; with --orbit {ORBIT_RUNS}, {QUICK_ORBIT_RUNS} with --quick)",
    )
    parser.add_argument(
        "--passes",
        action="store_true",
        help="also show where the exact scans spend their time: milliseconds by pass "
        "(rays to cells, bins, voxels in view, tile lists, tile tests, ...); not with --orbit",
    )
    parser.add_argument(
        "--orbit",
        action="store_true",
        help="instead, time a whole 36-scan orbit (scene and target-only runs, "
        "depth rule, fusion, measures) end to end after a warm-up",
    )
    parser.set_defaults(handler=run)


def run(args):
    if args.passes and args.orbit:
        from ladartui.errors import LadarError

        raise LadarError(
            "--passes and --orbit do not combine: --orbit times whole orbits, with no time by pass; drop one"
        )
    if args.runs is not None:
        run_count("--runs", args.runs)
    from ladartui.cli.progress import sigterm_as_interrupt
    from ladartui.errors import Cancelled

    try:
        with sigterm_as_interrupt(), _status() as say:
            if args.orbit:
                report = run_orbit_bench(quick=args.quick, runs=args.runs, progress=say)
            else:
                report = run_bench(quick=args.quick, runs=args.runs, progress=say)
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: its exit status says which
        raise Cancelled("bench cancelled; nothing was measured") from None
    if args.orbit:
        if args.json:
            print(json.dumps(report, indent=2))
        else:
            print(
                f"{report['scans']}-scan orbit on {report['scene']}, {report['sensor']}, "
                f"{report['backend']}: median {report['median_seconds']:.2f} s end to end "
                f"over {plural(report['runs'], 'run')} after a warm-up "
                f"(trace {report['median_trace_seconds']:.2f} s; "
                f"{report['rays']:,} rays over both runs)"
            )
        return 0
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        _print_table(report)
        if args.passes:
            from ladartui.cli.console import CliConsole as Console

            print_passes(Console(), report)
    return 0


@contextlib.contextmanager
def _status():
    """``say(text)``: what the bench does now, on a status line of stderr (a terminal only)."""
    from ladartui.cli.console import CliConsole

    console = CliConsole(stderr=True)
    if not console.is_terminal:
        yield lambda text: None
        return
    with console.status("bench: starting", refresh_per_second=2) as status:  # little CPU beside the timing
        yield lambda text: status.update(f"bench: {text}")


ORBIT_SCANS = 36
ORBIT_SLANT_RANGE_M = 150.0
ORBIT_DEPRESSION = 45.0


def bench_grid(quick: bool) -> int:
    """Detectors a side of the bench's sensor: 64 with --quick, else 128."""
    return 64 if quick else 128


def run_orbit_bench(quick=False, runs=None, backend="numba", progress=None) -> dict:
    """Median seconds of a whole orbit simulation (both runs), after one warm-up run, with
    ``bench_grid(quick)`` detectors a side; ``progress(text)`` hears what it does."""
    say = progress or (lambda text: None)
    runs = runs or (QUICK_ORBIT_RUNS if quick else ORBIT_RUNS)
    grid = bench_grid(quick)
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.scenario import Scenario
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate

    scene, label = load_bench_scene(say)
    centre = scene.target.astype(np.float64).mean(axis=0) * scene.voxel_size
    e = math.radians(ORBIT_DEPRESSION)
    orbit = Orbit(
        centre=tuple(centre),
        radius=ORBIT_SLANT_RANGE_M * math.cos(e),
        altitude=ORBIT_SLANT_RANGE_M * math.sin(e),
        scans=ORBIT_SCANS,
    )
    sensor = Sensor(grid=grid, ray_grid=4, fov=5.0)
    folder = cache_dir()
    scenario = Scenario(
        folder / "orbit-bench.toml",
        folder / "reference.txt",
        scene.voxel_size,
        sensor,
        FlightPlan(segments=(orbit,)),
        backend=backend,
    )
    say("orbit warm-up (kernels, occupancy)")
    simulate(scenario, scene=scene, write=False)  # warm-up: kernels, occupancy
    totals, traces = [], []
    for run in range(runs):
        say(f"orbit run {run + 1} of {runs}")
        started = time.perf_counter()
        result = simulate(scenario, scene=scene, write=False)
        totals.append(time.perf_counter() - started)
        traces.append(result.timings.get("trace", float("nan")))
    return {
        "scene": label,
        "sensor": f"{sensor.grid}x{sensor.grid} detectors, {sensor.ray_grid}x{sensor.ray_grid} rays each, "
        f"{sensor.fov:g} degree field of view",
        "scans": ORBIT_SCANS,
        "slant_range_m": ORBIT_SLANT_RANGE_M,
        "depression": ORBIT_DEPRESSION,
        "backend": result.backend,
        "runs": runs,
        "rays": 2 * ORBIT_SCANS * sensor.rays_per_scan,
        "median_seconds": statistics.median(totals),
        "all_seconds": totals,
        "median_trace_seconds": statistics.median(traces),
        "obscured_coverage": result.measures.obscured_coverage,
        "unobscured_coverage": result.measures.unobscured_coverage,
    }


def cache_dir() -> Path:
    """Where the generated benchmark scene is kept between runs (made when missing)."""
    from ladartui.user_data import data_home, made_folder

    return made_folder(data_home() / "bench")


def load_bench_scene(progress=None):
    """(scene, label): the ``reference`` scene, generated into the cache folder when absent."""
    from ladartui.scene.model import Scene

    path = cache_dir() / "reference-0.npz"
    if not path.exists():
        from ladartui.scene.generate import generate_scene

        if progress is not None:
            progress("generating the reference scene (first run only)")
        generated = generate_scene("reference", 0)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as handle:
                np.savez(
                    handle,
                    voxels=generated.voxels,
                    target=generated.target,
                    shape=np.array(generated.shape),
                    voxel_size=generated.voxel_size,
                )
    with np.load(path) as data:
        scene = Scene(
            data["voxels"],
            data["target"],
            float(data["voxel_size"]),
            shape=tuple(int(v) for v in data["shape"]),
            name="reference",
        )
    return scene, "reference"


def bench_rays(scene, depression, grid=128, ray_grid=4, view="wide"):
    """Origins and directions (metres) of one look at the target (else the scene centre).

    ``wide``: the default field of view from SLANT_RANGE_M away, looking north;
    ``narrow``: NARROW_FOV from NARROW_ALTITUDE_M up, looking along NARROW_BEARING.
    """
    from ladartui.flight import ScanPose, aim_at
    from ladartui.sensor import Sensor

    nx, ny, _ = scene.shape
    if len(scene.target):
        centre = scene.target.astype(np.float64).mean(axis=0) * scene.voxel_size
    else:
        centre = np.array([nx / 2, ny / 2, 0.0]) * scene.voxel_size
    e = math.radians(depression)
    if view == "narrow":
        height = NARROW_ALTITUDE_M - centre[2]
        back = height / math.tan(e) if depression < 90.0 else 0.0
        b = math.radians(NARROW_BEARING)
        aircraft = centre + np.array([-back * math.sin(b), -back * math.cos(b), height])
        sensor = Sensor(grid=grid, ray_grid=ray_grid, fov=NARROW_FOV)
    else:
        aircraft = centre + SLANT_RANGE_M * np.array([0.0, -math.cos(e), math.sin(e)])
        sensor = Sensor(grid=grid, ray_grid=ray_grid)
    if depression >= 90.0:
        aircraft[:2] = centre[:2]
    pose = aim_at(
        ScanPose(float(aircraft[0]), float(aircraft[1]), float(aircraft[2]), 0.0, 0.0, 90.0), centre.tolist()
    )
    origins, directions, _ = sensor.rays(pose)
    return origins, directions


def run_bench(quick=False, runs=None, progress=None) -> dict:
    """Measure every available backend and method; returns the report as a dict.
    ``progress(text)`` hears what it does."""
    say = progress or (lambda text: None)
    from ladartui.scene.occupancy import Occupancy
    from ladartui.tracing import trace
    from ladartui.tracing.backend import backend_status, get_backend

    runs = runs or (QUICK_RUNS if quick else RUNS)
    grid = bench_grid(quick)
    scene, label = load_bench_scene(say)
    say("building the occupancy")
    started, cpu_started = time.perf_counter(), time.process_time()
    occupancy = Occupancy.build(scene.voxels, scene.shape)
    setup = time.perf_counter() - started
    setup_cpu = time.process_time() - cpu_started
    report = {
        "scene": label,
        "shape": list(scene.shape),
        "voxels": int(occupancy.count),
        "voxel_size": scene.voxel_size,
        "setup_seconds": setup,
        "setup_cpu_seconds": setup_cpu,
        "occupancy_bytes": occupancy.nbytes,
        "occupancy": occupancy.summary(),
        "sensor": f"{grid}x{grid} detectors, 4x4 rays each",
        "runs": runs,
        "slant_range_m": SLANT_RANGE_M,
        "views": {
            "wide": f"10 degree view from {SLANT_RANGE_M:g} m, looking north",
            "narrow": f"{NARROW_FOV:g} degree view from {NARROW_ALTITUDE_M:g} m up, "
            f"looking along bearing {NARROW_BEARING:g}, exact only",
        },
        "backends": {},
        "results": [],
    }
    rays = {(view, d): bench_rays(scene, d, grid=grid, view=view) for view in VIEWS for d in DEPRESSIONS}
    backends = {}
    for name, reason in backend_status().items():
        report["backends"][name] = reason or "available"
        if not reason:
            try:
                backends[name] = get_backend(name)
            except BackendUnavailable:
                continue
    origins, directions = rays[("wide", DEPRESSIONS[0])]
    say("warming up " + ", ".join(backends) + " (kernels, device clocks)")
    report["warm_up"] = {
        name: warm_up(
            lambda name=name: trace(
                occupancy, origins, directions, backend=name, voxel_size=scene.voxel_size
            ),
            most=0.0 if quick else WARM_MOST_S,
        )
        for name in backends
    }
    for method in METHODS:
        for (view, depression), (origins, directions) in rays.items():
            if view == "narrow" and method == "march":
                continue  # thousands of samples a ray from that height: minutes, not a bench
            kwargs = dict(method=method, step=0.5, voxel_size=scene.voxel_size)
            first, results = {}, {}
            for name in backends:
                warm = time.perf_counter()
                results[name] = trace(occupancy, origins, directions, backend=name, **kwargs)
                first[name] = time.perf_counter() - warm
            # Backends take turns run by run, so a slow spell of this shared machine
            # falls on all of them and their ratio stays fair. Each turn traces once
            # untimed first: in a real run a backend's scans follow each other, and the
            # other backend's data should not be in the caches of the timed one.
            times: dict[str, list[float]] = {name: [] for name in backends}
            cpu: dict[str, list[float]] = {name: [] for name in backends}
            orders: dict[str, set[str]] = {name: set() for name in backends}  # over the timed runs
            passes: dict[str, list[dict[str, float]]] = {name: [] for name in backends}
            for run in range(runs):
                say(f"{method} {view} {depression:g} deg: run {run + 1} of {runs}")
                for name in backends:
                    trace(occupancy, origins, directions, backend=name, **kwargs)
                    c = time.process_time()
                    t = time.perf_counter()
                    timed = trace(occupancy, origins, directions, backend=name, **kwargs)
                    times[name].append(time.perf_counter() - t)
                    orders[name].add(timed.info.get("order", "ray"))
                    passes[name].append(timed.info["passes"])
                    cpu[name].append(time.process_time() - c)
            for name, backend in backends.items():
                median = statistics.median(times[name])
                cpu_median = statistics.median(cpu[name])
                result = results[name]
                report["results"].append(
                    {
                        "backend": name,
                        "method": method,
                        "view": view,
                        "depression": depression,
                        "rays": len(origins),
                        "rays_per_second": len(origins) / median,
                        "median_seconds": median,
                        "run_seconds": times[name],  # run by run, in turn with the others
                        "first_call_seconds": first[name],
                        # On a shared machine wall time includes waiting for the
                        # cores; rays per CPU-second (all threads) does not.
                        "cpu_seconds": cpu_median,
                        "rays_per_cpu_second": len(origins) / cpu_median if cpu_median > 0 else None,
                        "voxel_hits": float(np.mean(result.kind == 1)),
                        "ground_hits": float(np.mean(result.kind == 2)),
                        "order": "/".join(sorted(orders[name])),
                        # Median seconds by pass (tracing/passes.py), "other" the rest of a call.
                        "passes": pass_medians(times[name], passes[name]),
                        "device": _device(backend.describe()),
                        # f32 where an adapter without shader-f64 traced "f64" calls
                        "precision": result.info.get("precision", "f64"),
                    }
                )
    _add_ratios(report["results"])
    return report


def _device(described: dict) -> str:
    """The adapter, or the CPU with its threads and numba's threading layer (TBB or OpenMP)."""
    if described.get("adapter"):
        return str(described["adapter"])
    return f"cpu, {described.get('threads', '?')} threads ({described.get('threading_layer', '?')})"


def warm_up(trace_once, most=WARM_MOST_S, window=WARM_WINDOW_S, clock=time.perf_counter) -> dict:
    """Call ``trace_once`` once (that call compiles: it may take most of a minute),
    then until the median call of a ``window`` of seconds is within 5 % of the
    window's before, or ``most`` seconds have passed after it. Returns the calls
    made and the seconds they took, the first's included."""
    first = clock()
    trace_once()
    calls, before, times = 1, None, []
    started = clock()
    while clock() - started < most:
        t = clock()
        trace_once()
        calls += 1
        times.append(clock() - t)
        if sum(times) >= window:
            median = statistics.median(times)
            if before is not None and abs(median - before) <= 0.05 * before:
                break
            before, times = median, []
    return {"calls": calls, "seconds": clock() - first}


def _add_ratios(results):
    """Each row's speed as a share of numba's on the same method, view and angle
    (``vs_numba``): the median over runs of numba's time over the row's in the same
    turn, so a slow spell of the machine, which falls on both runs of a turn, moves
    it less than it moves either median."""
    numba = {
        (r["method"], r["view"], r["depression"]): r["run_seconds"]
        for r in results
        if r["backend"] == "numba"
    }
    for row in results:
        base = numba.get((row["method"], row["view"], row["depression"]))
        pairs = [b / t for b, t in zip(base or (), row["run_seconds"]) if t > 0]
        row["vs_numba"] = statistics.median(pairs) if pairs else None


def _orders_shown(orders: str) -> str:
    """A row's orders (``run_bench``'s "object+ray/ray") as the table shows them: "mix ray"."""
    names = {"object": "obj", "ray": "ray", "object+ray": "mix"}
    return " ".join(names.get(order, order) for order in orders.split("/"))


def _print_table(report):
    from rich import box
    from rich.table import Table

    from ladartui.cli.console import CliConsole as Console

    console = Console()
    console.print(
        f"scene {report['scene']} {report['shape']}, {report['voxels']:,} voxels; "
        f"occupancy {report['occupancy_bytes'] / 2**20:.1f} MiB built in "
        f"{report['setup_seconds']:.2f} s ({report['setup_cpu_seconds']:.2f} CPU-s); "
        f"{report['sensor']}; median of "
        f"{plural(report['runs'], 'run')} after a warm-up ("
        + ", ".join(
            f"{name} {plural(w['calls'], 'call')} in {w['seconds']:.1f} s"
            for name, w in report["warm_up"].items()
        )
        + ")"
    )
    # Fits 80 columns (an SSH terminal): millions in the headers, not on every figure;
    # a row whose timed runs took several orders lists them a line each.
    table = Table(box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True, show_edge=False)
    for name in ("backend", "method", "view", "depr.", "order"):
        table.add_column(name, no_wrap=name != "order", min_width=len(name))
    for name in ("M rays/s", "x numba", "M/CPU-s", "voxel", "ground"):
        table.add_column(name, no_wrap=True, justify="right", min_width=len(name))
    devices = {}
    for row in report["results"]:
        per_cpu = row["rays_per_cpu_second"]
        devices[row["backend"]] = row["device"]
        table.add_row(
            row["backend"],
            row["method"],
            row["view"],
            f"{row['depression']:g}",
            _orders_shown(row["order"]),
            f"{row['rays_per_second'] / 1e6:.2f}",
            f"{row['vs_numba']:.2f}" if row.get("vs_numba") is not None else "-",
            f"{per_cpu / 1e6:.2f}" if per_cpu else "-",
            f"{row['voxel_hits']:.1%}",
            f"{row['ground_hits']:.1%}",
        )
    console.print(table)
    console.print(f"views: wide {report['views']['wide']}; narrow {report['views']['narrow']}")
    console.print(
        "order: obj object, ray ray order, mix both in one call (several: the timed runs "
        "differed); devices: " + "; ".join(f"{name} {device}" for name, device in devices.items())
    )
    in_f32 = sorted({row["backend"] for row in report["results"] if row.get("precision") == "f32"})
    for name in in_f32:
        console.print(
            f"{name} traced in f32 (its adapter has no float64): its x numba compares f32 with f64",
            markup=False,
        )
    for name, status in report["backends"].items():
        if status != "available":
            console.print(f"[dim]{name}: {status}[/dim]")
