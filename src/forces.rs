//! Per-contact forces and their per-particle reduction.
//!
//! `contact_forces` evaluates each contact on its own (geometry → relative velocity →
//! law) and stores the force on particle i and the contact point. `reduce_forces` then
//! sums, for every particle, its contacts in contact-list order. On the CPU that is one
//! pass over the list adding +F to i and −F to j; it visits each particle's contacts in
//! increasing contact index, the same fixed order a per-particle GPU reduction uses, so
//! the sum never depends on thread timing (no float atomics).

use crate::contacts::{Pair, WALL_BASE};
use crate::geometry::{Geometry, WallSegment, cross, disk_disk, disk_wall, spin_velocity, tangent};
use crate::law::{ContactInput, ContactLaw};
use crate::overlap::{disk_disk_area, disk_wall_area, polygon_disk, polygon_polygon, polygon_wall};
use crate::shape::WorldShapes;
use crate::state::{Dof, Particles};

/// The result of one contact, kept for outputs and the reduction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    /// Total force on particle i (−force acts on j).
    pub force: [f64; 2],
    /// Contact point, where both forces act.
    pub point: [f64; 2],
    /// Normal (from j to i) and the normal and tangential components.
    pub n: [f64; 2],
    pub f_n: f64,
    pub f_t: f64,
    /// Geometric overlap δ.
    pub overlap: f64,
    /// Elastic energy stored in the contact.
    pub energy: f64,
}

/// Stage: forces of every contact, and the updated tangential history.
pub fn contact_forces(
    particles: &Particles,
    shapes: &WorldShapes,
    walls: &[WallSegment],
    law: &ContactLaw,
    dt: f64,
    pairs: &[Pair],
    history_in: &[f64],
    out: &mut Vec<ContactForce>,
    history_out: &mut Vec<f64>,
) {
    out.clear();
    history_out.clear();
    for (&pair, &history) in pairs.iter().zip(history_in) {
        let area = matches!(law, ContactLaw::OverlapArea(_));
        let (g, input) = contact_input(particles, shapes, walls, dt, area, pair, history);
        let res = law.evaluate(&input);
        let t = tangent(g.n);
        let force = [
            res.f_n * g.n[0] + res.f_t * t[0],
            res.f_n * g.n[1] + res.f_t * t[1],
        ];
        out.push(ContactForce {
            force,
            point: g.point,
            n: g.n,
            f_n: res.f_n,
            f_t: res.f_t,
            overlap: g.delta,
            energy: res.energy,
        });
        history_out.push(res.history);
    }
}

/// Geometry and kinematics of one contact: what the law needs.
/// `area`: the overlap-area law, which sees every pair (disks too) by its overlap area.
pub fn contact_input(
    particles: &Particles,
    shapes: &WorldShapes,
    walls: &[WallSegment],
    dt: f64,
    area: bool,
    pair: Pair,
    history: f64,
) -> (Geometry, ContactInput) {
    let i = pair.i as usize;
    if area {
        return area_contact_input(particles, shapes, walls, dt, pair, history);
    }
    let p1 = particles.position(i);
    let v1 = particles.velocity(i, dt);
    let (g, v2, w2, m2) = if pair.is_wall() {
        let wall = &walls[(pair.j - WALL_BASE) as usize];
        (
            disk_wall(p1, particles.radius[i], wall),
            [0.0, 0.0],
            0.0,
            f64::INFINITY,
        )
    } else {
        let j = pair.j as usize;
        let v = particles.velocity(j, dt);
        (
            disk_disk(
                p1,
                particles.radius[i],
                particles.position(j),
                particles.radius[j],
            ),
            [v[0], v[1]],
            v[2],
            particles.mass[j],
        )
    };
    let l1 = [g.point[0] - p1[0], g.point[1] - p1[1]];
    let s1 = spin_velocity(v1[2], l1);
    let s2 = if pair.is_wall() {
        [0.0, 0.0]
    } else {
        let p2 = particles.position(pair.j as usize);
        spin_velocity(w2, [g.point[0] - p2[0], g.point[1] - p2[1]])
    };
    // Relative velocity of the two surfaces at the contact point (rotation included).
    let v12 = [v1[0] + s1[0] - v2[0] - s2[0], v1[1] + s1[1] - v2[1] - s2[1]];
    let t = tangent(g.n);
    let m1 = particles.mass[i];
    let (m12, mass) = if m2.is_infinite() {
        (m1, m1)
    } else {
        let m12 = m1 * m2 / (m1 + m2);
        (m12, 2.0 * m12)
    };
    let input = ContactInput {
        delta: g.delta,
        r: g.r,
        sigma: g.sigma,
        delta_dot: -(v12[0] * g.n[0] + v12[1] * g.n[1]),
        v_t: v12[0] * t[0] + v12[1] * t[1],
        m12,
        mass,
        history,
        dt,
    };
    (g, input)
}

/// Velocity of particle j's material at the point x (zero for a wall), and its mass.
fn material_velocity(particles: &Particles, dt: f64, pair: Pair, x: [f64; 2]) -> ([f64; 2], f64) {
    if pair.is_wall() {
        return ([0.0, 0.0], f64::INFINITY);
    }
    let j = pair.j as usize;
    let v = particles.velocity(j, dt);
    let p = particles.position(j);
    let s = spin_velocity(v[2], [x[0] - p[0], x[1] - p[1]]);
    ([v[0] + s[0], v[1] + s[1]], particles.mass[j])
}

/// Geometry and kinematics of a polygon contact (SPEC 2.3, src/law/overlap_area.rs): the
/// law sees δ = A/l, its rate L v_n / l and the depth A/L. A pair that no longer
/// overlaps (possible only between finding and evaluating, which see the same state)
/// gives zero input.
fn area_contact_input(
    particles: &Particles,
    shapes: &WorldShapes,
    walls: &[WallSegment],
    dt: f64,
    pair: Pair,
    history: f64,
) -> (Geometry, ContactInput) {
    let i = pair.i as usize;
    let p1 = particles.position(i);
    let (ri, poly_i) = (particles.radius[i], particles.is_polygon(i));
    let c = if pair.is_wall() {
        let wall = &walls[(pair.j - WALL_BASE) as usize];
        if poly_i {
            polygon_wall(shapes.of(i), p1, wall)
        } else {
            disk_wall_area(p1, ri, wall)
        }
    } else {
        let j = pair.j as usize;
        let p2 = particles.position(j);
        match (poly_i, particles.is_polygon(j)) {
            (true, true) => polygon_polygon(shapes.of(i), p1, shapes.of(j), p2),
            (true, false) => polygon_disk(shapes.of(i), p1, p2, particles.radius[j], true),
            (false, true) => polygon_disk(shapes.of(j), p2, p1, ri, false),
            (false, false) => disk_disk_area(p1, ri, p2, particles.radius[j]),
        }
    }
    .unwrap_or_default();
    let v1 = particles.velocity(i, dt);
    let s1 = spin_velocity(v1[2], [c.point[0] - p1[0], c.point[1] - p1[1]]);
    let (v2, m2) = material_velocity(particles, dt, pair, c.point);
    let v12 = [v1[0] + s1[0] - v2[0], v1[1] + s1[1] - v2[1]];
    let t = tangent(c.n);
    let m1 = particles.mass[i];
    let m12 = if m2.is_infinite() {
        m1
    } else {
        m1 * m2 / (m1 + m2)
    };
    let (delta, depth) = if c.l > 0.0 {
        (
            c.area / c.l,
            if c.chord > 0.0 { c.area / c.chord } else { 0.0 },
        )
    } else {
        (0.0, 0.0)
    };
    let v_n = -(v12[0] * c.n[0] + v12[1] * c.n[1]);
    let input = ContactInput {
        delta,
        r: depth,
        sigma: 0.0,
        delta_dot: if c.l > 0.0 { c.chord * v_n / c.l } else { 0.0 },
        v_t: v12[0] * t[0] + v12[1] * t[1],
        m12,
        mass: 2.0 * m12,
        history,
        dt,
    };
    let g = Geometry {
        n: c.n,
        delta,
        r: depth,
        sigma: 0.0,
        point: c.point,
    };
    (g, input)
}

/// Stage: total contact force and torque (fx, fz, τ) on every particle.
pub fn reduce_forces(
    particles: &Particles,
    pairs: &[Pair],
    contacts: &[ContactForce],
    out: &mut Vec<Dof>,
) {
    out.clear();
    out.resize(particles.len(), [0.0; 3]);
    for (pair, c) in pairs.iter().zip(contacts) {
        let i = pair.i as usize;
        let pi = particles.position(i);
        let acc = &mut out[i];
        acc[0] += c.force[0];
        acc[1] += c.force[1];
        acc[2] += cross([c.point[0] - pi[0], c.point[1] - pi[1]], c.force);
        if !pair.is_wall() {
            let j = pair.j as usize;
            let pj = particles.position(j);
            let acc = &mut out[j];
            acc[0] -= c.force[0];
            acc[1] -= c.force[1];
            acc[2] -= cross([c.point[0] - pj[0], c.point[1] - pj[1]], c.force);
        }
    }
}
