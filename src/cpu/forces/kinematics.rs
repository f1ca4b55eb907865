//! Geometry and kinematics of one contact: what the law reads (overlap, normal, arm,
//! relative velocity, the material pair).

use super::StepState;
use crate::base::geometry::{
    Geometry, WallSegment, disk_disk, disk_wall, spin_velocity, tangent, wall_from,
};
use crate::cpu::contacts::{Pair, WALL_BASE};
use crate::cpu::orientation::RotatedCorners;
use crate::law::ContactInput;
use crate::overlap::{
    AreaContact, Hint, disk_disk_area, disk_wall_area, polygon_disk, polygon_polygon_hinted,
    polygon_wall,
};
use crate::state::Particles;
use crate::state::offset;

/// Geometry and kinematics of one contact: what the law needs. The geometry is in a
/// frame at particle i's centre (`Geometry::arm`).
/// `area`: the overlap-area law, which sees every pair (disks too) by its overlap area.
pub fn contact_input(
    s: &StepState,
    area: bool,
    pair: Pair,
    history: f64,
) -> (Geometry, ContactInput) {
    if area {
        let c = area_contact(s.particles, s.corners, s.walls, pair).unwrap_or_default();
        return area_kinematics(s, pair, history, c);
    }
    let (g, d) = disk_geometry(s, pair);
    disk_kinematics(s, pair, history, g, d)
}

/// The disk laws' geometry of a pair (disk–disk or disk–wall), and the offset r_i − r_j
/// of a particle pair.
#[inline(always)]
pub(super) fn disk_geometry(s: &StepState, pair: Pair) -> (Geometry, Option<[f64; 2]>) {
    let (particles, i) = (s.particles, pair.i as usize);
    if pair.is_wall() {
        let wall = &s.walls[(pair.j - WALL_BASE) as usize];
        let w = wall_from(wall, particles.position(i));
        (disk_wall(particles.radius[i], &w), None)
    } else {
        let j = pair.j as usize;
        let d = offset(particles, i, j);
        let g = disk_disk(d, particles.radius[i], particles.radius[j]);
        (g, Some(d))
    }
}

/// What a disk law needs from the geometry g: the relative velocity of the two surfaces
/// at the contact point (rotation included), along n and t, and the masses.
#[inline(always)]
pub(super) fn disk_kinematics(
    s: &StepState,
    pair: Pair,
    history: f64,
    g: Geometry,
    d: Option<[f64; 2]>,
) -> (Geometry, ContactInput) {
    let i = pair.i as usize;
    let v1 = s.velocity[i];
    let s1 = spin_velocity(v1[2], g.arm);
    let (v2, m2) = material_velocity(s, pair, g.arm, d);
    let v12 = [v1[0] + s1[0] - v2[0], v1[1] + s1[1] - v2[1]];
    let t = tangent(g.n);
    // The centres' relative velocity and the spins, for the continuous law's readings
    // of paper 001 eq. 4 and 6 (a wall neither moves nor spins).
    let (vc2, w2) = match (pair.is_wall(), d) {
        (false, Some(_)) => {
            let v = s.velocity[pair.j as usize];
            ([v[0], v[1]], v[2])
        }
        _ => (wall_velocity(s, pair), 0.0),
    };
    let v_centres = (v1[0] - vc2[0]) * t[0] + (v1[1] - vc2[1]) * t[1];
    let m1 = s.particles.mass[i];
    let (m12, mass) = if m2.is_infinite() {
        (m1, m1)
    } else {
        let m12 = m1 * m2 / (m1 + m2);
        (m12, 2.0 * m12)
    };
    let (m_eff, pair_slot) = material_pair(s, pair, m12);
    let input = ContactInput {
        delta: g.delta,
        r: g.r,
        sigma: g.sigma,
        delta_dot: -(v12[0] * g.n[0] + v12[1] * g.n[1]),
        v_t: v12[0] * t[0] + v12[1] * t[1],
        v_centres,
        spin: v1[2] + w2,
        m12,
        mass,
        history,
        dt: s.dt,
        m_eff,
        pair: pair_slot,
    };
    (g, input)
}

/// The material form's view of a contact (src/law/restitution.rs): its effective mass,
/// a fixed partner or a wall infinitely heavy, and its slot in the pair table; (m12, 0)
/// for the other laws, which do not read them.
#[inline(always)]
pub(super) fn material_pair(s: &StepState, pair: Pair, m12: f64) -> (f64, u32) {
    use crate::law::restitution::{PairTable, effective_mass};
    if s.pair_side == 0 {
        return (m12, 0);
    }
    let p = s.particles;
    let i = pair.i as usize;
    if pair.is_wall() {
        let slot = PairTable::slot(s.pair_side, p.material[i], s.pair_side as u32 - 1);
        return (effective_mass(p.mass[i], p.fixed[i], None), slot);
    }
    let j = pair.j as usize;
    let m_eff = effective_mass(p.mass[i], p.fixed[i], Some((p.mass[j], p.fixed[j])));
    (
        m_eff,
        PairTable::slot(s.pair_side, p.material[i], p.material[j]),
    )
}

/// The surface velocity of a wall pair's wall.
#[inline(always)]
pub(super) fn wall_velocity(s: &StepState, pair: Pair) -> [f64; 2] {
    s.wall_velocity[(pair.j - WALL_BASE) as usize]
}

/// Velocity of particle j's material at the contact point (a wall's surface velocity),
/// and its mass (infinite for a wall). The point is `arm` from r_i, so `arm + d` from
/// r_j (d = r_i − r_j).
#[inline(always)]
pub(super) fn material_velocity(
    s: &StepState,
    pair: Pair,
    arm: [f64; 2],
    d: Option<[f64; 2]>,
) -> ([f64; 2], f64) {
    let (false, Some(d)) = (pair.is_wall(), d) else {
        return (wall_velocity(s, pair), f64::INFINITY);
    };
    let j = pair.j as usize;
    let v = s.velocity[j];
    let w = spin_velocity(v[2], [arm[0] + d[0], arm[1] + d[1]]);
    ([v[0] + w[0], v[1] + w[1]], s.particles.mass[j])
}

/// The overlap-area geometry of a pair (SPEC 2.3), whatever the shapes, in the frame of
/// i's centre; None when they do not overlap.
pub fn area_contact(
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    pair: Pair,
) -> Option<AreaContact> {
    area_contact_hinted(particles, corners, walls, pair, Hint::NONE).0
}

/// [`area_contact`] from the pair's hint (polygon pairs), and its hint for the next step.
#[inline(always)]
pub fn area_contact_hinted(
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    pair: Pair,
    hint: Hint,
) -> (Option<AreaContact>, Hint) {
    let i = pair.i as usize;
    let (ri, poly_i) = (particles.radius[i], particles.is_polygon(i));
    if pair.is_wall() {
        let wall = &walls[(pair.j - WALL_BASE) as usize];
        let w = wall_from(wall, particles.position(i));
        let c = if poly_i {
            polygon_wall(corners.of(i), &w)
        } else {
            disk_wall_area(ri, &w)
        };
        return (c, Hint::NONE);
    }
    let j = pair.j as usize;
    let d = offset(particles, i, j);
    let rj = particles.radius[j];
    let c = match (poly_i, particles.is_polygon(j)) {
        (true, true) => {
            return polygon_polygon_hinted(
                &corners.outline(i, [0.0; 2], ri),
                &corners.outline(j, [-d[0], -d[1]], rj),
                d,
                hint,
            );
        }
        // The polygon's centre relative to the disk's.
        (true, false) => polygon_disk(corners.of(i), d, rj, true),
        (false, true) => polygon_disk(corners.of(j), [-d[0], -d[1]], ri, false),
        (false, false) => disk_disk_area(d, ri, rj),
    };
    (c, Hint::NONE)
}

/// What the overlap-area law needs from an area contact's geometry (SPEC 2.3,
/// src/law/overlap_area.rs): δ = A/l, its rate L v_n / l and the depth A/L, and the
/// relative velocity at the force point. A pair that no longer overlaps (possible only
/// between finding and evaluating, which see the same state) gives zero input.
#[inline(always)]
pub(super) fn area_kinematics(
    s: &StepState,
    pair: Pair,
    history: f64,
    c: AreaContact,
) -> (Geometry, ContactInput) {
    let (particles, dt) = (s.particles, s.dt);
    let i = pair.i as usize;
    let d = (!pair.is_wall()).then(|| offset(particles, i, pair.j as usize));
    let v1 = s.velocity[i];
    let s1 = spin_velocity(v1[2], c.arm);
    let (v2, m2) = material_velocity(s, pair, c.arm, d);
    let v12 = [v1[0] + s1[0] - v2[0], v1[1] + s1[1] - v2[1]];
    let t = tangent(c.n);
    let m1 = particles.mass[i];
    let m12 = if m2.is_infinite() {
        m1
    } else {
        m1 * m2 / (m1 + m2)
    };
    // One division for the two quotients by l.
    let inv_l = if c.l > 0.0 { 1.0 / c.l } else { 0.0 };
    let (delta, depth) = if c.l > 0.0 {
        (
            c.area * inv_l,
            if c.chord > 0.0 { c.area / c.chord } else { 0.0 },
        )
    } else {
        (0.0, 0.0)
    };
    let v_n = -(v12[0] * c.n[0] + v12[1] * c.n[1]);
    let (m_eff, pair_slot) = material_pair(s, pair, m12);
    let input = ContactInput {
        delta,
        r: depth,
        sigma: 0.0,
        delta_dot: c.chord * v_n * inv_l,
        v_t: v12[0] * t[0] + v12[1] * t[1],
        // Read by the continuous law only, which takes disks.
        v_centres: 0.0,
        spin: 0.0,
        m12,
        mass: 2.0 * m12,
        history,
        dt,
        m_eff,
        pair: pair_slot,
    };
    let g = Geometry {
        n: c.n,
        delta,
        r: depth,
        sigma: 0.0,
        arm: c.arm,
    };
    (g, input)
}
