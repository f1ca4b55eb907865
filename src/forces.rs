//! Per-contact forces and their per-particle reduction.
//!
//! `contact_forces` evaluates each contact on its own (geometry → relative velocity →
//! law) and stores the force on particle i and the contact point. `reduce_forces` then
//! sums, for every particle, its contacts in contact-list order. On the CPU that is one
//! pass over the list adding +F to i and −F to j; it visits each particle's contacts in
//! increasing contact index, the same fixed order a per-particle GPU reduction uses, so
//! the sum never depends on thread timing (no float atomics).

use crate::contacts::{Pair, WALL_BASE};
use crate::geometry::{
    Geometry, WallSegment, disk_disk, disk_wall, spin_velocity, tangent, wall_from,
};
use crate::law::hertz_cohesive::HertzCohesive;
use crate::law::{ContactInput, ContactLaw, ContactOutput, Law};
use crate::neighbours::{NeighbourList, id_pair};
use crate::overlap::{
    AreaContact, Hint, disk_disk_area, disk_wall_area, polygon_disk, polygon_polygon_hinted,
    polygon_wall,
};
use crate::shape::RotatedCorners;
use crate::spheropolygon::{SubContact, SubSprings};
use crate::springs::pair_key;
use crate::state::{Dof, Particles};
use std::sync::atomic::{AtomicU64, Ordering};

/// The result of one contact, kept for outputs and the reduction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    /// Total force on particle i (−force acts on j).
    pub force: [f64; 2],
    /// Its torques: about i's centre, arm × F, and about j's, (arm + r_i − r_j) × F (the
    /// torque on j is minus that; 0 for a wall).
    pub torque: [f64; 2],
    /// Contact point, where both forces act (world coordinates, for outputs).
    pub point: [f64; 2],
    /// The contact point relative to particle i's centre: the branch vector the torques
    /// use (relative to j's centre it is `arm + r_i − r_j`).
    pub arm: [f64; 2],
    /// Normal (from j to i) and the normal and tangential components.
    pub n: [f64; 2],
    pub f_n: f64,
    pub f_t: f64,
    /// Geometric overlap δ.
    pub overlap: f64,
    /// Elastic energy stored in the contact.
    pub energy: f64,
}

/// What every contact of a step reads: the state, each particle's velocity (q1/dt,
/// computed once per step, `velocities`), the rotated corners and the walls.
#[derive(Clone, Copy)]
pub struct StepState<'a> {
    pub particles: &'a Particles,
    pub velocity: &'a [Dof],
    pub corners: &'a RotatedCorners,
    pub walls: &'a [WallSegment],
    pub dt: f64,
    /// The side of the material form's pair table (src/law/restitution.rs); 0 without.
    pub pair_side: usize,
}

/// Stage: the velocity (vx, vz, ω) = q1/dt of every particle.
pub fn velocities(particles: &Particles, dt: f64, out: &mut Vec<Dof>) {
    out.resize(particles.len(), [0.0; 3]);
    crate::parallel::for_each(out, |i, v| *v = particles.velocity(i, dt));
}

/// Stage: forces of every contact, and the updated tangential history.
#[allow(clippy::too_many_arguments)]
pub fn contact_forces(
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    law: &ContactLaw,
    dt: f64,
    pairs: &[Pair],
    history_in: &[f64],
    out: &mut Vec<ContactForce>,
    history_out: &mut Vec<f64>,
) {
    let mut velocity = Vec::new();
    velocities(particles, dt, &mut velocity);
    let s = StepState {
        particles,
        velocity: &velocity,
        corners,
        walls,
        dt,
        pair_side: law.pair_table().map_or(0, |t| t.side),
    };
    out.clear();
    history_out.clear();
    let area = matches!(law, ContactLaw::OverlapArea(_));
    for (&pair, &history) in pairs.iter().zip(history_in) {
        let (g, input) = contact_input(&s, area, pair, history);
        let (c, h) = contact_force(particles, |c| law.evaluate(c), pair, &g, &input);
        out.push(c);
        history_out.push(h);
    }
}

/// The law applied to one contact's geometry and kinematics: the force on i and the
/// updated history.
#[inline(always)]
fn contact_force(
    particles: &Particles,
    evaluate: impl Fn(&ContactInput) -> ContactOutput,
    pair: Pair,
    g: &Geometry,
    input: &ContactInput,
) -> (ContactForce, f64) {
    let res = evaluate(input);
    let t = tangent(g.n);
    let force = [
        res.f_n * g.n[0] + res.f_t * t[0],
        res.f_n * g.n[1] + res.f_t * t[1],
    ];
    let i = pair.i as usize;
    let p = particles.position(i);
    let arm_j = (!pair.is_wall()).then(|| {
        let d = offset(particles, i, pair.j as usize);
        [g.arm[0] + d[0], g.arm[1] + d[1]]
    });
    let c = ContactForce {
        force,
        torque: res.torques(force, g.arm, arm_j),
        point: [p[0] + g.arm[0], p[1] + g.arm[1]],
        arm: g.arm,
        n: g.n,
        f_n: res.f_n,
        f_t: res.f_t,
        overlap: g.delta,
        energy: res.energy,
    };
    (c, res.history)
}

/// One candidate of the neighbour list: its contact force and updated history if the
/// pair touches (the test of `contacts::find_contacts`, with the geometry computed once:
/// the disks' for the disk laws, the overlap for polygons), None if it does not.
#[inline(always)]
pub fn candidate_force<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    history: f64,
) -> Option<(ContactForce, f64)> {
    candidate_force_hinted(s, law, pair, history, Hint::NONE).0
}

/// [`candidate_force`] from the candidate's hint of its last evaluation (polygon pairs,
/// `overlap::Hint`: the same result to the bit, with less work), and its hint for the
/// next.
#[inline(always)]
pub fn candidate_force_hinted<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    history: f64,
    hint: Hint,
) -> (Option<(ContactForce, f64)>, Hint) {
    let (g, input, hint) = if L::AREA {
        let (c, hint) = area_candidate(s, law, pair, hint);
        let Some(c) = c else {
            return (None, hint);
        };
        let (g, input) = area_kinematics(s, pair, history, c);
        (g, input, hint)
    } else {
        let Some((g, d)) = disk_candidate(s, law, pair) else {
            return (None, Hint::NONE);
        };
        let (g, input) = disk_kinematics(s, pair, history, g, d);
        (g, input, Hint::NONE)
    };
    let r = contact_force(s.particles, |c| law.evaluate(c), pair, &g, &input);
    (Some(r), hint)
}

/// A disk law's first half of `candidate_force`: the geometry of a candidate, None when
/// it does not touch.
#[inline(always)]
fn disk_candidate<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
) -> Option<(Geometry, Option<[f64; 2]>)> {
    let (g, d) = disk_geometry(s, pair);
    // A NaN distance (a diverged state) interacts with nothing.
    if g.r.is_nan() || g.r >= law.range_factor() * g.sigma {
        return None;
    }
    Some((g, d))
}

/// A disk law's second half of `candidate_force`: the contact of a touching candidate.
#[inline(always)]
fn disk_candidate_force<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    history: f64,
    (g, d): (Geometry, Option<[f64; 2]>),
) -> (ContactForce, f64) {
    let (g, input) = disk_kinematics(s, pair, history, g, d);
    contact_force(s.particles, |c| law.evaluate(c), pair, &g, &input)
}

/// Candidates of a disk law evaluated per block, each half for the whole block at once.
/// Alone, one candidate is a long chain of dependent steps (a square root, a division,
/// the law) that the processor cannot overlap with the next; the first half of several
/// candidates side by side keeps it busy. Each candidate's arithmetic is unchanged.
const DISK_BLOCK: usize = 16;

/// Candidates of the overlap-area law evaluated per block (`candidates_with`), as
/// [`DISK_BLOCK`].
const AREA_BLOCK: usize = 16;

/// The overlap-area law's first half of `candidate_force_hinted`: the overlap of a
/// candidate that touches (zero area for disks whose circles touch), None when it does
/// not, and the pair's hint for the next step.
#[inline(always)]
fn area_candidate<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    hint: Hint,
) -> (Option<AreaContact>, Hint) {
    let (p, c) = (s.particles, s.corners);
    let (i, j) = (pair.i as usize, pair.j as usize);
    if !pair.is_wall() && !c.of(i).is_empty() && !c.of(j).is_empty() {
        let d = offset(p, i, j);
        // The circumscribed circles within range (`contacts::circles_touch`), squared.
        let (ri, rj) = (p.radius[i], p.radius[j]);
        let reach = law.range_factor() * (ri + rj);
        if !(d[0] * d[0] + d[1] * d[1] < reach * reach) {
            return (None, Hint::NONE);
        }
        return polygon_polygon_hinted(
            &c.outline(i, [0.0; 2], ri),
            &c.outline(j, [-d[0], -d[1]], rj),
            d,
            hint,
        );
    }
    if !crate::contacts::circles_touch(s.particles, s.walls, law.range_factor(), pair) {
        return (None, Hint::NONE);
    }
    let (c, hint) = area_contact_hinted(s.particles, s.corners, s.walls, pair, hint);
    // Polygons touch when their outlines overlap (disks: when their circles do).
    let polygon = p.is_polygon(i) || (!pair.is_wall() && p.is_polygon(j));
    if polygon && c.is_none() {
        return (None, hint);
    }
    (Some(c.unwrap_or_default()), hint)
}

/// Whether a contact shows a diverging state: a non-finite force, or an overlap beyond
/// `max_overlap` of the smaller radius (limits.max_overlap).
#[inline(always)]
pub fn diverges(particles: &Particles, pair: Pair, c: &ContactForce, max_overlap: f64) -> bool {
    if !(c.force[0].is_finite() && c.force[1].is_finite()) {
        return true;
    }
    // Most contacts are far below the limit: a multiplication (with room for rounding)
    // tells, and only those near it take the division that decides.
    let rmin = smaller_radius(particles, pair);
    c.overlap > 0.999 * max_overlap * rmin && c.overlap / rmin > max_overlap
}

/// The smaller radius of a pair (a wall: the particle's).
#[inline(always)]
fn smaller_radius(particles: &Particles, pair: Pair) -> f64 {
    let ri = particles.radius[pair.i as usize];
    if pair.is_wall() {
        ri
    } else {
        ri.min(particles.radius[pair.j as usize])
    }
}

/// A contact's overlap relative to the smaller radius.
pub fn overlap_ratio(particles: &Particles, pair: Pair, c: &ContactForce) -> f64 {
    c.overlap / smaller_radius(particles, pair)
}

/// What the force reduction needs of one candidate: whether it touches, its force on i
/// and its two torques (`ContactForce::torque`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kick {
    pub force: [f64; 2],
    pub torque: [f64; 2],
    pub contact: bool,
}

/// This step's results of the candidates: for each, its kick and its updated history
/// (0 when not in contact), and when recording, the whole contact (for outputs).
#[derive(Clone, Debug, Default)]
pub struct CandidateResults {
    pub kicks: Vec<Kick>,
    pub history: Vec<f64>,
    /// Spheropolygon pairs (law hertz_cohesive): each candidate's sub-contact springs
    /// (empty under the other laws).
    pub sub_history: Vec<SubSprings>,
    /// Every candidate's contact, or None; empty when the step did not record.
    pub contacts: Vec<Option<ContactForce>>,
    /// The first candidate (by pair of ids) whose contact diverges (`diverges`), with
    /// that contact.
    pub diverging: Option<(usize, ContactForce)>,
}

/// Stage: every candidate of the neighbour list evaluated on its own, in parallel, into
/// `out`. The loop is specialised to the law. `record`: keep every whole contact too.
/// `ids`: each memory slot's particle id.
pub fn candidate_forces(
    s: &StepState,
    law: &ContactLaw,
    list: &NeighbourList,
    ids: &[u32],
    max_overlap: f64,
    record: bool,
    out: &mut CandidateResults,
) {
    let c = (list, ids, max_overlap, record);
    match law {
        ContactLaw::SpringDashpot(l) => candidates_with(s, l, c, out),
        ContactLaw::OverlapArea(l) => candidates_with(s, l, c, out),
        ContactLaw::Continuous(l) => candidates_with(s, l, c, out),
        ContactLaw::HertzCohesive(l) => spheropolygon_candidates(s, l, c, out),
    }
}

/// The candidates of a spheropolygon scene (law hertz_cohesive, SPEC 2.4): each pair's
/// force is the sum over its sub-contacts (`spheropolygon::pair_force`), each with its
/// spring from the list's slot (`NeighbourList::sub_history`). A disk is a point core
/// swept by its radius; a wall a segment of sweep 0. When recording, a pair is reported
/// as one contact: its total force, at the point whose Σ f ⊗ l is nearest its
/// sub-contacts' (`centre_of_forces`), with its deepest sub-contact's normal and overlap.
fn spheropolygon_candidates(
    s: &StepState,
    law: &HertzCohesive,
    (list, ids, max_overlap, record): (&NeighbourList, &[u32], f64, bool),
    out: &mut CandidateResults,
) {
    let n = list.pairs.len();
    out.kicks.resize(n, Kick::default());
    out.sub_history.resize(n, SubSprings::default());
    // The pair slot's own history is unused: its springs are the sub-contacts'.
    out.history.clear();
    out.history.resize(n, 0.0);
    out.contacts.clear();
    if record {
        out.contacts.resize(n, None);
    }
    let first = AtomicU64::new(u64::MAX);
    let watch = Watch {
        particles: s.particles,
        ids,
        max_overlap,
        first: &first,
    };
    let springs = if list.sub_history.len() == n {
        &list.sub_history[..]
    } else {
        &[]
    };
    let evaluate = |k: usize| spheropolygon_candidate(s, law, list.pairs[k], springs.get(k));
    let contacts = std::sync::Mutex::new(Vec::new());
    crate::parallel::for_each2(&mut out.kicks, &mut out.sub_history, |k, kick, sub| {
        let (c, new) = evaluate(k);
        *sub = new;
        let mut h = 0.0;
        let c = settle(&watch, list.pairs[k], c.map(|c| (c, 0.0)), kick, &mut h);
        if record && c.is_some() {
            contacts
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push((k, c));
        }
    });
    for (k, c) in contacts.into_inner().unwrap_or_else(|e| e.into_inner()) {
        out.contacts[k] = c;
    }
    let key = first.into_inner();
    out.diverging = (key != u64::MAX).then(|| {
        let k = (list.pairs.iter())
            .position(|&p| pair_key(id_pair(p, ids)) == key)
            .expect("the diverging pair is a candidate");
        let c = evaluate(k).0.expect("a diverging candidate is a contact");
        (k, c)
    });
}

/// One spheropolygon candidate: its contact (None when no sub-contact is in range) and
/// its sub-contacts' updated springs.
fn spheropolygon_candidate(
    s: &StepState,
    law: &HertzCohesive,
    pair: Pair,
    springs: Option<&SubSprings>,
) -> (Option<ContactForce>, SubSprings) {
    let p = s.particles;
    let i = pair.i as usize;
    const POINT: [[f64; 2]; 1] = [[0.0, 0.0]];
    // A particle's core, turned, and its sweep (a disk: a point swept by its radius).
    let core = |k: usize| -> (&[[f64; 2]], f64) {
        if p.is_swept(k) {
            (s.corners.of(k), p.sweep[k])
        } else {
            (&POINT, p.radius[k])
        }
    };
    let mi = p.mass[i];
    let none = SubSprings::default();
    let springs = springs.unwrap_or(&none);
    let f = if pair.is_wall() {
        let w = wall_from(&s.walls[(pair.j - WALL_BASE) as usize], p.position(i));
        let seg = [w.a, w.b];
        let motion = (s.velocity[i], [0.0; 3]);
        crate::spheropolygon::pair_force(
            law,
            core(i),
            (&seg, 0.0),
            [0.0; 2],
            motion,
            (mi, mi),
            springs,
            s.dt,
        )
    } else {
        let j = pair.j as usize;
        let mj = p.mass[j];
        let m12 = mi * mj / (mi + mj);
        let d = offset(p, i, j);
        let motion = (s.velocity[i], s.velocity[j]);
        crate::spheropolygon::pair_force(
            law,
            core(i),
            core(j),
            d,
            motion,
            (m12, 2.0 * m12),
            springs,
            s.dt,
        )
    };
    let Some(deepest) = f
        .contacts
        .iter()
        .map(|(c, _)| c)
        .max_by(|a, b| a.delta.total_cmp(&b.delta))
    else {
        return (None, f.springs);
    };
    let t = tangent(deepest.n);
    let pos = p.position(i);
    let arm = centre_of_forces(&f.contacts).unwrap_or(deepest.arm);
    let c = ContactForce {
        force: f.force,
        // ContactForce's second torque is about j's centre, arm' × F (on j: minus that).
        torque: [f.torque[0], -f.torque[1]],
        point: [pos[0] + arm[0], pos[1] + arm[1]],
        arm,
        n: deepest.n,
        f_n: f.force[0] * deepest.n[0] + f.force[1] * deepest.n[1],
        f_t: f.force[0] * t[0] + f.force[1] * t[1],
        overlap: deepest.delta,
        energy: f.contacts.iter().map(|(_, r)| r.energy).sum(),
    };
    (Some(c), f.springs)
}

/// The point a spheropolygon pair is reported at, as an arm from i's centre: the l whose
/// F ⊗ l comes closest (least squares over the four components) to the pair's
/// Σ_k f_k ⊗ l_k, with F = Σ_k f_k its total force: l = Σ_k (F·f_k) l_k / |F|². Where
/// the sub-contacts' forces are parallel (rods side by side without friction: one
/// normal) F ⊗ l is exactly Σ_k f_k ⊗ l_k, so the stress of each grain (paper 000 eq.
/// 8) is that of its sub-contacts; otherwise it is the projection of that sum on F's
/// direction, never larger than the sum itself. (Weighting by the normal forces alone,
/// as before stop 33, put the tangential force of a cohesive pair whose sub-contacts
/// push and pull hundreds of rod lengths away.) None when |F|² ≤ 10⁻¹² Σ_k |f_k|²
/// (then the deepest sub-contact's point: F ⊗ l ≈ 0). Twin of the weighting in
/// spheropolygon.wgsl `spheropolygon_force`.
fn centre_of_forces(subs: &[(SubContact, crate::law::ContactOutput)]) -> Option<[f64; 2]> {
    let force = |(c, r): &(SubContact, crate::law::ContactOutput)| {
        let t = tangent(c.n);
        [r.f_n * c.n[0] + r.f_t * t[0], r.f_n * c.n[1] + r.f_t * t[1]]
    };
    let total = subs
        .iter()
        .map(force)
        .fold([0.0; 2], |a, f| [a[0] + f[0], a[1] + f[1]]);
    let (mut p, mut sizes) = ([0.0; 2], 0.0);
    for sub in subs {
        let f = force(sub);
        let w = total[0] * f[0] + total[1] * f[1];
        p = [p[0] + w * sub.0.arm[0], p[1] + w * sub.0.arm[1]];
        sizes += f[0] * f[0] + f[1] * f[1];
    }
    let norm = total[0] * total[0] + total[1] * total[1];
    (norm > 1e-12 * sizes).then(|| [p[0] / norm, p[1] / norm])
}

fn candidates_with<L: Law>(
    s: &StepState,
    law: &L,
    (list, ids, max_overlap, record): (&NeighbourList, &[u32], f64, bool),
    out: &mut CandidateResults,
) {
    let n = list.pairs.len();
    out.kicks.resize(n, Kick::default());
    out.history.resize(n, 0.0);
    out.contacts.clear();
    // The first diverging candidate by pair of ids (the same whatever the memory order
    // and whichever thread finds it).
    let first = AtomicU64::new(u64::MAX);
    let watch = Watch {
        particles: s.particles,
        ids,
        max_overlap,
        first: &first,
    };
    let settle = |k: usize, r: Option<(ContactForce, f64)>, kick: &mut Kick, h: &mut f64| {
        settle(&watch, list.pairs[k], r, kick, h)
    };
    let evaluate = |k: usize, kick: &mut Kick, h: &mut f64| {
        let hint = list.hints.get(k);
        let (r, hint) = candidate_force_hinted(s, law, list.pairs[k], list.history[k], hint);
        list.hints.set(k, hint);
        settle(k, r, kick, h)
    };
    if record {
        out.contacts.resize(n, None);
        let mut kh: Vec<(Kick, f64)> = vec![(Kick::default(), 0.0); n];
        crate::parallel::for_each2(&mut out.contacts, &mut kh, |k, c, (kick, h)| {
            *c = evaluate(k, kick, h);
        });
        for (k, (kick, h)) in kh.into_iter().enumerate() {
            out.kicks[k] = kick;
            out.history[k] = h;
        }
    } else if !L::AREA {
        let block = |k0: usize, kicks: &mut [Kick], h: &mut [f64]| {
            let pairs = &list.pairs[k0..k0 + kicks.len()];
            let mut geometry = [None; DISK_BLOCK];
            for (g, &pair) in geometry.iter_mut().zip(pairs) {
                *g = disk_candidate(s, law, pair);
            }
            for (m, (kick, h)) in kicks.iter_mut().zip(h).enumerate() {
                let k = k0 + m;
                let r =
                    geometry[m].map(|g| disk_candidate_force(s, law, pairs[m], list.history[k], g));
                settle(k, r, kick, h);
            }
        };
        crate::parallel::for_each_block2(&mut out.kicks, &mut out.history, DISK_BLOCK, block);
    } else {
        // As the disks' blocks: first every candidate's overlap in the block, then the
        // law for those that touch, so that one candidate's long chain of dependent
        // steps (crossings, a square root, divisions, then the law's) overlaps the
        // next's. Each candidate's arithmetic is unchanged.
        let block = |k0: usize, kicks: &mut [Kick], h: &mut [f64]| {
            let pairs = &list.pairs[k0..k0 + kicks.len()];
            let mut geometry = [None; AREA_BLOCK];
            for (m, (g, &pair)) in geometry.iter_mut().zip(pairs).enumerate() {
                let (c, hint) = area_candidate(s, law, pair, list.hints.get(k0 + m));
                list.hints.set(k0 + m, hint);
                *g = c;
            }
            for (m, (kick, h)) in kicks.iter_mut().zip(h).enumerate() {
                let k = k0 + m;
                let r = geometry[m].map(|c| {
                    let (g, input) = area_kinematics(s, pairs[m], list.history[k], c);
                    contact_force(s.particles, |c| law.evaluate(c), pairs[m], &g, &input)
                });
                settle(k, r, kick, h);
            }
        };
        crate::parallel::for_each_block2(&mut out.kicks, &mut out.history, AREA_BLOCK, block);
    }
    let key = first.into_inner();
    out.diverging = (key != u64::MAX).then(|| {
        let k = (list.pairs.iter())
            .position(|&p| pair_key(id_pair(p, ids)) == key)
            .expect("the diverging pair is a candidate");
        let c = candidate_force(s, law, list.pairs[k], list.history[k]);
        (k, c.expect("a diverging candidate is a contact").0)
    });
}

/// What `settle` needs to watch for a diverging contact.
struct Watch<'a> {
    particles: &'a Particles,
    ids: &'a [u32],
    max_overlap: f64,
    /// The smallest key (by ids) of a diverging pair so far.
    first: &'a AtomicU64,
}

/// One candidate's result into its kick and history slot (0 when not in contact); a
/// diverging contact is noted. Returns the contact.
#[inline(always)]
fn settle(
    w: &Watch,
    pair: Pair,
    r: Option<(ContactForce, f64)>,
    kick: &mut Kick,
    h: &mut f64,
) -> Option<ContactForce> {
    match r {
        Some((c, v)) => {
            if diverges(w.particles, pair, &c, w.max_overlap) {
                note_diverging(w.first, pair, w.ids);
            }
            *kick = Kick {
                force: c.force,
                torque: c.torque,
                contact: true,
            };
            *h = v;
            Some(c)
        }
        None => {
            kick.contact = false;
            *h = 0.0;
            None
        }
    }
}

/// Keeps the smaller of `first` and this diverging pair's key (by ids). Out of line:
/// it is rare, and the candidate loop stays small enough to be inlined whole.
#[cold]
#[inline(never)]
fn note_diverging(first: &AtomicU64, pair: Pair, ids: &[u32]) {
    first.fetch_min(pair_key(id_pair(pair, ids)), Ordering::Relaxed);
}

/// r_i − r_j: the offset of the pair, the only way positions enter a contact's geometry
/// (issue 18).
#[inline]
pub fn offset(particles: &Particles, i: usize, j: usize) -> [f64; 2] {
    let (pi, pj) = (particles.position(i), particles.position(j));
    [pi[0] - pj[0], pi[1] - pj[1]]
}

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
fn disk_geometry(s: &StepState, pair: Pair) -> (Geometry, Option<[f64; 2]>) {
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
fn disk_kinematics(
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
        _ => ([0.0, 0.0], 0.0),
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
fn material_pair(s: &StepState, pair: Pair, m12: f64) -> (f64, u32) {
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

/// Velocity of particle j's material at the contact point (zero for a wall), and its
/// mass. The point is `arm` from r_i, so `arm + d` from r_j (d = r_i − r_j).
#[inline(always)]
fn material_velocity(
    s: &StepState,
    pair: Pair,
    arm: [f64; 2],
    d: Option<[f64; 2]>,
) -> ([f64; 2], f64) {
    let (false, Some(d)) = (pair.is_wall(), d) else {
        return ([0.0, 0.0], f64::INFINITY);
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
fn area_kinematics(
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

/// Stage: total contact force and torque (fx, fz, τ) on every particle from the
/// candidates' results, each particle on its own (in parallel): first the contacts in
/// which it is the higher id (by increasing partner id), then its own (by increasing
/// partner, walls last). That is the order in which `reduce_forces` adds them, so the
/// sums are bitwise the same, whatever the thread count.
pub fn reduce_candidate_forces(
    particles: &Particles,
    list: &NeighbourList,
    kicks: &[Kick],
    out: &mut Vec<Dof>,
) {
    out.clear();
    out.resize(particles.len(), [0.0; 3]);
    crate::parallel::for_each(out, |p, acc| *acc = kick_sum(list, kicks, p));
}

/// The total contact force and torque on particle p: its candidates as the higher id
/// (−F, in increasing partner id), then as the lower id (+F, in increasing partner id,
/// walls last). The integrators call it for each particle they move, so that the sum
/// and the update are one pass.
#[inline(always)]
pub fn kick_sum(list: &NeighbourList, kicks: &[Kick], p: usize) -> Dof {
    let mut acc = [0.0; 3];
    let down = &list.down[list.down_start[p] as usize..list.down_start[p + 1] as usize];
    for &k in down {
        let c = &kicks[k as usize];
        if c.contact {
            acc[0] -= c.force[0];
            acc[1] -= c.force[1];
            acc[2] -= c.torque[1];
        }
    }
    let own = &kicks[list.start[p] as usize..list.start[p + 1] as usize];
    for c in own.iter().filter(|c| c.contact) {
        acc[0] += c.force[0];
        acc[1] += c.force[1];
        acc[2] += c.torque[0];
    }
    acc
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
        let acc = &mut out[i];
        acc[0] += c.force[0];
        acc[1] += c.force[1];
        acc[2] += c.torque[0];
        if !pair.is_wall() {
            let acc = &mut out[pair.j as usize];
            acc[0] -= c.force[0];
            acc[1] -= c.force[1];
            acc[2] -= c.torque[1];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::ContactOutput;

    fn sub(n: [f64; 2], arm: [f64; 2], f_n: f64, f_t: f64) -> (SubContact, ContactOutput) {
        let c = SubContact {
            key: 0,
            delta: 0.0,
            n,
            arm,
        };
        let r = ContactOutput {
            f_n,
            f_t,
            history: 0.0,
            energy: 0.0,
            lever: 0.0,
        };
        (c, r)
    }

    /// Σ_k f_k ⊗ l_k, and F ⊗ l at the reported arm (F the total force).
    fn moments(subs: &[(SubContact, ContactOutput)]) -> ([[f64; 2]; 2], [[f64; 2]; 2]) {
        let mut m = [[0.0; 2]; 2];
        let mut total = [0.0; 2];
        for (c, r) in subs {
            let t = tangent(c.n);
            let f = [r.f_n * c.n[0] + r.f_t * t[0], r.f_n * c.n[1] + r.f_t * t[1]];
            for a in 0..2 {
                total[a] += f[a];
                for b in 0..2 {
                    m[a][b] += f[a] * c.arm[b];
                }
            }
        }
        let l = centre_of_forces(subs).unwrap();
        let reported = [
            [total[0] * l[0], total[0] * l[1]],
            [total[1] * l[0], total[1] * l[1]],
        ];
        (m, reported)
    }

    #[test]
    fn a_pairs_reported_point_keeps_its_stress_exact_or_bounded() {
        let norm = |m: [[f64; 2]; 2]| m.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
        // Rods side by side without friction: one normal, the forces parallel, and one
        // pushing while the other pulls (cohesion): F ⊗ l is exactly Σ f_k ⊗ l_k.
        let n = [0.0, 1.0];
        let (m, got) = moments(&[
            sub(n, [-2.0, -0.5], 3.0, 0.0),
            sub(n, [1.5, -0.5], -1.0, 0.0),
        ]);
        for (a, b) in m.iter().flatten().zip(got.iter().flatten()) {
            assert!((a - b).abs() < 1e-12 * norm(m), "{m:?} against {got:?}");
        }
        // Pushing and pulling nearly equally, with friction: the normal forces' own
        // centre would lie 10³ arms away and carry the tangential force there; F ⊗ l is
        // now never larger than the sum it stands for.
        let subs = [
            sub(n, [-2.0, -0.5], 1.0 + 1e-3, 0.4),
            sub(n, [1.5, -0.5], -1.0, 0.3),
        ];
        let (m, got) = moments(&subs);
        assert!(
            norm(got) <= norm(m) * (1.0 + 1e-12),
            "{got:?} against {m:?}"
        );
    }
}
