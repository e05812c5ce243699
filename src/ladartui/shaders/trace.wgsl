// The voxel tracer as a compute shader: one invocation per ray.
//
// This is tracing/numba_backend.py and tracing/march.py (with tracing/axis.py) written again in WGSL:
// the same functions under the same names (without the leading underscore),
// the same steps in the same order, as fixed in docs/architecture.md ("Exact
// traversal", "March").
// Read the two side by side; change them together. In f64 both give the same
// answer, bit for bit, for every ray (tests/test_wgpu_precision.py).
//
// Cell space: voxel (i, j, k) spans [i, i+1) on each axis, ground at c_z = 0.
// tracing/wgpu_backend.py prepends a header (tracing/wgpu_occupancy.py)
// declaring `alias real = f64;` (or f32) and the constants shared with the host (tracing/config.py,
// wgsl_constants: hit kinds, INF, BUNDLE, method codes), the occupancy
// bindings, read through `fn occ(word) -> u32`, and shaders/axis.wgsl
// (boundary_t, cell_at, slab):
// one logical u32 array [root | regions | tiles | bricks | columns | cubes] that
// may be split over several storage bindings; cubes holds the four octants'
// u8 sides of one brick cell in one word (byte `octant`).
//
// Loop budget: lavapipe (llvmpipe) ends every loop of an invocation once all its
// loops together have run 65,535 iterations, a guard against endless shaders,
// and the code after the loop then runs as if the loop had ended normally. So
// the march samples at most `extra.z` (well under that) per dispatch and says
// UNFINISHED; the host dispatches the rest from sample `extra.y` on. A loop that
// ends early all the same (here or in the exact traversal) says CUT, and the
// host reports it instead of taking it for a miss.

struct Params {
    shape: vec4<i32>,        // nx, ny, nz
    bbox_lo: vec4<i32>,      // occupied box, cell space, hi exclusive
    bbox_hi: vec4<i32>,
    root_origin: vec4<i32>,  // cell of root cell (0, 0, 0), a multiple of 512
    root_dims: vec4<i32>,
    bases: vec4<u32>,        // first word of root, regions, tiles, bricks in occ()
    run: vec4<i32>,          // ray count, method (0 exact, 1 march), zmax, root cells
    extra: vec4<u32>,        // first word of columns in occ() (NO_COLUMNS: none), march: first sample, samples per pass; first_hits: 1 when all rays share origins[0..3]
    cube_origin: vec4<i32>,  // brick cell of the empty-cube box's corner; w: first word of cubes in occ()
    cube_dims: vec4<i32>,    // its size in bricks; all zero without cubes (no jumps)
    footprint: vec4<i32>,    // the scene's [0, nx) x [0, ny) in the rays' cell space: x0, y0, x1, y1
    reals: vec2<real>,       // march step (voxels), unused
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> rays: array<real>;             // ox oy oz dx dy dz per ray
@group(0) @binding(2) var<storage, read_write> hits: array<vec4<i32>>;  // kind, i, j, k
@group(0) @binding(3) var<storage, read_write> ranges: array<real>;     // t of the hit
@group(0) @binding(4) var<storage, read> starts: array<real>;           // bundle start per BUNDLE rays
// first_hits (exact rays, tracing/wgpu_hits.py): the host's arrays as they are, one word back a ray.
@group(0) @binding(5) var<storage, read> origins: array<real>;          // ox oy oz per ray
@group(0) @binding(6) var<storage, read> directions: array<real>;       // dx dy dz per ray
@group(0) @binding(7) var<storage, read_write> found: array<i32>;       // hit voxel's box offset, NO_VOXEL, CUT_WORD

// MISS, VOXEL, GROUND; UNFINISHED (march: no answer within this pass's samples);
// CUT (a loop was ended by the adapter, not by the ray): from the header.

struct Hit {
    kind: i32,
    i: i32,
    j: i32,
    k: i32,
    t: real,
}

fn miss() -> Hit {
    return Hit(MISS, -1, -1, -1, INF);
}

fn cut() -> Hit {
    return Hit(CUT, -1, -1, -1, INF);
}

// numba: _exit_boundary
fn exit_boundary(c: i32, s: u32, positive: bool) -> i32 {
    if (positive) {
        return ((c >> s) + 1) << s;
    }
    return (c >> s) << s;
}

// numba: node_slot (tracing/axis.py)
fn slot(x: i32, y: i32, z: i32, s: u32) -> u32 {
    return u32(((x >> s) & 7) | (((y >> s) & 7) << 3u) | (((z >> s) & 7) << 6u));
}

struct Skip {
    b: i32,
    t: real,
}

// Exit boundary and its parameter of the node c >> s on one axis (numba: _node_skip).
fn node_skip(c: i32, s: u32, positive: bool, moving: bool, o: real, d: real, inv: real) -> Skip {
    let b = exit_boundary(c, s, positive);
    return Skip(b, select(INF, boundary_t(real(b), o, inv), moving));
}

// Cell on one axis after crossing into a new node at t: the boundary cell for an
// axis that stepped, else cell_at(t) kept inside the node of c (numba: _enter).
fn enter(c: i32, b: i32, stepped: bool, positive: bool, s: u32, o: real, d: real, inv: real, t: real) -> i32 {
    if (stepped) {
        return select(b - 1, b, positive);
    }
    let lo = (c >> s) << s;
    return clamp_i(cell_at(o, d, inv, t), lo, lo + (1 << s) - 1);
}

// Cell on one axis on entering brick b at t after a brick step (numba: _brick_entry).
fn brick_entry(b: i32, stepped: bool, positive: bool, o: real, d: real, inv: real, t: real) -> i32 {
    return enter(b << 3u, select((b + 1) << 3u, b << 3u, positive), stepped, positive, 3u, o, d, inv, t);
}

fn root_cell(x: i32, y: i32, z: i32) -> u32 {
    let r = params.root_origin;
    return u32(((x - r.x) >> 9u) + params.root_dims.x * (((y - r.y) >> 9u) + params.root_dims.y * ((z - r.z) >> 9u)));
}

fn clamp_i(v: i32, lo: i32, hi: i32) -> i32 {
    return select(select(v, hi, v > hi), lo, v < lo);
}

// The first occupied voxel along one cell-space ray; kind MISS when none
// (numba: the per-ray body of _exact_kernel, steps 1 to 5).
// Empty root cells and regions are skipped as nodes; inside a tile a DDA over
// 8-voxel bricks skips empty bricks (and, going down, the part of a brick column
// above its highest brick), jumps across the empty cube of bricks ahead of the
// ray (Occupancy.cubes) and walks on past tile faces while bricks are known
// empty; inside a brick a voxel DDA tests bits and goes on into neighbouring
// non-empty bricks of the tile. `start` is the ray's bundle start (step 0).
fn first_voxel(ox: real, oy: real, oz: real, dx: real, dy: real, dz: real, start: real) -> Hit {
    let none = miss();
    if (params.run.w == 0) {  // empty scene: no root cells
        return none;
    }
    // Step 1: a ray inside a plane of cell faces enters no interior.
    if ((dx == 0.0 && ox == floor(ox)) || (dy == 0.0 && oy == floor(oy))
            || (dz == 0.0 && oz == floor(oz))) {
        return none;
    }
    let ix = select(INF, 1.0 / dx, dx != 0.0);
    let iy = select(INF, 1.0 / dy, dy != 0.0);
    let iz = select(INF, 1.0 / dz, dz != 0.0);
    let mx = dx != 0.0;
    let my = dy != 0.0;
    let mz = dz != 0.0;
    let lo = params.bbox_lo;
    let hi = params.bbox_hi;
    // Step 2: clip to the occupied box, from the bundle start on (step 0, computed
    // on the host by tracing/bundle.py for each BUNDLE rays: `starts`).
    let span_x = slab(ox, dx, ix, real(lo.x), real(hi.x));
    let span_y = slab(oy, dy, iy, real(lo.y), real(hi.y));
    let span_z = slab(oz, dz, iz, real(lo.z), real(hi.z));
    let t0 = max(start, max(span_x.enter, max(span_y.enter, span_z.enter)));
    let t1 = min(span_x.leave, min(span_y.leave, span_z.leave));
    if (!(t0 < t1)) {
        return none;
    }
    // Step 3: the start cell.
    var cx = clamp_i(cell_at(ox, dx, ix, t0), lo.x, hi.x - 1);
    var cy = clamp_i(cell_at(oy, dy, iy, t0), lo.y, hi.y - 1);
    var cz = clamp_i(cell_at(oz, dz, iz, t0), lo.z, hi.z - 1);
    let px = dx > 0.0;
    let py = dy > 0.0;
    let pz = dz > 0.0;
    let sx = select(-1, 1, px);
    let sy = select(-1, 1, py);
    let sz = select(-1, 1, pz);
    // Offset from a cell to its exit boundary, for the voxel DDA. A still axis
    // (inv = INF, origin off the boundaries) gets +1 so its parameter is huge.
    let fx = select(real(1.0), real(0.0), dx < 0.0);
    let fy = select(real(1.0), real(0.0), dy < 0.0);
    let fz = select(real(1.0), real(0.0), dz < 0.0);
    var t = t0;
    let rx0 = params.root_origin.x;
    let ry0 = params.root_origin.y;
    let rz0 = params.root_origin.z;
    let rdx = params.root_dims.x;
    // Brick columns (see Occupancy.columns), relative to the root grid.
    let qx0 = rx0 >> 3u;
    let qy0 = ry0 >> 3u;
    let qz0 = rz0 >> 3u;
    let qnx = rdx * 64;
    // Empty-cube sides (see Occupancy.cubes) for this ray's octant.
    let dox = params.cube_origin.x;
    let doy = params.cube_origin.y;
    let doz = params.cube_origin.z;
    let cube_base = bitcast<u32>(params.cube_origin.w);
    var ddx = params.cube_dims.x;
    let ddy = params.cube_dims.y;
    let ddz = params.cube_dims.z;
    let octant = select(1u, 0u, px) | select(2u, 0u, py);
    if (pz) {  // cubes are kept for rays that do not climb only
        ddx = 0;
    }
    let descending = dz < 0.0 && params.extra.x != NO_COLUMNS;  // the column skip's one gate
    let cap = 4 * (hi.x - lo.x + hi.y - lo.y + hi.z - lo.z) + 64;
    var steps = 0;
    while (steps < cap) {
        steps += 1;
        if (cx < lo.x || cy < lo.y || cz < lo.z || cx >= hi.x || cy >= hi.y || cz >= hi.z) {
            return none;  // only reachable through rounding at the box's edge
        }
        var s = 9u;
        let g = occ(params.bases.x + root_cell(cx, cy, cz));
        if (g != 0u) {
            s = 6u;
            let tl = occ(params.bases.y + (g - 1u) * 512u + slot(cx, cy, cz, 6u));
            if (tl != 0u) {
                // Inside a tile: DDA over its 8 x 8 x 8 brick slots.
                let tile = params.bases.z + (tl - 1u) * 512u;
                let gx = cx >> 6u;
                let gy = cy >> 6u;
                let gz = cz >> 6u;
                var bx = cx >> 3u;
                var by = cy >> 3u;
                var bz = cz >> 3u;
                var fresh = true;  // (cx, cy, cz) is the cell at t
                var stx = false;   // axes stepped by the last brick step
                var sty = false;
                var stz = false;
                while (steps < cap) {
                    // The empty cubes tell empty bricks without the tile; only a
                    // brick it cannot vouch for needs the tile, so only then does
                    // leaving the tile end this walk.
                    let ux = bx - dox;
                    let uy = by - doy;
                    let uz = bz - doz;
                    var far = -1;
                    if (0 <= ux && ux < ddx && 0 <= uy && uy < ddy && 0 <= uz && uz < ddz) {
                        let word = occ(cube_base + u32(ux + ddx * (uy + ddy * uz)));
                        far = i32((word >> (octant << 3u)) & 255u);
                    }
                    var br = 0u;
                    if (far <= 0) {
                        if ((bx >> 3u) != gx || (by >> 3u) != gy || (bz >> 3u) != gz) {
                            break;
                        }
                        br = occ(tile + u32((bx & 7) | ((by & 7) << 3u) | ((bz & 7) << 6u)));
                    }
                    if (br != 0u) {
                        if (!fresh) {
                            cx = brick_entry(bx, stx, px, ox, dx, ix, t);
                            cy = brick_entry(by, sty, py, oy, dy, iy, t);
                            cz = brick_entry(bz, stz, pz, oz, dz, iz, t);
                        }
                        // Voxel DDA inside the brick; t of an axis's next boundary is
                        // recomputed from that boundary whenever the axis steps.
                        // numba also skips empty 4- and 2-voxel blocks here. Skips never
                        // change the answer (docs/architecture.md, step 4), and on
                        // lavapipe the extra branches cost more than the steps they
                        // save (the voxel-by-voxel loop traced about 20 % more rays
                        // per CPU second), so the shader steps voxel by voxel; the
                        // f64 tests check the answers stay identical, t included.
                        var base = params.bases.w + (br - 1u) * 16u;
                        var tx = (real(cx) + fx - ox) * ix;
                        var ty = (real(cy) + fy - oy) * iy;
                        var tz = (real(cz) + fz - oz) * iz;
                        loop {
                            let bit = u32((cx & 7) | ((cy & 7) << 3u) | ((cz & 7) << 6u));
                            if (((occ(base + (bit >> 5u)) >> (bit & 31u)) & 1u) != 0u) {
                                return Hit(VOXEL, cx, cy, cz, t);
                            }
                            let tn = min(tx, min(ty, tz));
                            if (tn >= t1) {
                                return none;
                            }
                            steps += 1;
                            // Tied axes step together: touching an edge or corner is no visit.
                            if (tx == tn) {
                                cx += sx;
                                tx = (real(cx) + fx - ox) * ix;
                            }
                            if (ty == tn) {
                                cy += sy;
                                ty = (real(cy) + fy - oy) * iy;
                            }
                            if (tz == tn) {
                                cz += sz;
                                tz = (real(cz) + fz - oz) * iz;
                            }
                            t = tn;
                            if ((cx >> 3u) != bx || (cy >> 3u) != by || (cz >> 3u) != bz) {
                                // Into the next brick: stay in this loop while it is a
                                // non-empty brick of the same tile.
                                bx = cx >> 3u;
                                by = cy >> 3u;
                                bz = cz >> 3u;
                                if ((bx >> 3u) != gx || (by >> 3u) != gy || (bz >> 3u) != gz) {
                                    break;
                                }
                                br = occ(tile + u32((bx & 7) | ((by & 7) << 3u) | ((bz & 7) << 6u)));
                                if (br == 0u) {
                                    break;
                                }
                                base = params.bases.w + (br - 1u) * 16u;
                            }
                            if (steps >= cap) {
                                break;
                            }
                        }
                        bx = cx >> 3u;
                        by = cy >> 3u;
                        bz = cz >> 3u;
                        fresh = true;
                    } else {
                        // Skip empty bricks: the cube of `far` empty bricks ahead
                        // (Occupancy.cubes; one brick without it), or for a
                        // descending ray above the highest brick of its brick column
                        // that whole column part, whichever reaches further.
                        var k = select(1, far, far >= 2);
                        var near = k - 1;
                        var tbx = select(INF, (real(select((bx - near) << 3u, (bx + k) << 3u, px)) - ox) * ix, mx);
                        var tby = select(INF, (real(select((by - near) << 3u, (by + k) << 3u, py)) - oy) * iy, my);
                        var tbz = select(INF, (real(select((bz - near) << 3u, (bz + k) << 3u, pz)) - oz) * iz, mz);
                        var tn = min(tbx, min(tby, tbz));
                        var top = bz + 1;
                        if (descending) {
                            top = i32(occ(params.extra.x + u32((bx - qx0) + qnx * (by - qy0)))) + qz0;
                        }
                        var above = bz >= top;
                        if (above) {
                            let tcx = select(INF, (real(select(bx << 3u, (bx + 1) << 3u, px)) - ox) * ix, mx);
                            let tcy = select(INF, (real(select(by << 3u, (by + 1) << 3u, py)) - oy) * iy, my);
                            let tcz = (real(top << 3u) - oz) * iz;
                            let tc = min(tcx, min(tcy, tcz));
                            above = tc > tn || k == 1;
                            if (above) {
                                k = 1;
                                near = 0;
                                tbx = tcx;
                                tby = tcy;
                                tbz = tcz;
                                tn = tc;
                            }
                        }
                        if (tn >= t1) {
                            return none;
                        }
                        steps += 1;
                        stx = tbx == tn;
                        sty = tby == tn;
                        stz = tbz == tn;
                        if (stx) {
                            bx += sx * k;
                        } else if (near > 0) {
                            bx = clamp_i(cell_at(ox, dx, ix, tn) >> 3u, bx - select(near, 0, px), bx + select(0, near, px));
                        }
                        if (sty) {
                            by += sy * k;
                        } else if (near > 0) {
                            by = clamp_i(cell_at(oy, dy, iy, tn) >> 3u, by - select(near, 0, py), by + select(0, near, py));
                        }
                        if (stz) {
                            bz = select(bz + sz * k, top - 1, above);
                        } else if (above) {
                            bz = clamp_i(cell_at(oz, dz, iz, tn) >> 3u, top, bz);
                        } else if (near > 0) {
                            bz = clamp_i(cell_at(oz, dz, iz, tn) >> 3u, bz - select(near, 0, pz), bz + select(0, near, pz));
                        }
                        t = tn;
                        fresh = false;
                    }
                }
                if (!fresh) {
                    // Left the tile through an empty brick: the cell at t for the node lookup.
                    cx = brick_entry(bx, stx, px, ox, dx, ix, t);
                    cy = brick_entry(by, sty, py, oy, dy, iy, t);
                    cz = brick_entry(bz, stz, pz, oz, dz, iz, t);
                }
                continue;
            }
        }
        // Skip the empty root cell or region c >> s.
        let kx = node_skip(cx, s, px, mx, ox, dx, ix);
        let ky = node_skip(cy, s, py, my, oy, dy, iy);
        let kz = node_skip(cz, s, pz, mz, oz, dz, iz);
        let tn = min(kx.t, min(ky.t, kz.t));
        if (tn >= t1) {
            return none;
        }
        cx = enter(cx, kx.b, kx.t == tn, px, s, ox, dx, ix, tn);
        cy = enter(cy, ky.b, ky.t == tn, py, s, oy, dy, iy, tn);
        cz = enter(cz, kz.b, kz.t == tn, pz, s, oz, dz, iz, tn);
        t = tn;
    }
    if (steps < cap) {
        return cut();  // the loop condition still held: the adapter ended the loop
    }
    return none;
}

// The march's jump over an empty node (numba: last_sample_on_axis, the same steps): the
// last sample certain to stay in [lo_face, hi_face) on one axis, as a real, at most cap.
fn last_sample_on_axis(o: real, d: real, lo_face: real, hi_face: real, t_s: real, step: real, cap: real) -> real {
    if (d > 0.0) {
        return min(cap, ((hi_face - MARCH_SKIP_MARGIN - o) / d - t_s) / step);
    }
    if (d < 0.0) {
        return min(cap, ((lo_face + MARCH_SKIP_MARGIN - o) / d - t_s) / step);
    }
    return cap;
}

// The last sample certain to stay in the empty node of 1 << shift cells a side holding
// cell c and in the scene's box [lo.x, box.x) x [lo.y, box.y) x [lo.z, box.z) (below the
// current sample when no later one is).
fn last_sample_in_node(c: vec3<i32>, shift: u32, o: vec3<real>, d: vec3<real>, t_s: real, step: real, lo: vec3<real>, box: vec3<real>, samples: i32) -> i32 {
    let size = real(1 << shift);
    let b = vec3<real>((c >> vec3<u32>(shift)) << vec3<u32>(shift));
    let cap = real(samples - 1);
    let kx = last_sample_on_axis(o.x, d.x, max(b.x, lo.x), min(b.x + size, box.x), t_s, step, cap);
    let ky = last_sample_on_axis(o.y, d.y, max(b.y, lo.y), min(b.y + size, box.y), t_s, step, cap);
    let kz = last_sample_on_axis(o.z, d.z, max(b.z, lo.z), min(b.z + size, box.z), t_s, step, cap);
    let last = min(kx, min(ky, kz));
    if (last >= 1.0) {
        return i32(last) - 1;
    }
    return -1;
}

// The report's fixed-step march for one ray (numba: the per-ray body of march_kernel).
// Each sample's lookup is numba's; the brick found is remembered while the
// samples stay in it, which saves loads, not answers. Written as one loop with
// plain variables (a lookup function with its cache behind a pointer ran 8 %
// slower on lavapipe).
fn march_one(ox: real, oy: real, oz: real, dx: real, dy: real, dz: real) -> Hit {
    var key = vec3<i32>(-1);  // brick coordinates (cell >> 3) of the remembered lookup; never negative
    var base = 0u;            // its first word in occ() + 1, 0 when the brick is empty
    var empty = 3u;           // with base 0: the empty node's shift (9 root cell, 6 region, 3 brick)
    let step = params.reals.x;
    let zmax = real(params.run.z);
    let nx = real(params.shape.x);
    let ny = real(params.shape.y);
    // The footprint's sides: 0 and nx, 0 and ny unless f32 rays come shifted
    // (tracing/f32_rays.py, f32_shift; every box below is shifted with them).
    let x0 = real(params.footprint.x);
    let y0 = real(params.footprint.y);
    let x1 = real(params.footprint.z);
    let y1 = real(params.footprint.w);
    let top = zmax + 1.0;
    let lo = params.bbox_lo.xyz;
    let hi = params.bbox_hi.xyz;
    var t_s = real(0.0);
    if (oz > top) {
        if (dz >= 0.0) {
            return miss();
        }
        t_s = (top - oz) * (1.0 / dz);
    }
    let rising = dz >= 0.0;
    // From the start sample on, every sample is inside the extent's box or ends the ray.
    let limit = i32((sqrt(nx * nx + ny * ny + top * top) + 2.0) / step) + 2;
    // This pass's samples: [first, last).
    let first = i32(params.extra.y);
    let last = min(limit, first + i32(params.extra.z));
    var k = first;
    for (; k < last; k++) {
        let t = t_s + real(k) * step;
        let cx = ox + t * dx;
        let cy = oy + t * dy;
        let cz = oz + t * dz;
        let inside = x0 <= cx && cx < x1 && y0 <= cy && cy < y1;
        if (cz < 0.0) {
            if (inside) {
                return Hit(GROUND, i32(floor(cx)), i32(floor(cy)), 0, t);
            }
            return miss();
        }
        if (!inside || (cz >= top && rising)) {
            return miss();
        }
        let c = vec3<i32>(vec3<real>(floor(cx), floor(cy), floor(cz)));
        if (all(c >= lo) && all(c < hi)) {
            let here = c >> vec3<u32>(3u);
            if (any(here != key)) {
                key = here;
                base = 0u;
                empty = 9u;
                let g = occ(params.bases.x + root_cell(c.x, c.y, c.z));
                if (g != 0u) {
                    empty = 6u;
                    let tl = occ(params.bases.y + (g - 1u) * 512u + slot(c.x, c.y, c.z, 6u));
                    if (tl != 0u) {
                        empty = 3u;
                        let br = occ(params.bases.z + (tl - 1u) * 512u + slot(c.x, c.y, c.z, 3u));
                        if (br != 0u) {
                            base = params.bases.w + (br - 1u) * 16u + 1u;
                        }
                    }
                }
            }
            if (base == 0u) {
                // An empty node: on past its samples (none of them ends the ray).
                let o = vec3<real>(ox, oy, oz);
                let d = vec3<real>(dx, dy, dz);
                k = max(k, last_sample_in_node(c, empty, o, d, t_s, step, vec3<real>(x0, y0, 0.0), vec3<real>(x1, y1, top), last));
                continue;
            }
            let bit = slot(c.x, c.y, c.z, 0u);
            if (((occ(base - 1u + (bit >> 5u)) >> (bit & 31u)) & 1u) == 1u) {
                return Hit(VOXEL, c.x, c.y, c.z, t);
            }
        }
    }
    if (k < last) {
        return cut();
    }
    if (last < limit) {
        return Hit(UNFINISHED, -1, -1, -1, INF);
    }
    return miss();
}

// numba: _exact_kernel and march_kernel, one invocation per ray.
@compute @workgroup_size(BUNDLE)
fn trace_rays(@builtin(workgroup_id) group: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>,
              @builtin(local_invocation_index) lane: u32) {
    let r = (group.y * groups.x + group.x) * BUNDLE + lane;
    if (r >= u32(params.run.x)) {
        return;
    }
    let b = r * 6u;
    let ox = rays[b];
    let oy = rays[b + 1u];
    let oz = rays[b + 2u];
    let dx = rays[b + 3u];
    let dy = rays[b + 4u];
    let dz = rays[b + 5u];
    var hit: Hit;
    if (params.run.y == METHOD_EXACT) {
        // No voxel is MISS here: the host applies the ground rule in float64
        // (numba: ground_answers), where no fused multiply-add can move it.
        hit = first_voxel(ox, oy, oz, dx, dy, dz, starts[r / BUNDLE]);
    } else {
        hit = march_one(ox, oy, oz, dx, dy, dz);
    }
    hits[r] = vec4<i32>(hit.kind, hit.i, hit.j, hit.k);
    ranges[r] = hit.t;
}

// Exact rays without their answers: each ray's first voxel as its offset in the
// occupied box, (i - lo.x) + sx * ((j - lo.y) + sy * (k - lo.z)) with s the box's
// sides (the host makes sure that fits an i32); NO_VOXEL when it hits none (the
// host applies the ground rule), CUT_WORD when the adapter ended its loop. The
// host recomputes t (answers.voxel_entry, as for object order): a quarter of
// trace_rays' bytes back, and no repacking of the rays on the way in.
@compute @workgroup_size(BUNDLE)
fn first_hits(@builtin(workgroup_id) group: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>,
              @builtin(local_invocation_index) lane: u32) {
    let r = (group.y * groups.x + group.x) * BUNDLE + lane;
    if (r >= u32(params.run.x)) {
        return;
    }
    let b = r * 3u;
    let o = select(b, 0u, params.extra.w == 1u);  // a scan's one origin: 24 bytes written, not 24 a ray
    let hit = first_voxel(origins[o], origins[o + 1u], origins[o + 2u],
                          directions[b], directions[b + 1u], directions[b + 2u], starts[r / BUNDLE]);
    var word = NO_VOXEL;
    if (hit.kind == VOXEL) {
        let lo = params.bbox_lo;
        let side = params.bbox_hi - lo;
        word = (hit.i - lo.x) + side.x * ((hit.j - lo.y) + side.y * (hit.k - lo.z));
    } else if (hit.kind == CUT) {
        word = CUT_WORD;
    }
    found[r] = word;
}
