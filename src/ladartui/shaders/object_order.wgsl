// Object-order tile tests as a compute shader: one invocation per ray.
//
// This is tracing/tile_tests.py's test_tiles seen from the ray's side. The
// host (tracing/shader_scan.py) puts the rays in bin order, finds the occupied
// voxels in view nearest brick first and lists each tile's voxels in that
// order. Each invocation takes one ray (sorted position s, ray order[s]) down
// its tile's list: it stops at the first entry whose `rest` (the least voxel
// near from there to the end of the list, numba's tile stop) is at or beyond
// the nearest hit so far, and slab-tests every voxel before it; a hit strictly
// nearer becomes the bound (of equal entries the first listed stays, as in
// numba). numba's bound where the ray leaves the occupied box is left out:
// no hit starts beyond it, and on lavapipe its three slabs cost more than the
// entries it spared (the tile tests ran 1.01-1.11x faster without it).
//
// lavapipe runs eight invocations as one vector and pays for every operation
// in the entry loop, so the loop holds as few as it can: an entry is two words
// (rest as float32 rounded down, still a lower bound; the voxel's cell packed
// into one u32 relative to the scan's offset), the offset rides in each ray's
// face offsets, and a still axis costs one mask test. The shader
// writes the hit's packed cell alone (NO_CELL: none): the host unpacks it and
// recomputes t with the same slab test. In f64 the answers are numba's bit for
// bit (tests/test_wgpu_object_order.py).
//
// tracing/wgpu_scans.py prepends the header of tracing/config.py (wgsl_constants:
// `alias real = f64;`, INF, BUNDLE, ...), shaders/axis.wgsl and the tile bounds
// (tile_bounds_source): binding 5 and `tile_bounds(tile)`, the tile's entries.
// On lavapipe they come from a uniform buffer, which it reads with a vector
// gather where storage is read lane by lane (the device pass took 0.96-0.97x
// the time); elsewhere, and past a uniform buffer's 16,384 tiles, from storage.
// Loop budget (see trace.wgsl): the host sends no tile list of 65,535 entries or more.

// Set per pipeline: lavapipe runs both sides of every branch, and pays for a
// storage load a lane skips, so a branch on a uniform field still cost its
// loads (without them the device pass took 0.92-0.93x the time).
override ONE_PER_BIN: bool;  // sorted position s is in tile s >> (2 * tile_shift): no ray_tiles
override ONE_ORIGIN: bool;   // every ray starts at params.origin: no origins

struct TileParams {
    rays: u32,               // rays in this dispatch
    tile_shift: u32,         // tiles of 1 << tile_shift bins a side
    shifts: vec4<u32>,       // packed cell: axis a is (cell >> shifts[a]) & masks[a] (at most 31 bits)
    masks: vec4<u32>,
    offset: vec4<i32>,       // cell of packed (0, 0, 0)
    origin: vec4<real>,      // xyz: the rays' one origin (ONE_ORIGIN)
}

@group(0) @binding(0) var<uniform> params: TileParams;
@group(0) @binding(1) var<storage, read> origins: array<real>;     // ox oy oz per ray (unless ONE_ORIGIN)
@group(0) @binding(2) var<storage, read> directions: array<real>;  // dx dy dz per ray
@group(0) @binding(3) var<storage, read> order: array<u32>;        // sorted position -> ray
@group(0) @binding(4) var<storage, read> ray_tiles: array<u32>;    // tile of sorted position (unless ONE_PER_BIN)
@group(0) @binding(6) var<storage, read> entries: array<vec2<u32>>; // rest (f32 bits), packed cell
@group(0) @binding(7) var<storage, read_write> found: array<u32>;  // per ray: packed cell of its hit, NO_CELL none

// The packed cell of the first voxel the ray meets among entries first .. last,
// NO_CELL none. `enter_face` and `leave_face` are per axis the cells' offset
// plus the face (0 or 1) the ray enters and leaves a cell by, so each slab
// parameter is the reference tracer's boundary_t of the face's coordinate, bit
// for bit (sums of small integers are exact), with no min or max (lavapipe's
// are slow). A still axis (d = 0) has no faces: the ray is inside the open slab
// of one cell there or of none, which `still_axis` made a test of the packed
// cell, (cell & still_mask) == still_cell (always true when no axis is still).
fn first_hit(first: u32, last: u32, o: vec3<real>, inv: vec3<real>, enter_face: vec3<real>,
             leave_face: vec3<real>, still_mask: u32, still_cell: u32) -> u32 {
    var best = INF;
    var hit = NO_CELL;
    for (var e = first; e < last; e++) {
        let entry = entries[e];
        if (real(bitcast<f32>(entry.x)) >= best) {
            break;  // no voxel from here on starts before the nearest hit
        }
        // Axes of at most 31 bits: i32's conversion is lavapipe's cheap one.
        let x = real(i32((entry.y >> params.shifts.x) & params.masks.x));
        let y = real(i32((entry.y >> params.shifts.y) & params.masks.y));
        let z = real(i32((entry.y >> params.shifts.z) & params.masks.z));
        let ex = boundary_t(x + enter_face.x, o.x, inv.x);
        let ey = boundary_t(y + enter_face.y, o.y, inv.y);
        let ez = boundary_t(z + enter_face.z, o.z, inv.z);
        let lx = boundary_t(x + leave_face.x, o.x, inv.x);
        let ly = boundary_t(y + leave_face.y, o.y, inv.y);
        let lz = boundary_t(z + leave_face.z, o.z, inv.z);
        var enter = select(ex, ey, ey > ex);
        enter = select(enter, ez, ez > enter);
        var leave = select(lx, ly, ly < lx);
        leave = select(leave, lz, lz < leave);
        // (Outside a still axis's slab its parameters are +-inf or NaN; inside,
        // -inf and +inf, which the slab passes over.)
        enter = select(INF, enter, (entry.y & still_mask) == still_cell);
        let start = select(enter, 0.0, enter < 0.0);
        if (start < leave && start < best) {
            best = start;
            hit = entry.y;
        }
    }
    return hit;
}

// One axis's share of the still test, as (mask, cell) over packed cells, joined
// with the other axes' by OR: (0, 0) when the ray moves along the axis. When it
// does not, the ray is in the open slab of cell c (c < o < c + 1) only for
// c = floor(o), and never when o lies on a face or that cell is outside the
// packing's span: then all ones for both, which no cell matches (cell_packing
// keeps NO_CELL free) whatever the other axes add.
fn still_axis(o: real, d: real, offset: i32, shift: u32, mask: u32) -> vec2<u32> {
    if (d != 0.0) {
        return vec2<u32>(0u);
    }
    let c = floor(o) - real(offset);
    if (floor(o) == o || c < 0.0 || c > real(mask)) {
        return vec2<u32>(NO_CELL);
    }
    return vec2<u32>(mask << shift, u32(c) << shift);
}

// numba: test_tiles (tracing/tile_tests.py)
@compute @workgroup_size(BUNDLE)
fn test_tiles(@builtin(workgroup_id) group: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>,
              @builtin(local_invocation_index) lane: u32) {
    let s = (group.y * groups.x + group.x) * BUNDLE + lane;
    if (s >= params.rays) {
        return;
    }
    var tile: u32;
    if (ONE_PER_BIN) {
        tile = s >> (2u * params.tile_shift);
    } else {
        tile = ray_tiles[s];
    }
    let r = order[s];
    let b = r * 3u;
    // One origin from the uniform block: one load for all lanes (0.97x the device time).
    var o = params.origin.xyz;
    if (!ONE_ORIGIN) {
        o = vec3<real>(origins[b], origins[b + 1u], origins[b + 2u]);
    }
    let d = vec3<real>(directions[b], directions[b + 1u], directions[b + 2u]);
    let inv = select(vec3<real>(INF), vec3<real>(1.0) / d, d != vec3<real>(0.0));
    let face = select(vec3<real>(0.0), vec3<real>(1.0), d < vec3<real>(0.0));
    let offset = vec3<real>(params.offset.xyz);
    // (Loaded before the still test: after it, the tile tests ran 1.04-1.08x slower on lavapipe.)
    let bounds = tile_bounds(tile);
    let still = still_axis(o.x, d.x, params.offset.x, params.shifts.x, params.masks.x)
        | still_axis(o.y, d.y, params.offset.y, params.shifts.y, params.masks.y)
        | still_axis(o.z, d.z, params.offset.z, params.shifts.z, params.masks.z);
    found[r] = first_hit(bounds.x, bounds.y, o, inv, face + offset, (vec3<real>(1.0) - face) + offset, still.x, still.y);
}
