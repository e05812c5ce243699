// Object-order tile tests as a compute shader: one invocation per ray.
//
// This is tracing/tile_tests.py's test_tiles seen from the ray's side. The
// host (tracing/shader_scan.py) puts the rays in bin order, finds the occupied
// voxels in view nearest brick first and lists each tile's voxels in that
// order. Each invocation takes one ray (sorted position s, ray order[s]) down
// its tile's list: it stops at the first entry whose `rest` (the least voxel
// near from there to the end of the list, numba's tile stop) is at or beyond
// the ray's bound, and slab-tests every voxel before it; a hit strictly nearer
// than the bound becomes the bound (of equal entries the first listed stays,
// as in numba). The bound starts where the ray leaves the occupied box (every
// hit starts before that).
//
// lavapipe loads a storage value lane by lane, so the layout counts words:
// an entry is two (rest as float32 rounded down, still a lower bound; the
// voxel's cell packed into one u32 relative to the scan's offset), and the
// shader writes the hit's packed cell alone (NO_CELL: none): the host unpacks
// it and recomputes t with the same slab test. In f64 the answers are
// numba's bit for bit (tests/test_wgpu_object_order.py).
//
// tracing/wgpu_scans.py prepends the header of tracing/config.py (wgsl_constants:
// `alias real = f64;`, INF, BUNDLE, ...) and shaders/axis.wgsl.
// Loop budget (see trace.wgsl): the host sends no tile list of 65,535 entries or more.

struct TileParams {
    rays: u32,               // rays in this dispatch
    tile_shift: u32,         // tiles of 1 << tile_shift bins a side
    one_per_bin: u32,        // 1: sorted position s is in tile s >> (2 * tile_shift)
    one_origin: u32,         // 1: every ray starts at origins[0..3] (one row sent)
    shifts: vec4<u32>,       // packed cell: axis a is (cell >> shifts[a]) & masks[a]
    masks: vec4<u32>,
    offset: vec4<i32>,       // cell of packed (0, 0, 0)
    box_lo: vec4<i32>,       // the occupied box, hi exclusive
    box_hi: vec4<i32>,
}

@group(0) @binding(0) var<uniform> params: TileParams;
@group(0) @binding(1) var<storage, read> origins: array<real>;     // ox oy oz per ray
@group(0) @binding(2) var<storage, read> directions: array<real>;  // dx dy dz per ray
@group(0) @binding(3) var<storage, read> order: array<u32>;        // sorted position -> ray
@group(0) @binding(4) var<storage, read> ray_tiles: array<u32>;    // tile of sorted position (unless one_per_bin)
@group(0) @binding(5) var<storage, read> tile_starts: array<u32>;  // tile's entries
@group(0) @binding(6) var<storage, read> entries: array<vec2<u32>>; // rest (f32 bits), packed cell
@group(0) @binding(7) var<storage, read_write> found: array<u32>;  // per ray: packed cell of its hit, NO_CELL none

// The packed cell of the first voxel the ray meets before `bound` among entries
// first .. last, NO_CELL none. `enter_face` and `leave_face` are per axis the cell
// offsets (0 or 1) of the faces the ray enters and leaves a cell by, so each
// slab parameter is the reference tracer's boundary_t, bit for bit, with no
// min or max (lavapipe's are slow). A still axis (d = 0) has no faces: the ray
// is inside the open slab for every t or never, which `still` checks (one loop
// for both kinds of ray: two inlined copies of it, one per value, made the
// tile tests on lavapipe 1.03-1.11x slower).
fn first_hit(first: u32, last: u32, bound: real, o: vec3<real>, d: vec3<real>, inv: vec3<real>,
             enter_face: vec3<real>, leave_face: vec3<real>, still: bool) -> u32 {
    let offset = vec3<real>(params.offset.xyz);
    var best = bound;
    var hit = NO_CELL;
    for (var e = first; e < last; e++) {
        let entry = entries[e];
        if (real(bitcast<f32>(entry.x)) >= best) {
            break;  // no voxel from here on starts before the bound
        }
        let x = offset.x + real((entry.y >> params.shifts.x) & params.masks.x);
        let y = offset.y + real((entry.y >> params.shifts.y) & params.masks.y);
        let z = offset.z + real((entry.y >> params.shifts.z) & params.masks.z);
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
        if (still) {
            let inside = (d.x != 0.0 || (x < o.x && o.x < x + 1.0)) && (d.y != 0.0 || (y < o.y && o.y < y + 1.0))
                && (d.z != 0.0 || (z < o.z && o.z < z + 1.0));
            enter = select(INF, enter, inside);
        }
        let start = select(enter, 0.0, enter < 0.0);
        if (start < leave && start < best) {
            best = start;
            hit = entry.y;
        }
    }
    return hit;
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
    if (params.one_per_bin != 0u) {
        tile = s >> (2u * params.tile_shift);
    } else {
        tile = ray_tiles[s];
    }
    let r = order[s];
    let b = r * 3u;
    let ob = select(b, 0u, params.one_origin != 0u);
    let o = vec3<real>(origins[ob], origins[ob + 1u], origins[ob + 2u]);
    let d = vec3<real>(directions[b], directions[b + 1u], directions[b + 2u]);
    let inv = select(vec3<real>(INF), vec3<real>(1.0) / d, d != vec3<real>(0.0));
    let lo = vec3<real>(params.box_lo.xyz);
    let hi = vec3<real>(params.box_hi.xyz);
    // Where it leaves the occupied box: every hit starts before that.
    let bound = min(slab(o.x, d.x, inv.x, lo.x, hi.x).leave,
                    min(slab(o.y, d.y, inv.y, lo.y, hi.y).leave, slab(o.z, d.z, inv.z, lo.z, hi.z).leave));
    let enter_face = select(vec3<real>(0.0), vec3<real>(1.0), d < vec3<real>(0.0));
    let leave_face = vec3<real>(1.0) - enter_face;
    let first = tile_starts[tile];
    let last = tile_starts[tile + 1u];
    found[r] = first_hit(first, last, bound, o, d, inv, enter_face, leave_face, any(d == vec3<real>(0.0)));
}
