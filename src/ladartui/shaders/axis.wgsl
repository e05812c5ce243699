// One-axis cell arithmetic shared by the shaders (tracing/axis.py, the same
// functions under the same names). INF (from the header, tracing/config.py's
// SHADER_INF) stands for +inf: WGSL has no infinity literal.

struct Span {
    enter: real,
    leave: real,
}

// The one formula for boundary parameters (tracing/axis.py: boundary_t).
fn boundary_t(b: real, o: real, inv: real) -> real {
    return (b - o) * inv;
}

// Cell index on one axis just after parameter t, exact against boundary_t (tracing/axis.py: cell_at).
fn cell_at(o: real, d: real, inv: real, t: real) -> i32 {
    var c = floor(o + t * d);
    if (d > 0.0) {
        if (boundary_t(c + 1.0, o, inv) <= t) {
            c += 1.0;
        } else if (boundary_t(c, o, inv) > t) {
            c -= 1.0;
        }
    } else if (d < 0.0) {
        if (boundary_t(c, o, inv) <= t) {
            c -= 1.0;
        } else if (boundary_t(c + 1.0, o, inv) > t) {
            c += 1.0;
        }
    }
    return i32(c);
}

// Entry and exit parameters of [lo, hi) on one axis; (inf, -inf) when never inside (tracing/axis.py: slab).
fn slab(o: real, d: real, inv: real, lo: real, hi: real) -> Span {
    if (d > 0.0) {
        return Span(boundary_t(lo, o, inv), boundary_t(hi, o, inv));
    }
    if (d < 0.0) {
        return Span(boundary_t(hi, o, inv), boundary_t(lo, o, inv));
    }
    if (lo < o && o < hi) {
        return Span(-INF, INF);
    }
    return Span(INF, -INF);
}
