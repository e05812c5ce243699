"""Tracing's constants and tuning knobs, in one place.

Hit kinds and the numbers the numba kernels and the WGSL shaders must agree on
live here once: ``wgsl_constants`` writes them into the shader source when it is
assembled, so the shaders never restate them. The tuning knobs of both backends
sit below them, each with why it has its value.

The numba kernels take these as compile-time constants; numba's on-disk cache
only notices edits to a kernel's own file, so ``ladartui.kernel_cache`` clears
the cached kernels once any of their sources changed.
"""

from __future__ import annotations

# -- answers ----------------------------------------------------------------------

MISS, VOXEL, GROUND = 0, 1, 2  # hit kinds of every backend (CellHits.kind)
# Shader-only kinds: a march pass ended without an answer, and a loop ended by the
# adapter's iteration guard rather than by the ray (see shaders/trace.wgsl).
UNFINISHED, CUT = 3, 4
INF = float("inf")  # the parameter of no hit (CellHits.t of a miss)
# The shader's +inf: WGSL has no infinity literal, and no ray parameter comes near it.
SHADER_INF = 1e30
# Method codes the shader reads from its parameters (params.run.y).
METHOD_CODES = {"exact": 0, "march": 1}

# -- work split -------------------------------------------------------------------

# Rays per bundle: one numba prange work item (coherent neighbours stay on one
# thread), one WGSL workgroup, and one bundle start each (tracing.bundle).
BUNDLE = 64
# Parallel passes split into this many fixed runs, so sums do not depend on the threads.
PARTS = 64
BLOCK = 1 << 16  # rays per numba kernel call: cancel is checked between calls
DEFAULT_STEP = 0.5  # voxels between march samples
# The finest march step taken (voxels). Finer ones sample a 1,500-voxel path over
# 1.5 million times a ray (at 1e-12 a call never ended, and cannot be cancelled
# within a ray), and under about 1e-7 the samples' count overflows: misses. The
# exact method gives what a finer march would approach.
MIN_STEP = 0.001

# -- bundle starts (tracing.bundle) -------------------------------------------------

BUNDLE_REACH = 7.0  # voxels: under one brick (8), one voxel of slack for rounding
FINE_REACH = 3.0  # the same over ``Occupancy.halo4`` (4-voxel cells)
FAR = 1e12  # cells: beyond this the one-voxel margins drown in rounding, so no bundle start

# -- object order (tracing.object_order) --------------------------------------------

EPS = 1e-9  # widening of projected rectangles (tangent units), far above rounding
NEAR_MARGIN = 1e-9  # relative lowering of depth bounds, far above rounding
# Tiles of rays tested together (numba): up to 64 x 64 bins (a row is one int64 mask).
# A scan's voxels each cover about 8 x 8 bins, so big tiles list each voxel about
# once: on a 512 x 512 scan 64 x 64 tiles traced 25 % faster than 16 x 16.
# tile_tests.tile_shift_for takes smaller ones where a scan has fewer bins.
MAX_TILE_SHIFT = 6
MAX_SPREAD = 1.0  # largest origin half-spread (cells) handled in object order
MIN_COS = 0.5  # every ray within 60 degrees of the cone's axis
SCAN_BLOCK = 1 << 18  # rays per object-order call (one 512 x 512 scan)
MIN_SCAN_RAYS = 4096  # fewer rays: ray order, whose set-up is nil
# At most this many occupied voxels in view per ray for object order to be tried (more,
# and walking the rays is cheaper). numba: object order took 0.25-0.65x ray order's time
# at 0.3-1.3 voxels a ray, 0.8-0.9x at 2.0-2.4 and 1.07x at 3.2, on the generated small
# and reference scenes at 45 degrees and at nadir; the learned choice (OrderChoice)
# picks between the two where both may run. wgpu: the crossover measured before on the
# reference scene.
VOXELS_PER_RAY = 2.0
WGPU_VOXELS_PER_RAY = 0.6

# -- wgpu (tracing.wgpu_backend) ----------------------------------------------------

RAY_BATCH = 1 << 20  # rays per dispatch: bounds host and device memory
# Ask for no more than this many occupancy bindings (16 GiB at 128 MiB each).
MAX_OCCUPANCY_BINDINGS = 128
# Samples a ray per march pass: well under lavapipe's 65,535 loop iterations
# per invocation, all loops together.
MARCH_SAMPLES_PER_PASS = 1 << 15
# Object order in the shader: tiles of 4 x 4 bins. Each ray walks its tile's list
# until the least near still to come passes its bound, so bigger tiles cost the
# shader more entries and smaller ones cost the host longer lists: a whole wgpu
# scan (the bench's narrow 45 degree view) took 22.8 ms with 4 x 4 tiles, 28.0 ms
# with 2 x 2 and 27.0 ms with 8 x 8.
OBJECT_ORDER_TILE_SHIFT = 2
# Longest tile list an invocation may walk: under lavapipe's 65,535 loop iterations.
LOOP_BUDGET = 65_000
# The march jumps over samples certain to lie in an empty node: certain by this margin
# (voxels), far above the rounding of a sample's position, float32 included.
MARCH_SKIP_MARGIN = 0.01
# trace.wgsl's first_hits: a ray's word when it hits no voxel, or its loop was cut.
NO_VOXEL, CUT_WORD = -1, -2
# The object-order shader's word for a ray without a hit: the packed cell no voxel
# has (shader_scan.cell_packing refuses the one box whose corner packs to it).
NO_CELL = 0xFFFFFFFF
# The parameter block's first word of the column tops when the occupancy has none
# (Occupancy.columns is None, as for a few voxels over a huge box): no column skip.
NO_COLUMNS = 0xFFFFFFFF


def wgsl_constants(real: str) -> str:
    """The header every shader is assembled after: the float type and the shared constants."""
    if real not in ("f32", "f64"):
        raise ValueError(f"real must be f32 or f64, not {real!r}")
    codes = {
        "MISS": MISS,
        "VOXEL": VOXEL,
        "GROUND": GROUND,
        "UNFINISHED": UNFINISHED,
        "CUT": CUT,
        "NO_VOXEL": NO_VOXEL,
        "CUT_WORD": CUT_WORD,
    }
    lines = [
        "// Written by tracing/config.py (wgsl_constants): change the values there.",
        f"alias real = {real};",
        *(f"const {name}: i32 = {value};" for name, value in codes.items()),
        *(f"const METHOD_{name.upper()}: i32 = {code};" for name, code in METHOD_CODES.items()),
        f"const INF: real = {_wgsl_float(SHADER_INF)};",
        f"const MARCH_SKIP_MARGIN: real = {_wgsl_float(MARCH_SKIP_MARGIN)};",
        f"const BUNDLE: u32 = {BUNDLE}u;",
        f"const NO_CELL: u32 = {NO_CELL}u;",
        f"const NO_COLUMNS: u32 = {NO_COLUMNS}u;",
    ]
    return "\n".join(lines) + "\n"


def _wgsl_float(value: float) -> str:
    # repr gives 1e+30; WGSL reads 1e30 as the same abstract float.
    return repr(float(value)).replace("e+", "e")
