// Object-order tile tests as a compute shader: one invocation per ray.
//
// This is tracing/tile_tests.py's test_tiles seen from the ray's side. The
// host (prepare_scan there) bins the rays, sorts them tile by tile, finds the
// occupied voxels in view nearest brick first and lists each tile's voxels in
// that order. Each invocation takes one sorted ray down its tile's list: it
// stops at the first brick whose `near` is at or beyond the ray's bound, as
// numba's tile does, and slab-tests every voxel before it; a hit strictly
// nearer than the bound becomes the bound (of equal entries the first listed
// stays, as in numba). numba also skips voxels by their own `near` and by
// their rectangle of bins; those only skip voxels that cannot win, and with
// tiles of 2 x 2 bins they prune too little to pay for reading them here
// (one 16-byte record per voxel instead of 32 was 20 % faster on lavapipe).
// The brick nears go as float32 rounded down, still lower bounds, and the
// coordinates as float32, exact below 2^24; so in f64 the answers are numba's
// bit for bit (tests/test_wgpu_object_order.py).
//
// tracing/wgpu_backend.py prepends the header of tracing/config.py (wgsl_constants:
// `alias real = f64;`, INF, BUNDLE, ...) and shaders/axis.wgsl.
// Loop budget (see trace.wgsl): the host sends no tile list of 65,535 voxels or more.

struct TileParams {
    rays: u32,            // sorted rays in this dispatch
    tile_shift: u32,      // tiles of 1 << tile_shift bins a side
    tiles_per_side: u32,
    unused: u32,
}

@group(0) @binding(0) var<uniform> params: TileParams;
@group(0) @binding(1) var<storage, read> rays: array<real>;          // ox oy oz dx dy dz per sorted ray
@group(0) @binding(2) var<storage, read> ray_bins: array<u32>;       // its bin, i | j << 16 (for its tile)
@group(0) @binding(3) var<storage, read_write> best_t: array<real>;  // in: exit from the occupied box; out: hit t
@group(0) @binding(4) var<storage, read_write> best_v: array<i32>;   // out: voxel number, -1 none
@group(0) @binding(5) var<storage, read> voxels: array<vec4<f32>>;     // brick's near, x, y, z
@group(0) @binding(6) var<storage, read> tile_starts: array<u32>;   // tile's entries in `listed`
@group(0) @binding(7) var<storage, read> listed: array<u32>;        // voxel numbers, tile by tile

// numba: test_tiles (tracing/tile_tests.py)
@compute @workgroup_size(BUNDLE)
fn test_tiles(@builtin(workgroup_id) group: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>,
              @builtin(local_invocation_index) lane: u32) {
    let s = (group.y * groups.x + group.x) * BUNDLE + lane;
    if (s >= params.rays) {
        return;
    }
    let bin = ray_bins[s];
    let bi = bin & 0xffffu;
    let bj = bin >> 16u;
    let tile = (bj >> params.tile_shift) * params.tiles_per_side + (bi >> params.tile_shift);
    let b = s * 6u;
    let ox = rays[b];
    let oy = rays[b + 1u];
    let oz = rays[b + 2u];
    let dx = rays[b + 3u];
    let dy = rays[b + 4u];
    let dz = rays[b + 5u];
    let ix = select(INF, 1.0 / dx, dx != 0.0);
    let iy = select(INF, 1.0 / dy, dy != 0.0);
    let iz = select(INF, 1.0 / dz, dz != 0.0);
    var best = best_t[s];
    var found = -1;
    for (var e = tile_starts[tile]; e < tile_starts[tile + 1u]; e++) {
        let q = listed[e];
        let voxel = voxels[q];
        if (real(voxel.x) >= best) {
            break;  // this brick and every later one start beyond the bound
        }
        let x = real(voxel.y);
        let y = real(voxel.z);
        let z = real(voxel.w);
        // The slab test of the reference tracer: the voxel's open interior.
        let sx = slab(ox, dx, ix, x, x + 1.0);
        let sy = slab(oy, dy, iy, y, y + 1.0);
        let sz = slab(oz, dz, iz, z, z + 1.0);
        let enter = max(sx.enter, max(sy.enter, sz.enter));
        let leave = min(sx.leave, min(sy.leave, sz.leave));
        let start = max(enter, 0.0);
        if (start < leave && start < best) {
            best = start;
            found = i32(q);
        }
    }
    best_t[s] = best;
    best_v[s] = found;
}
