"""One sweep variant: the base scenario with the variant's parameters, run, made a row.

Flight parameters act on the base scenario's path preset segment (the first
orbit, fly-past or standoff segment of its flight plan):

* ``preset`` replaces the whole flight plan by one segment of that preset,
  taking from the base's preset segment what still applies (target point,
  altitude, scans, orientation) and from the variant the rest;
* ``radius`` (orbit), ``standoff`` (fly-past, standoff), ``altitude``,
  ``scans``, ``arc`` (orbit) set that segment's fields;
* ``heading_offset`` turns the path about its target: it is added to the
  bearing (from the target) of the orbit's first scan, the fly-past's
  closest point or the standoff line (and to a standoff's own heading, when it
  gives one), and a new preset keeps the base's
  bearing (so an orbit starting south becomes a fly-past passing south);
* ``speed`` is the aircraft speed; ``sensor_grid``, ``ray_grid``, ``fov``
  and ``depth_resolution`` set the sensor.

A fly-past built from another preset is ``2 * standoff`` long (it spans the
bearings 45 degrees either side of the closest point); a standoff sweep built
from another preset, or with a new number of scans, puts ``scans`` scans
evenly from ``standoff`` in to ``standoff / scans``, far to near; otherwise
the base's standoff distances are scaled so the farthest is ``standoff``.
"""

from __future__ import annotations

import dataclasses
import os
import socket
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ladartui.errors import BackendUnavailable, Cancelled, FieldError, LadarError, ResourceLimitError
from ladartui.sweep.columns import PER_TARGET_KEY, per_target_columns

PRESET_KINDS = ("orbit", "flypast", "standoff")
SENSOR_FIELDS = {
    "sensor_grid": "grid",
    "ray_grid": "ray_grid",
    "fov": "fov",
    "depth_resolution": "depth_resolution",
}
FLIGHT_PARAMETERS = ("preset", "radius", "standoff", "altitude", "scans", "heading_offset", "arc")

# A path built without a base preset starts (or passes closest) due south of the target.
DEFAULT_BEARING = 180.0

# Which flight parameters apply to each preset ("radius or standoff").
APPLIES = {
    "orbit": {"radius", "altitude", "scans", "heading_offset", "arc"},
    "flypast": {"standoff", "altitude", "scans", "heading_offset"},
    "standoff": {"standoff", "altitude", "scans", "heading_offset"},
}


def applicable(params: dict) -> dict:
    """``params`` without flight parameters that do not apply to its preset.

    So a grid of presets times radii times standoffs does not fly the same
    orbit once per standoff. Without a ``preset`` the base's preset decides,
    and nothing is dropped here.
    """
    preset = params.get("preset")
    if preset not in APPLIES:
        return dict(params)
    keep = APPLIES[preset] | {"preset"}
    return {k: v for k, v in params.items() if k not in FLIGHT_PARAMETERS or k in keep}


def preset_segment(flight):
    """Index and segment of the first orbit, fly-past or standoff segment (None, None if none)."""
    for index, segment in enumerate(flight.segments):
        if getattr(segment, "kind", None) in PRESET_KINDS:
            return index, segment
    return None, None


def target_point(scene) -> tuple[float, float, float]:
    """Centre of the scene's target model in metres (the aim point when the base has none)."""
    x, y, z = (float(v) for v in scene.target_centre_m())
    return (x, y, z)


def _flypast_turn(side):
    """Degrees from a fly-past's heading to the bearing of the target: the side it passes."""
    return 90.0 if side == "right" else -90.0


def _base_geometry(segment):
    """What a variant's preset takes from the base's: target, bearing, distance, scans.

    The bearing is that of the base path's first or closest scan, from the
    target. Orbit: its start bearing; standoff: its bearing; fly-past: the side
    of the target it passes (target on the right: 90 degrees left of the
    heading). Without a base preset segment only the bearing has a default.
    """
    if segment is None:
        return None, DEFAULT_BEARING, None, None
    if segment.kind == "orbit":
        return segment.centre, segment.start_bearing, segment.radius, segment.scans
    if segment.kind == "flypast":
        return (
            segment.target,
            segment.heading - _flypast_turn(segment.side),
            segment.standoff,
            segment.scans,
        )
    return segment.target, segment.bearing, max(segment.standoffs), len(segment.standoffs)


def _need(name, value, preset):
    if value is None:
        raise FieldError(
            name, None, f"a value in the sweep, since the base scenario has no {preset} to take it from"
        )
    return value


def _standoff_distances(distance, scans):
    distance, scans = float(distance), int(scans)
    if scans < 1:
        raise FieldError("scans", scans, "an integer >= 1")
    return tuple(distance * (scans - k) / scans for k in range(scans))


def build_preset(params: dict, base_segment, default_target):
    """The flight segment of this variant when it names a ``preset`` (or changes the base's)."""
    from ladartui.flight import FlyPast, Orbit, Standoff

    preset = params.get("preset") or base_segment.kind
    same = base_segment is not None and base_segment.kind == preset
    base_target, base_bearing, base_distance, base_scans = _base_geometry(base_segment)
    target = base_target or default_target()
    bearing = base_bearing + params.get("heading_offset", 0.0)
    altitude = params.get("altitude", getattr(base_segment, "altitude", None))
    scans = params.get("scans", base_scans)
    distance_name = "radius" if preset == "orbit" else "standoff"
    distance = params.get(distance_name)
    if distance is None:
        # A changed preset keeps the base's distance from the target.
        distance = params.get("standoff" if preset == "orbit" else "radius", base_distance)
    altitude = _need("altitude", altitude, preset)
    scans = _need("scans", scans, preset)
    distance = _need(distance_name, distance, preset)

    if preset == "orbit":
        fields = dataclasses.asdict(base_segment) if same else {}
        fields.update(centre=target, radius=distance, altitude=altitude, scans=scans, start_bearing=bearing)
        if "arc" in params:
            fields["arc"] = params["arc"]
        fields.setdefault("aim_at", None)
        return Orbit(**fields)
    if preset == "flypast":
        fields = dataclasses.asdict(base_segment) if same else {}
        side = fields.get("side", "right")
        length = fields.get("length", 2.0 * float(distance))
        fields.update(
            target=target,
            standoff=distance,
            altitude=altitude,
            scans=scans,
            heading=bearing + _flypast_turn(side),
            length=length,
        )
        return FlyPast(**fields)
    fields = dataclasses.asdict(base_segment) if same else {}
    farthest = max(base_segment.standoffs) if same else 0.0
    if same and "scans" not in params and farthest > 0:
        # Keep the base's spacing, scaled so its farthest scan is at the standoff.
        standoffs = tuple(s * float(distance) / farthest for s in base_segment.standoffs)
    else:
        standoffs = _standoff_distances(distance, scans)
    fields.update(target=target, standoffs=standoffs, altitude=altitude, bearing=bearing)
    if not same:
        fields["heading"] = None
    elif fields.get("heading") is not None:  # the base's own heading turns with its line
        fields["heading"] += params.get("heading_offset", 0.0)
    return Standoff(**fields)


def variant_flight(base_flight, params: dict, scene_loader):
    """The base flight plan with this variant's flight parameters applied."""
    from ladartui.flight import FlightPlan

    flight_params = {k: v for k, v in params.items() if k in FLIGHT_PARAMETERS}
    if not flight_params:
        return base_flight
    index, segment = preset_segment(base_flight)
    if "preset" not in params and segment is None:
        name = next(iter(flight_params))
        raise FieldError(
            name,
            params[name],
            "a 'preset' in the sweep: the base scenario's "
            "flight plan has no orbit, flypast or standoff segment to vary",
        )
    if "preset" not in params:
        preset = segment.kind
        wrong = [k for k in flight_params if k not in APPLIES[preset]]
        if wrong:
            raise FieldError(
                wrong[0],
                params[wrong[0]],
                f"a parameter of the base's {preset} (" + ", ".join(sorted(APPLIES[preset])) + ")",
            )

    def default_target():
        return target_point(scene_loader())

    new_segment = build_preset(params, segment, default_target)
    if "preset" in params:
        return FlightPlan(start=None, segments=(new_segment,))
    segments = list(base_flight.segments)
    segments[index] = new_segment
    return dataclasses.replace(base_flight, segments=tuple(segments))


def apply_parameters(base, params: dict, scene_loader=lambda: None):
    """The scenario of one variant: ``base`` with ``params`` applied (FieldError if impossible).

    ``scene_loader`` gives the scene (for its target centre) only when a
    preset must be built without a target point in the base.
    """
    try:
        sensor_changes = {SENSOR_FIELDS[k]: v for k, v in params.items() if k in SENSOR_FIELDS}
        changes = {}
        if sensor_changes:
            changes["sensor"] = dataclasses.replace(base.sensor, **sensor_changes)
        flight = variant_flight(base.flight, params, scene_loader)
        if flight is not base.flight:
            changes["flight"] = flight
            flight.poses()  # build now, so a bad segment fails here with its field
        if "speed" in params:
            _check_speed_matters(flight, params["speed"])
            changes["speed"] = params["speed"]
        return base.with_changes(**changes) if changes else base
    except FieldError as error:
        raise _as_parameter(error, params) from None


def _check_speed_matters(flight, speed) -> None:
    """A flight that is one flight log keeps the log's clock: every speed gives the same
    variant, ranked as many."""
    if flight.one_log:
        raise FieldError(
            "speed",
            speed,
            "a base flown at its speed: its one flight log keeps the log's own clock, so the "
            "speed changes nothing",
        )


def _as_parameter(error: FieldError, params: dict) -> FieldError:
    """Name the sweep parameter behind a field error (``grid`` -> ``sensor_grid``)."""
    field = error.field.rsplit(".", 1)[-1]
    for name, sensor_field in SENSOR_FIELDS.items():
        if sensor_field == field and name in params:
            return FieldError(name, params[name], error.expected)
    aliases = {
        "centre": "preset",
        "target": "preset",
        "start_bearing": "heading_offset",
        "bearing": "heading_offset",
        "heading": "heading_offset",
        "standoffs": "standoff",
        "speed_mps": "speed",
    }
    name = aliases.get(field, field)
    if name in params:
        return FieldError(name, params[name], error.expected)
    return error


def _flatten(prefix, value, out):
    if isinstance(value, dict):
        for key, item in value.items():
            _flatten(f"{prefix}.{key}" if prefix else key, item, out)
    else:
        out[prefix] = value


def measure_columns(measures: dict, reserved=()) -> dict:
    """Measures as flat columns (``obscured_directions.mean_direction``); lists stay lists."""
    flat: dict[str, object] = {}
    _flatten("", measures, flat)
    renames = {"scans": "scan_count"}
    out = {}
    for key, value in flat.items():
        key = renames.get(key, key)
        if key in reserved:
            key = f"measure.{key}"
        out[key] = value
    return out


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def run_variant(
    base, params: dict, variant_id: str, base_digest: str = "", scene=None, simulate_options=None
) -> dict:
    """Simulate one variant (scene and target-only runs, nothing written) and return its row.

    ``scene`` is the loaded base scene (shared by every variant on a worker);
    without it the scenario loads its own. Impossible parameters give a row
    with status "error" and the message; a refusal by this machine's limits or
    backends, or any other failure, a row with status "failed" (tried again when the
    sweep resumes). Never raises for a variant.
    """
    from ladartui.simulation import simulate

    started = time.perf_counter()
    row = {"variant": variant_id, "status": "ok", "base": base_digest, **params}
    try:
        scene = scene_of(scene) if scene is not None else base.load_scene()
        scenario = apply_parameters(base, params, lambda: scene)
        result = simulate(scenario, **(simulate_options or {}), write=False, scene=scene)
        measures = result.measures.to_dict()
        # Per-target measures become flat columns per target id (sweep.columns), not one JSON cell.
        per_target = (measures.get("targets") or {}).pop(PER_TARGET_KEY, None)
        row["path_length_m"] = scenario.flight.path_length()
        row["flight_time_s"] = scenario.flight.flight_time(scenario.speed)
        row["backend"] = result.backend
        row["method"] = result.method
        reserved = set(row) | set(params)
        reserved -= {"scan_count"}
        for key, value in measure_columns(measures, reserved).items():
            if key in ("measure.path_length_m", "measure.flight_time_s"):
                continue  # the same figures as the row's own columns
            row[key] = value
        if per_target is not None:
            row.update(per_target_columns(per_target))
        if row.get("scan_count") is None:
            row["scan_count"] = len(scenario.flight.poses())
    except Cancelled:
        raise  # a cancelled run is no result
    except (ResourceLimitError, BackendUnavailable) as error:
        # this machine's limits or backends, not the variant's values: run it again on resume
        from ladartui.resources import sweep_advice

        row.update(status="failed", error=sweep_advice(error))
    except LadarError as error:
        row.update(status="error", error=str(error))
    except Exception as error:  # noqa: BLE001 - one variant's crash must not end the sweep
        row.update(status="failed", error=f"{type(error).__name__}: {error}")
    row["run_time_s"] = round(time.perf_counter() - started, 6)
    row["worker"] = worker_name()
    return row


@dataclass(frozen=True)
class ScenePayload:
    """A loaded scene as plain arrays, to send to workers once (a Scene holds a lock)."""

    token: str
    voxels: np.ndarray
    target: np.ndarray
    voxel_size: float
    shape: tuple
    name: str
    path: str | None
    target_ids: np.ndarray  # one id per target voxel (several targets)

    @classmethod
    def of(cls, scene, token: str) -> ScenePayload:
        return cls(
            token,
            scene.voxels,
            scene.target,
            scene.voxel_size,
            tuple(scene.shape),
            scene.name,
            None if scene.path is None else str(scene.path),
            scene.target_ids,
        )


# Scenes rebuilt on this worker, by payload token: the occupancy built by the
# first variant serves every later one. Two sweeps' worth at most.
_WORKER_SCENES: OrderedDict = OrderedDict()
_WORKER_SCENES_KEPT = 2
_worker_lock = threading.Lock()


def scene_of(scene):
    """A Scene from a Scene or a ScenePayload (rebuilt once per worker and token)."""
    if not isinstance(scene, ScenePayload):
        return scene
    from ladartui.scene.model import Scene

    with _worker_lock:
        cached = _WORKER_SCENES.get(scene.token)
        if cached is None:
            cached = Scene(
                scene.voxels,
                scene.target,
                scene.voxel_size,
                shape=scene.shape,
                name=scene.name,
                path=scene.path,
                target_ids=scene.target_ids,
            )
            _WORKER_SCENES[scene.token] = cached
            while len(_WORKER_SCENES) > _WORKER_SCENES_KEPT:
                _WORKER_SCENES.popitem(last=False)
        else:
            _WORKER_SCENES.move_to_end(scene.token)
        return cached
