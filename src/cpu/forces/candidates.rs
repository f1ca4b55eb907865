//! Stage `candidate_forces`: every candidate of the neighbour list evaluated on its own
//! (touching or not), in blocks on every thread, into its kick and history slot.

use super::divergence::diverges;
use super::kinematics::area_contact_hinted;
use super::kinematics::{area_kinematics, disk_geometry, disk_kinematics};
use super::rods::spheropolygon_candidates;
use super::{ContactForce, StepState, contact_force};
use crate::base::geometry::Geometry;
use crate::cpu::contacts::Pair;
use crate::cpu::neighbours::{NeighbourList, id_pair};
use crate::cpu::springs::{ROLLING_KEY, SubSprings, pair_key};
use crate::law::{ContactLaw, Law};
use crate::overlap::{AreaContact, Hint, polygon_polygon_hinted};
use crate::state::Particles;
use crate::state::offset;
use std::sync::atomic::{AtomicU64, Ordering};

/// One candidate of the neighbour list: its contact force and updated history if the
/// pair touches (the test of `contacts::find_contacts`, with the geometry computed once:
/// the disks' for the disk laws, the overlap for polygons), None if it does not.
/// `rolling`: its rolling spring before the step (rolling model `spring_dashpot`).
#[inline(always)]
pub fn candidate_force<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    history: f64,
    rolling: f64,
) -> Option<(ContactForce, f64)> {
    candidate_force_hinted(s, law, pair, history, rolling, Hint::NONE).0
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
    rolling: f64,
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
    let r = contact_force(s, |c| law.evaluate(c), pair, &g, &input, rolling);
    (Some(r), hint)
}

/// A disk law's first half of `candidate_force`: the geometry of a candidate, None when
/// it does not touch.
#[inline(always)]
pub(super) fn disk_candidate<L: Law>(
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
pub(super) fn disk_candidate_force<L: Law>(
    s: &StepState,
    law: &L,
    pair: Pair,
    history: f64,
    rolling: f64,
    (g, d): (Geometry, Option<[f64; 2]>),
) -> (ContactForce, f64) {
    let (g, input) = disk_kinematics(s, pair, history, g, d);
    contact_force(s, |c| law.evaluate(c), pair, &g, &input, rolling)
}

/// Candidates of a disk law evaluated per block, each half for the whole block at once.
/// Alone, one candidate is a long chain of dependent steps (a square root, a division,
/// the law) that the processor cannot overlap with the next; the first half of several
/// candidates side by side keeps it busy. Each candidate's arithmetic is unchanged.
pub(super) const DISK_BLOCK: usize = 16;

/// Candidates of the overlap-area law evaluated per block (`candidates_with`), as
/// [`DISK_BLOCK`].
pub(super) const AREA_BLOCK: usize = 16;

/// The overlap-area law's first half of `candidate_force_hinted`: the overlap of a
/// candidate that touches (zero area for disks whose circles touch), None when it does
/// not, and the pair's hint for the next step.
#[inline(always)]
pub(super) fn area_candidate<L: Law>(
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
    if !crate::cpu::contacts::circles_touch(s.particles, s.walls, law.range_factor(), pair) {
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

pub(super) fn candidates_with<L: Law>(
    s: &StepState,
    law: &L,
    (list, ids, max_overlap, record): (&NeighbourList, &[u32], f64, bool),
    out: &mut CandidateResults,
) {
    let n = list.pairs.len();
    out.kicks.resize(n, Kick::default());
    out.history.resize(n, 0.0);
    out.contacts.clear();
    // Each candidate's rolling spring before the step (model `spring_dashpot`), kept
    // among its `SubSprings`; 0 for all in a list that has none yet.
    let springs = s.rolling.has_spring();
    let rolling = |k: usize| match list.sub_history.get(k) {
        Some(sub) if springs && list.sub_history.len() == n => sub.get(ROLLING_KEY),
        _ => 0.0,
    };
    if !springs {
        out.sub_history.clear();
    }
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
        let (r, hint) =
            candidate_force_hinted(s, law, list.pairs[k], list.history[k], rolling(k), hint);
        list.hints.set(k, hint);
        settle(k, r, kick, h)
    };
    if springs {
        // Rolling springs: each candidate's contact kept whole, for its spring (a
        // scene with them takes this plainer loop, recording or not).
        let mut contacts: Vec<Option<ContactForce>> = vec![None; n];
        let mut kh: Vec<(Kick, f64)> = vec![(Kick::default(), 0.0); n];
        crate::base::parallel::for_each2(&mut contacts, &mut kh, |k, c, (kick, h)| {
            *c = evaluate(k, kick, h);
        });
        out.sub_history.clear();
        for (k, ((kick, h), c)) in kh.into_iter().zip(&contacts).enumerate() {
            out.kicks[k] = kick;
            out.history[k] = h;
            out.sub_history
                .push(c.map_or_else(SubSprings::default, |c| SubSprings::rolling(c.rolling)));
        }
        if record {
            out.contacts = contacts;
        }
    } else if record {
        out.contacts.resize(n, None);
        let mut kh: Vec<(Kick, f64)> = vec![(Kick::default(), 0.0); n];
        crate::base::parallel::for_each2(&mut out.contacts, &mut kh, |k, c, (kick, h)| {
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
                let r = geometry[m]
                    .map(|g| disk_candidate_force(s, law, pairs[m], list.history[k], 0.0, g));
                settle(k, r, kick, h);
            }
        };
        crate::base::parallel::for_each_block2(&mut out.kicks, &mut out.history, DISK_BLOCK, block);
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
                    contact_force(s, |c| law.evaluate(c), pairs[m], &g, &input, 0.0)
                });
                settle(k, r, kick, h);
            }
        };
        crate::base::parallel::for_each_block2(&mut out.kicks, &mut out.history, AREA_BLOCK, block);
    }
    let key = first.into_inner();
    out.diverging = (key != u64::MAX).then(|| {
        let k = (list.pairs.iter())
            .position(|&p| pair_key(id_pair(p, ids)) == key)
            .expect("the diverging pair is a candidate");
        let c = candidate_force(s, law, list.pairs[k], list.history[k], rolling(k));
        (k, c.expect("a diverging candidate is a contact").0)
    });
}

/// What `settle` needs to watch for a diverging contact.
pub(super) struct Watch<'a> {
    pub(super) particles: &'a Particles,
    pub(super) ids: &'a [u32],
    pub(super) max_overlap: f64,
    /// The smallest key (by ids) of a diverging pair so far.
    pub(super) first: &'a AtomicU64,
}

/// One candidate's result into its kick and history slot (0 when not in contact); a
/// diverging contact is noted. Returns the contact.
#[inline(always)]
pub(super) fn settle(
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
            // Zero force and torque: the reduction adds every candidate's kick without a
            // branch (adding +0 to a sum that starts at +0 changes no bit).
            *kick = Kick::default();
            *h = 0.0;
            None
        }
    }
}

/// Keeps the smaller of `first` and this diverging pair's key (by ids). Out of line:
/// it is rare, and the candidate loop stays small enough to be inlined whole.
#[cold]
#[inline(never)]
pub(super) fn note_diverging(first: &AtomicU64, pair: Pair, ids: &[u32]) {
    first.fetch_min(pair_key(id_pair(pair, ids)), Ordering::Relaxed);
}
