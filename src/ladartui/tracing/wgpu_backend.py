"""The wgpu backend: the occupancy tracer as a WGSL compute shader.

Runs on any adapter wgpu can open: a real GPU (discrete, then integrated) when
there is one, else a CPU adapter such as Mesa's lavapipe. The shader
(``shaders/trace.wgsl``) is the numba kernel of ``tracing/numba_backend.py``
written again in WGSL, step for step, so that in float64 both give the same
answer for every ray.

Resources:

* The occupancy goes to the device once per ``Occupancy`` object, in chunks of
  one storage binding each (``tracing/wgpu_occupancy.py``), and serves every call.
* Rays go in batches that fit one binding; each batch is one dispatch over a
  2-D grid of workgroups kept within the per-dimension limit. Exact ``f64``
  rays go through trace.wgsl's ``first_hits`` (``tracing/wgpu_hits.py``: the
  rays as the host holds them, one word a ray back); f32 and the march
  through ``trace_rays`` (``tracing/wgpu_rays.py``: rays packed six reals a
  ray, kind, cell and ``t`` back; an exact ray with no voxel gets the ground
  rule on the host, in float64).
* The march goes in passes of at most ``MARCH_SAMPLES_PER_PASS`` samples a ray:
  lavapipe ends all loops of a shader invocation after 65,535 iterations in
  total, so a longer march would stop early. Rays without an answer after a
  pass are dispatched again from the next sample on. A loop ended early all the
  same (e.g. an exact ray needing more steps than that) raises
  ``BackendUnavailable`` rather than passing for a miss.

Object order: exact ``f64`` scans (one aircraft, a narrow cone; see
``tracing/object_order.py``) go voxel by voxel as in the numba backend. The
host puts the rays in bin order and lists the voxels in view per tile with the
numba functions of ``tracing/shader_scan.py`` (``prepare_shader_scan``);
``shaders/object_order.wgsl`` runs the tile tests, one invocation per ray; the
host makes each hit an answer, or applies the ground rule (``entry_answers``).
``OrderChoice`` learns per occupancy whether that or the ray-order shader is
faster, as in numba, and ``CellHits.info["order"]`` says which ran.

Precision: ``f64`` needs the adapter's ``shader-f64`` feature (lavapipe has
it). Without it the backend runs ``f32`` and says so in ``CellHits.info``.
In ``f32`` each ray starts where it enters the scene's box
(``tracing/f32_rays.py``), so an aircraft kilometres away loses no precision.

``wgpu`` is imported only inside ``probe`` and later calls: importing this
module is cheap and never fails.
"""

from __future__ import annotations

import importlib.resources
import math
import threading
import weakref
from typing import Any

import numpy as np

from ladartui.errors import BackendUnavailable, FieldError
from ladartui.tracing.backend import (
    METHODS,
    PRECISIONS,
    CellHits,
    TraceOrder,
    check_order,
    check_step,
    register_backend,
)
from ladartui.tracing.bundle import halo_arrays
from ladartui.tracing.config import (
    BUNDLE,
    LOOP_BUDGET,
    MAX_OCCUPANCY_BINDINGS,
    OBJECT_ORDER_TILE_SHIFT,
    RAY_BATCH,
    SCAN_BLOCK,
    WGPU_VOXELS_PER_RAY,
)
from ladartui.tracing.order_choice import RAY_SAMPLE, OrderChoice, trace_in_blocks
from ladartui.tracing.passes import timed
from ladartui.tracing.prepare import float_rows, one_origin, origin_rows
from ladartui.tracing.scan_rays import cone_frame
from ladartui.tracing.shader_scan import entry_answers, prepare_shader_scan
from ladartui.tracing.wgpu_adapter import INSTALL_HINT, choose_adapter, give_driver_a_runtime_dir
from ladartui.tracing.wgpu_hits import HIT_BINDINGS, FirstHits, box_sides
from ladartui.tracing.wgpu_occupancy import (
    FIXED_BINDINGS,
    PARAMS_BYTES,
    Upload,
    occupancy_header,
    pack_params,
    upload_occupancy,
)
from ladartui.tracing.wgpu_rays import RayPasses
from ladartui.tracing.wgpu_scans import ScanDispatcher

NAME = "wgpu"


class WgpuBackend:
    """Tracer running the WGSL kernel through wgpu (see module docstring)."""

    name = NAME
    summary = "WGSL compute shader through wgpu (GPU, else lavapipe on the CPU)"

    def __init__(
        self,
        *,
        max_binding_bytes: int | None = None,
        ray_batch: int = RAY_BATCH,
        max_workgroups_per_dimension: int | None = None,
        map_storage: bool = True,
        staged_upload: bool | None = None,
    ):
        """Optional caps below the adapter's limits (tests use them to force
        occupancy splitting, several batches and 2-D dispatch grids);
        ``map_storage=False`` runs object order as on a GPU even on a CPU adapter:
        its arrays copied through the queue, its tile bounds read from storage
        (tests run that way on lavapipe); ``staged_upload``: exact ray order writes
        its rays through staging buffers of its own (``FirstHits``), by default
        on a GPU only."""
        self._caps = {
            "max-storage-buffer-binding-size": max_binding_bytes,
            "max-compute-workgroups-per-dimension": max_workgroups_per_dimension,
        }
        self._ray_batch = int(ray_batch)
        self._map_storage = map_storage
        self._staged_upload = staged_upload
        self._lock = threading.RLock()
        self._probed = False
        self._reason: str | None = None
        self._adapter: Any = None  # wgpu objects (wgpu ships no type information)
        self._device: Any = None
        self._limits: dict[str, int] = {}
        self._has_f64 = False
        self._cpu_adapter = False  # lavapipe and the like: a dispatch costs little, memory is the host's
        # On a CPU adapter storage buffers can be mapped (tracing/wgpu_scans.py).
        self._maps_storage = False
        self._uploads: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()
        self._pinned_uploads: dict[int, Any] = {}  # for occupancies that cannot be weakly referenced
        self._modules: dict[Any, Any] = {}  # trace.wgsl compiled, by precision and chunks
        self._pipelines: dict[Any, Any] = {}  # its entry points, by the same and entry
        self._sources: dict[str, str] = {}
        self._orders: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()  # -> OrderChoice
        self._scans: ScanDispatcher | None = None  # object order on the device, once it is open
        self._hits: FirstHits | None = None  # exact ray order on the device, once it is open
        self._rays: RayPasses | None = None  # trace_rays: f32, the march, huge boxes

    # -- probing and device -------------------------------------------------

    def probe(self) -> str | None:
        """None when an adapter is usable here, else what to install."""
        with self._lock:
            if not self._probed:
                self._reason = self._find_adapter()
                self._probed = True
            return self._reason

    def _find_adapter(self) -> str | None:
        give_driver_a_runtime_dir()
        try:
            import wgpu
        except ImportError:
            return "the wgpu package is not installed: pip install wgpu==0.32.0"
        except Exception as error:  # a broken install: say so, never crash the caller
            return f"the wgpu package failed to import ({error}): reinstall wgpu==0.32.0"
        try:
            adapters = wgpu.gpu.enumerate_adapters_sync()
        except Exception as error:  # the native library failed to load or to start
            return f"wgpu could not list adapters ({error}); {INSTALL_HINT}"
        adapter = choose_adapter(adapters)
        if adapter is None:
            return INSTALL_HINT
        self._adapter = adapter
        self._has_f64 = "shader-f64" in adapter.features
        self._cpu_adapter = adapter.info.get("adapter_type") == "CPU"
        self._maps_storage = (
            self._map_storage and self._cpu_adapter and "mappable-primary-buffers" in adapter.features
        )
        return None

    def _require(self):
        reason = self.probe()
        if reason:
            raise BackendUnavailable(f"backend {NAME!r} is unavailable: {reason}")

    def _open_device(self):
        """The device, created once with the limits this backend needs."""
        if self._device is not None:
            return self._device
        self._require()
        adapter = self._adapter
        limits = adapter.limits
        storage = min(limits["max-storage-buffers-per-shader-stage"], FIXED_BINDINGS + MAX_OCCUPANCY_BINDINGS)
        wanted = {
            # The adapter's own maxima: asking for more fails at device creation.
            "max-storage-buffer-binding-size": limits["max-storage-buffer-binding-size"],
            "max-buffer-size": limits["max-buffer-size"],
            "max-storage-buffers-per-shader-stage": storage,
            "max-compute-workgroups-per-dimension": limits["max-compute-workgroups-per-dimension"],
        }
        features = ["shader-f64"] if self._has_f64 else []
        if self._maps_storage:
            features.append("mappable-primary-buffers")
        try:
            self._device = adapter.request_device_sync(
                label="ladartui-trace", required_features=features, required_limits=wanted
            )
        except Exception as error:
            raise BackendUnavailable(
                f"backend {NAME!r} could not open a device on {adapter.info.get('device')!r}: {error}"
            ) from error
        self._limits = dict(wanted)
        for key, cap in self._caps.items():
            if cap is not None:
                self._limits[key] = min(self._limits[key], int(cap))
        self._scans = ScanDispatcher(
            self._device,
            self._limits,
            self._shader_file,
            self._maps_storage,
            uniform_tile_bounds=self._cpu_adapter and self._map_storage,
        )
        staged = (not self._cpu_adapter) if self._staged_upload is None else self._staged_upload
        self._hits = FirstHits(
            self._device, self._limits, self._ray_batch, bundle_starts=self._cpu_adapter, staged=staged
        )
        self._rays = RayPasses(self._device, self._limits, self._ray_batch)
        return self._device

    def describe(self) -> dict:
        """Adapter name, type, graphics backend, f64 support and the limits used."""
        with self._lock:
            self._require()
            info = self._adapter.info
            limits = self._limits or {
                key: self._adapter.limits[key]
                for key in (
                    "max-storage-buffer-binding-size",
                    "max-buffer-size",
                    "max-storage-buffers-per-shader-stage",
                    "max-compute-workgroups-per-dimension",
                )
            }
            return {
                "backend": NAME,
                "adapter": info.get("device", ""),
                "adapter_type": info.get("adapter_type", ""),
                "graphics_backend": info.get("backend_type", ""),
                "driver": info.get("description", ""),
                "f64": self._has_f64,
                "precisions": list(PRECISIONS) if self._has_f64 else ["f32"],
                "limits": dict(limits),
                "workgroup_size": BUNDLE,
                "ray_batch": self._ray_batch,
                "maps_storage": self._maps_storage,  # object order's buffers mapped by the host
            }

    # -- occupancy upload ---------------------------------------------------

    def _upload(self, occupancy) -> Upload:
        """The device copy of ``occupancy``, made on first use (cached by identity)."""
        try:
            upload = self._uploads.get(occupancy)
        except TypeError:
            upload = self._pinned_uploads.get(id(occupancy), (None, None))
            upload = upload[1] if upload[0] is occupancy else None
        if upload is not None:
            return upload
        upload = self._make_upload(occupancy)
        try:
            self._uploads[occupancy] = upload
        except TypeError:
            self._pinned_uploads.clear()  # keep only the latest one alive
            self._pinned_uploads[id(occupancy)] = (occupancy, upload)
        return upload

    def _make_upload(self, occupancy) -> Upload:
        device = self._open_device()
        return upload_occupancy(device, occupancy, self._limits, self._adapter.info.get("device"), NAME)

    # -- pipelines ----------------------------------------------------------

    def _shader_file(self, name: str) -> str:
        if name not in self._sources:
            self._sources[name] = (importlib.resources.files("ladartui") / "shaders" / name).read_text()
        return self._sources[name]

    def _shader_source(self, real: str, chunks: int, chunk_shift: int) -> str:
        """trace.wgsl after its header (wgpu_occupancy.occupancy_header) and axis.wgsl."""
        header = occupancy_header(real, chunks, chunk_shift)
        return "\n\n".join((header, self._shader_file("axis.wgsl"), self._shader_file("trace.wgsl")))

    def _pipeline(self, precision: str, chunks: int, chunk_shift: int, entry: str = "trace_rays"):
        """trace.wgsl's ``entry`` (trace_rays or first_hits) for this occupancy layout."""
        key = (precision, chunks, chunk_shift, entry)
        pipeline = self._pipelines.get(key)
        if pipeline is None:
            device = self._open_device()
            module = self._modules.get(key[:3])
            if module is None:
                code = self._shader_source(precision, chunks, chunk_shift)
                module = device.create_shader_module(label=f"trace-{precision}", code=code)
                self._modules[key[:3]] = module
            pipeline = device.create_compute_pipeline(
                label=f"{entry}-{precision}-{chunks}",
                layout="auto",
                compute={"module": module, "entry_point": entry},
            )
            self._pipelines[key] = pipeline
        return pipeline

    # -- tracing ------------------------------------------------------------

    def trace_cells(
        self,
        occupancy,
        origins,
        directions,
        *,
        method="exact",
        step=0.5,
        precision="f64",
        cancel: threading.Event | None = None,
        order: TraceOrder = "auto",
        block_bounds=None,
    ) -> CellHits:
        """Trace (N, 3) float64 cell-space rays on the adapter; see ``Backend``
        (``order`` there: only exact f64 scans can go in object order)."""
        if method not in METHODS:
            raise FieldError("method", method, " or ".join(METHODS))
        if precision not in PRECISIONS:
            raise FieldError("precision", precision, " or ".join(PRECISIONS))
        check_order(order)
        origins = float_rows(np.reshape(origins, (-1, 3)))  # one row broadcast stays so
        directions = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 3)
        if origins.shape != directions.shape:
            raise ValueError("origins and directions differ in length")
        step = float(step) if step is not None else 0.5
        if method == "march":
            check_step(step)
        with self._lock:
            self._open_device()
            used = precision if (precision == "f32" or self._has_f64) else "f32"
            info = {"adapter": self._adapter.info.get("device", ""), "precision": used}
            if used != precision:
                info["precision_note"] = "the adapter has no shader-f64: traced in f32"
            if method == "exact" and used == "f64" and order != "ray" and occupancy.count > 0:
                return self._trace_scans(occupancy, origins, directions, order, cancel, info, block_bounds)
            info["order"] = "ray"
            shared = one_origin(block_bounds, 0, len(origins))
            with timed("ray order" if method == "exact" else "march"):
                return self._trace(occupancy, origins, directions, method, step, used, cancel, info, shared)

    def _trace_scans(self, occupancy, origins, directions, order, cancel, info, block_bounds):
        """Exact f64 in blocks, each in object or ray order (``trace_in_blocks``)."""
        n = len(origins)
        kind, index, t = empty_answers(n)  # every block writes all its rays

        def ray_order(a, b):
            shared = one_origin(block_bounds, a, b)
            into = (kind[a:b], index[a:b], t[a:b])
            with timed("ray order"):
                self._trace(
                    occupancy, origins[a:b], directions[a:b], "exact", 0.5, "f64", cancel, info, shared, into
                )

        def object_order_block(a, b, max_voxels):
            bounds = None if block_bounds is None else block_bounds[a // SCAN_BLOCK]
            shared = one_origin(block_bounds, a, b)
            block = (origins[a:b], directions[a:b], bounds, shared, max_voxels)
            return self._object_order(occupancy, *block, kind[a:b], index[a:b], t[a:b])

        orders = trace_in_blocks(
            n,
            order,
            self._orders.setdefault(occupancy, self._order_choice()),
            object_order_block,
            ray_order,
            cancel,
        )
        info["order"] = "+".join(sorted(orders)) or "ray"
        return CellHits(kind, index, t, info)

    def _order_choice(self) -> OrderChoice:
        """A new occupancy's order choice: each order timed twice (a first call also
        builds pipelines); on a CPU adapter ray order is timed on a sample of a block
        while it does not lead (there a dispatch costs little beside the work: on
        lavapipe a sixteenth in four runs read 1.27x the per-ray time of whole
        blocks, against ray order's 4.5-5x object order's), on a GPU on whole blocks."""
        return OrderChoice(
            settled_gap=math.inf,
            ray_sample=RAY_SAMPLE if self._cpu_adapter else None,
            voxels_per_ray=WGPU_VOXELS_PER_RAY,
        )

    def _object_order(
        self, occupancy, origins, directions, bounds, shared_origin, max_voxels, kind, index, t
    ):
        """One scan in object order into kind/index/t; False when it is no scan for it
        (or its lists or arrays exceed what the adapter allows). ``shared_origin``:
        every ray starts at ``origins[0]`` (``prepare.one_origin``)."""
        frame = cone_frame(origins, directions, bounds)
        scan = (
            None
            if frame is None
            else prepare_shader_scan(
                occupancy, origins, directions, frame, max_voxels, OBJECT_ORDER_TILE_SHIFT
            )
        )
        if scan is None or np.diff(scan.tile_starts).max(initial=0) >= LOOP_BUDGET:
            return False
        assert self._scans is not None  # the device is open
        rows = origin_rows(origins, shared_origin)
        with timed("device"):  # uploads, the shader, the read-back
            found = self._scans.test_tiles(rows, directions, scan, shared_origin)
        if found is None:
            return False
        nx, ny = float(occupancy.shape[0]), float(occupancy.shape[1])
        offset, shifts, masks = scan.packing
        with timed("answers"):
            entry_answers(
                found, offset, shifts, masks, rows, shared_origin, directions, nx, ny, kind, index, t
            )
        return True

    def _trace(
        self,
        occupancy,
        origins,
        directions,
        method,
        step,
        precision,
        cancel,
        info,
        shared_origin=False,
        into=None,
    ):
        """``shared_origin``: every ray starts at origins[0] (``one_origin``); ``into``:
        the (kind, index, t) arrays to answer in, else new ones. Every pass below
        writes every ray's answer, so they start empty (no filling pass)."""
        n = len(origins)
        kind, index, t = empty_answers(n) if into is None else into
        if n == 0:
            return CellHits(kind, index, t, info)
        upload = self._upload(occupancy)
        sides = box_sides(occupancy) if method == "exact" and precision == "f64" else None
        if sides is not None:
            self._first_hits(
                occupancy,
                sides,
                upload,
                origin_rows(origins, shared_origin),
                directions,
                cancel,
                info,
                kind,
                index,
                t,
                shared_origin,
            )
            return CellHits(kind, index, t, info)
        assert self._rays is not None  # the device is open
        pipeline = self._pipeline(precision, len(upload.buffers), upload.chunk_shift)
        rays = (origins, directions, shared_origin)
        cut = self._rays.trace(
            occupancy, upload, pipeline, rays, method, step, precision, cancel, (kind, index, t)
        )
        if cut:
            raise _cut_short(cut, info)
        return CellHits(kind, index, t, info)

    def _first_hits(
        self, occupancy, sides, upload, origins, directions, cancel, info, kind, index, t, shared_origin
    ):
        """Exact f64 rays through trace.wgsl's first_hits (tracing/wgpu_hits.py)."""
        assert self._hits is not None  # the device is open
        pipeline = self._pipeline("f64", len(upload.buffers), upload.chunk_shift, "first_hits")
        buffers = self._hits.buffers(PARAMS_BYTES)
        key = ("first_hits", id(pipeline), id(buffers["origins"]))
        bound = {b: buffers[name] for name, b in HIT_BINDINGS.items()}
        group = upload.bind_group(self._device, pipeline, key, bound)
        cut = self._hits.trace(
            occupancy,
            sides,
            pipeline,
            group,
            lambda count: pack_params(
                occupancy, upload, "exact", 0.5, count, "f64", shared_origin=shared_origin
            ),
            origins,
            directions,
            halo_arrays(occupancy),
            cancel,
            kind,
            index,
            t,
            shared_origin,
        )
        if cut:
            raise _cut_short(cut, info)


def empty_answers(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(kind, index, t) for ``n`` rays, not filled: for passes that answer every ray."""
    return np.empty(n, dtype=np.uint8), np.empty((n, 3), dtype=np.int32), np.empty(n)


def _cut_short(rays: int, info) -> BackendUnavailable:
    return BackendUnavailable(
        f"backend {NAME!r} could not finish {rays} rays on {info['adapter']!r}: the adapter "
        f"ended their loops early (lavapipe stops after 65,535 iterations); use backend 'numba'"
    )


register_backend(NAME, WgpuBackend)
