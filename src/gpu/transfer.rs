//! Between host and device: the f64 state to the device's fixed-point layout and back,
//! and the spring table (the readback itself is `readback`).

use super::*;

/// Per-slot values of the device put in id order (`ids`: each slot's id).
pub(super) fn by_id<T: Copy>(ids: &[u32], slots: Vec<T>) -> Vec<T> {
    let mut out = slots.clone();
    for (&id, v) in ids.iter().zip(slots) {
        out[id as usize] = v;
    }
    out
}

/// A wall's line normal n = (−t_z, t_x) (t along a → b) in Q30 integers q, and how q is
/// off n: q = (1 + α) n + β t, from the f64 end points. With them `wall_line`
/// (geometry.wgsl) measures distances from any line, long and inclined, exactly in
/// integers plus α (up to 2⁻³¹) times the distance and β times the distance along it.
pub(super) fn wall_normal(w: &crate::base::geometry::WallSegment) -> ([i32; 2], f32, f32) {
    let ab = [w.b[0] - w.a[0], w.b[1] - w.a[1]];
    let len = ab[0].hypot(ab[1]).max(f64::MIN_POSITIVE);
    let t = [ab[0] / len, ab[1] / len];
    let n = [-t[1], t[0]];
    let nq = [(n[0] * Q30).round() as i32, (n[1] * Q30).round() as i32];
    let q = [nq[0] as f64 / Q30, nq[1] as f64 / Q30];
    let beta = q[0] * t[0] + q[1] * t[1];
    let alpha = q[0] * n[0] + q[1] * n[1] - 1.0;
    (nq, beta as f32, alpha as f32)
}

/// Marks a spheropolygon's sweep radius in the host's corner table: the entry after its
/// core's corners is (sweep, SWEEP_TAG) (spheropolygon.wgsl reads it there).
pub const SWEEP_TAG: f64 = f64::INFINITY;

/// A particle's entries in the corner table: its corners, then its sweep radius if it
/// is a spheropolygon.
pub fn corner_block(corners: &[[f64; 2]], sweep: f64) -> Vec<[f64; 2]> {
    let mut b = corners.to_vec();
    if sweep > 0.0 {
        b.push([sweep, SWEEP_TAG]);
    }
    b
}

/// The device's entry of a sweep radius: whole units, and the remainder's bits.
fn sweep_entry(sweep: f64, unit: f64) -> [i32; 4] {
    let whole = (sweep / unit).round();
    let rem = ((sweep - whole * unit) / unit) as f32;
    let w = whole as i32;
    let r = rem.to_bits() as i32;
    [w, r, w, r]
}

/// The device's corner buffer: every corner in whole position units, body frame in xy
/// and rotated to its particle's orientation in zw (as `rotate_corners` in
/// orientation.wgsl; a candidate's are rotated when it is placed); a sweep radius
/// (`SWEEP_TAG`) as `sweep_entry`.
pub(super) fn device_corners(
    table: &[[f64; 2]],
    states: &[State],
    props: &[Props],
    unit: f64,
) -> Vec<[i32; 4]> {
    let mut out: Vec<[i32; 4]> = table
        .iter()
        .map(|&v| {
            if v[1] == SWEEP_TAG {
                return sweep_entry(v[0], unit);
            }
            let b = orientation::corner_units(v, unit);
            [b[0], b[1], b[0], b[1]]
        })
        .collect();
    for (s, p) in states.iter().zip(props) {
        let sc = orientation::turn_sin_cos(s.turn);
        let [start, count] = p.shape;
        for c in &mut out[start as usize..(start + count) as usize] {
            let w = orientation::rotate_units([c[0], c[1]], sc);
            c[2] = w[0];
            c[3] = w[1];
        }
    }
    out
}

/// One particle's props with its corners counted from 0 (for `device_corners` on a
/// table of its own corners).
pub(super) fn pr_local(p: &Props) -> [Props; 1] {
    [Props {
        shape: [0, p.shape[1]],
        ..*p
    }]
}

/// Where each particle's corners start in the corner buffer: particles in id order, each
/// with its `corner_block`.
pub fn corner_starts(p: &Particles) -> Vec<u32> {
    (0..p.len())
        .scan(0u32, |next, i| {
            let start = *next;
            *next += p.shape[i].len() as u32 + p.is_swept(i) as u32;
            Some(start)
        })
        .collect()
}

/// Every particle's `corner_block`, in id order.
pub fn corner_table(p: &Particles) -> Vec<[f64; 2]> {
    (0..p.len())
        .flat_map(|i| corner_block(&p.shape[i], p.sweep[i]))
        .collect()
}

/// Host f64 particles → device layout.
pub fn to_device(p: &Particles, origin: [f64; 2], cell: f32) -> (Vec<State>, Vec<Props>) {
    let mut states = Vec::with_capacity(p.len());
    let mut props = Vec::with_capacity(p.len());
    let starts = corner_starts(p);
    for i in 0..p.len() {
        let q0 = p.q[0][i];
        let (anchor, frac, rem) = position::split2(q0[0] - origin[0], q0[1] - origin[1], cell);
        let mut s = State {
            anchor,
            frac,
            ..Default::default()
        };
        let (turn, turn_rem) = orientation::split_angle(q0[2]);
        s.turn = turn;
        s.q[0] = [rem[0], rem[1], turn_rem, 0.0];
        for k in 1..GEAR_VALUES {
            let v = p.q[k][i];
            s.q[k] = [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
        }
        (s.q1_whole, s.q[1]) = split_q1(p.q[1][i], cell);
        states.push(s);
        let flags = super::layout::flags(p.active[i], p.fixed[i], p.material[i], p.copy[i]);
        let (radius_units, radius_rem) = position::length_units(p.radius[i], cell);
        props.push(Props {
            radius: p.radius[i] as f32,
            mass: p.mass[i] as f32,
            inv_inertia: (1.0 / p.inertia[i]) as f32,
            flags,
            radius_units,
            radius_rem,
            shape: [starts[i], p.shape[i].len() as u32],
        });
    }
    (states, props)
}

/// q1 = v dt (length, length, radians) in the device's fixed point: whole position and
/// turn units, and the rest in f32 (twin of position.wgsl `renormalize_q1`).
pub fn split_q1(q1: [f64; 3], cell: f32) -> ([i32; 4], [f32; 4]) {
    let u = [
        position::unit(cell),
        position::unit(cell),
        orientation::TURN_UNIT,
    ];
    let whole = [0, 1, 2].map(|k| (q1[k] / u[k]).round());
    let rest = [0, 1, 2].map(|k| (q1[k] - whole[k] * u[k]) as f32);
    (
        [whole[0] as i32, whole[1] as i32, whole[2] as i32, 0],
        [rest[0], rest[1], rest[2], 0.0],
    )
}

/// `split_q1` back: q1 in f64.
pub fn join_q1(whole: [i32; 4], rest: [f32; 4], cell: f32) -> [f64; 3] {
    let u = [
        position::unit(cell),
        position::unit(cell),
        orientation::TURN_UNIT,
    ];
    [0, 1, 2].map(|k| whole[k] as f64 * u[k] + rest[k] as f64)
}

/// Device layout → host f64 particles.
pub fn from_device(
    states: &[State],
    props: &[Props],
    origin: [f64; 2],
    cell: f32,
    corner_table: &[[f64; 2]],
) -> Particles {
    let mut p = Particles::default();
    for (s, pr) in states.iter().zip(props) {
        let coord = |k: usize| {
            let f = position::Fixed {
                anchor: s.anchor[k],
                frac: s.frac[k],
                rem: s.q[0][k],
            };
            origin[k] + position::join(f, cell)
        };
        let theta = orientation::join_angle(s.turn, s.q[0][2]);
        p.q[0].push([coord(0), coord(1), theta]);
        for k in 1..GEAR_VALUES {
            let v = s.q[k];
            p.q[k].push([v[0] as f64, v[1] as f64, v[2] as f64]);
        }
        let last = p.q[1].len() - 1;
        p.q[1][last] = join_q1(s.q1_whole, s.q[1], cell);
        p.radius
            .push((pr.radius_units as f64 + pr.radius_rem as f64) * position::unit(cell));
        p.mass.push(pr.mass as f64);
        p.inertia.push(if pr.inv_inertia == 0.0 {
            f64::INFINITY
        } else {
            1.0 / pr.inv_inertia as f64
        });
        p.fixed.push(pr.flags & FIXED != 0);
        p.active.push(pr.flags & ACTIVE != 0);
        p.material
            .push((pr.flags >> MATERIAL_SHIFT) & ((1 << (COPY_SHIFT - MATERIAL_SHIFT)) - 1));
        let [start, count] = pr.shape;
        let (start, end) = (start as usize, (start + count) as usize);
        p.shape.push(corner_table[start..end].to_vec());
        // A spheropolygon's sweep follows its corners (`corner_block`).
        let sweep = match corner_table.get(end) {
            Some(&[r, tag]) if count > 0 && tag == SWEEP_TAG => r,
            _ => 0.0,
        };
        p.sweep.push(sweep);
        p.copy.push(pr.flags >> COPY_SHIFT);
    }
    p
}

/// A spring table laid out as the kernels expect (host twin of `insert` in
/// store_history.wgsl).
pub fn build_table(entries: &[Entry], cap: usize) -> Vec<Entry> {
    build_tables(entries, None, cap).0
}

/// The spring table and its spheropolygon springs beside it (`table_sub`, of one
/// element without `subs`; else `subs` gives each entry's, or none for an empty one).
pub fn build_tables(
    entries: &[Entry],
    subs: Option<&[SubSprings]>,
    cap: usize,
) -> (Vec<Entry>, Vec<SubSprings>) {
    let empty = Entry {
        i: EMPTY,
        ..Default::default()
    };
    let mut t = vec![empty; cap];
    let mut ts = vec![SubSprings::default(); if subs.is_some() { cap } else { 1 }];
    let subs = subs.unwrap_or(&[]);
    let mask = cap - 1;
    for (k, e) in entries.iter().enumerate() {
        let mut slot = hash_pair(e.i, e.j) as usize & mask;
        while t[slot].i != EMPTY {
            slot = (slot + 1) & mask;
        }
        t[slot] = *e;
        if let Some(sub) = subs.get(k) {
            ts[slot] = *sub;
        }
    }
    (t, ts)
}

/// A pair's sub-contact springs in the device's layout (f32; keys EMPTY past the last).
pub fn sub_to_device(s: &crate::cpu::springs::SubSprings) -> SubSprings {
    let mut d = SubSprings::default();
    for k in 0..s.count.min(4) {
        d.key[k] = s.key[k];
        d.xi[k] = s.xi[k] as f32;
    }
    d
}

/// The device's sub-contact springs back in f64.
pub fn sub_from_device(d: &SubSprings) -> crate::cpu::springs::SubSprings {
    let mut s = crate::cpu::springs::SubSprings::default();
    for k in 0..4 {
        if d.key[k] != EMPTY {
            s.key[s.count] = d.key[k];
            s.xi[s.count] = d.xi[k] as f64;
            s.count += 1;
        }
    }
    s
}

/// Looks a pair up in a device-layout table (host twin of `lookup_old`).
pub fn table_lookup(table: &[Entry], i: u32, j: u32) -> Option<f32> {
    let mask = table.len() - 1;
    let mut slot = hash_pair(i, j) as usize & mask;
    for _ in 0..table.len() {
        let e = table[slot];
        if e.i == EMPTY {
            return None;
        }
        if e.i == i && e.j == j {
            return Some(e.value);
        }
        slot = (slot + 1) & mask;
    }
    None
}

/// The walls in the device's layout: both ends in fixed point, the exact normal.
pub(super) fn device_walls(
    walls: &[crate::scene::Wall],
    origin: [f64; 2],
    cell_size: f32,
) -> Vec<Wall> {
    walls
        .iter()
        .map(|w| {
            // The segment at t = 0: `wall_at` in geometry.wgsl moves it.
            let seg = crate::base::geometry::WallSegment { a: w.from, b: w.to };
            let (a_anchor, a_frac, a_rem) =
                position::split2(seg.a[0] - origin[0], seg.a[1] - origin[1], cell_size);
            let (b_anchor, b_frac, b_rem) =
                position::split2(seg.b[0] - origin[0], seg.b[1] - origin[1], cell_size);
            let (nq, beta, alpha) = wall_normal(&seg);
            let m = w.motion.unwrap_or_default();
            let f = |v: [f64; 2]| [v[0] as f32, v[1] as f32];
            Wall {
                a_anchor,
                a_frac,
                a_rem,
                b_anchor,
                b_frac,
                b_rem,
                ab: [(seg.b[0] - seg.a[0]) as f32, (seg.b[1] - seg.a[1]) as f32],
                nq,
                beta,
                alpha,
                velocity: f(w.velocity),
                motion_v: f(m.velocity),
                amplitude: f(m.amplitude),
                omega: m.omega() as f32,
                pad: 0,
            }
        })
        .collect()
}

/// The particles and springs to upload: a GPU checkpoint's exact device state, else the
/// f64 state and spring table converted (with the spheropolygon springs beside the
/// entries: empty when there are none).
pub(super) fn initial_state(
    sim: &Simulation,
    device_state: Option<DeviceState>,
    origin: [f64; 2],
    cell_size: f32,
) -> (Vec<State>, Vec<Props>, Vec<Entry>, Vec<SubSprings>) {
    match device_state {
        Some(mut ds) => {
            // The corner buffer is laid out afresh: point each particle at its corners.
            for (pr, start) in ds.props.iter_mut().zip(corner_starts(&sim.particles)) {
                pr.shape[0] = start;
            }
            (ds.states, ds.props, ds.springs, ds.sub)
        }
        None => {
            let (s, p) = to_device(&sim.particles, origin, cell_size);
            let table = sim.spring_table();
            let entry = |k: u64, v: f64| Entry {
                i: (k >> 32) as u32,
                j: k as u32,
                value: v as f32,
                _pad: 0,
            };
            let mut e: Vec<Entry> = table.entries().map(|(k, v)| entry(k, v)).collect();
            let mut subs = Vec::new();
            if !table.sub.is_empty() {
                // Every pair with sub-contact springs has an entry, its springs beside it.
                let mut by_key: std::collections::BTreeMap<u64, (f64, SubSprings)> = (e.iter())
                    .map(|x| {
                        (
                            (x.i as u64) << 32 | x.j as u64,
                            (x.value as f64, SubSprings::default()),
                        )
                    })
                    .collect();
                for (&k, sub) in &table.sub {
                    by_key.entry(k).or_insert((0.0, SubSprings::default())).1 = sub_to_device(sub);
                }
                e = by_key.iter().map(|(&k, &(v, _))| entry(k, v)).collect();
                subs = by_key.into_values().map(|(_, s)| s).collect();
            }
            (s, p, e, subs)
        }
    }
}
