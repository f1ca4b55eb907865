// Which query a pair of the overlap-area law takes, and the pairs' outlines loaded from
// the particle buffers (polygons_ij, polygon_wall_iw).

// The area contact of particle i with particle j (both polygons), in length units with
// the force point relative to centre i. Corners are exact in a frame at j's centre and
// clipped in f32 relative to the middle of the pair.
fn polygons_ij(i: u32, j: u32) -> AreaContact {
    let o = offset_ij(i, j);
    // Centres more than 1.5 cells apart cannot touch (and their corners would not fit
    // an i32 in the frame).
    if (!o.near || any(abs(o.d) > vec2<i32>(FRAC_ONE + FRAC_ONE / 2))) { return no_contact(); }
    var p = load_outline(i, o.d, o.e);
    var q = load_outline(j, vec2<i32>(0), vec2<f32>(0.0));
    let h = o.d / vec2<i32>(2);
    let ci = vec2<f32>(o.d - h) + o.e;
    var g = polygon_polygon(&p, &q, h, ci, vec2<f32>(-h));
    let u = params.unit;
    g.area *= u * u;
    g.chord *= u;
    g.l *= u;
    g.point = (g.point - ci) * u;
    return g;
}

// An offset in f32 units (exact when near, else to f32 precision).
fn offset_units(o: Offset) -> vec2<f32> {
    if (o.near) { return vec2<f32>(o.d) + o.e; }
    return offset_vector(o) * params.inv_unit;
}

// The area contact of particle i with wall w, in length units in i's frame.
fn polygon_wall_iw(i: u32, w: u32) -> AreaContact {
    let s = state[i];
    let wall = wall_at(w);
    let oa = offset(wall.a_anchor, wall.a_frac, wall.a_rem, s.anchor, s.frac, s.q[0].xy);
    let ob = offset(wall.b_anchor, wall.b_frac, wall.b_rem, s.anchor, s.frac, s.q[0].xy);
    let l = wall_line(i, w);
    if (!l.near) { return no_contact(); }
    var p = load_outline(i, vec2<i32>(0), vec2<f32>(0.0));
    var g = polygon_wall(&p, offset_units(oa), offset_units(ob), l);
    let u = params.unit;
    g.area *= u * u;
    g.chord *= u;
    g.l *= u;
    g.point *= u;
    return g;
}

// The area contact of particles i and j, whatever their shapes (force point relative
// to centre i). The pipelines are built for the shapes a scene has (`POLYGON_SHAPES`,
// `DISK_SHAPES`): the branches of the others compile away, since a thread that skips a
// branch still waits for its neighbours that take it, and a software adapter runs every
// branch of every thread.
fn area_contact(i: u32, j: u32) -> AreaContact {
    if (!DISK_SHAPES) { return polygons_ij(i, j); }
    if (!POLYGON_SHAPES) { return disks_area_ij(i, j); }
    let pi = props[i].shape.y > 0u;
    let pj = props[j].shape.y > 0u;
    if (pi && pj) { return polygons_ij(i, j); }
    if (pi) { return polygon_disk_ij(i, j, true); }
    if (pj) { return polygon_disk_ij(j, i, false); }
    return disks_area_ij(i, j);
}

fn area_contact_wall(i: u32, w: u32) -> AreaContact {
    if (!DISK_SHAPES) { return polygon_wall_iw(i, w); }
    if (!POLYGON_SHAPES) { return disk_wall_area(i, w); }
    if (props[i].shape.y > 0u) { return polygon_wall_iw(i, w); }
    return disk_wall_area(i, w);
}
