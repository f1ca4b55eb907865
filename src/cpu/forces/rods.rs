//! The candidates of a spheropolygon scene (paper 004, SPEC 2.4): each pair the sum of
//! its vertex–edge sub-contacts, reported as one contact.

use super::candidates::{CandidateResults, Kick};
use super::candidates::{Watch, settle};
use super::{ContactForce, StepState};
use crate::base::geometry::{tangent, wall_from};
use crate::cpu::contacts::{Pair, WALL_BASE};
use crate::cpu::neighbours::{NeighbourList, id_pair};
use crate::cpu::springs::pair_key;
use crate::cpu::springs::{MAX_SUB, SubSprings};
use crate::law::hertz_cohesive::HertzCohesive;
use crate::overlap::spheropolygon::{SubContact, SubList, sub_contacts};
use crate::shape::P2;
use crate::shape::spheropolygon::{cross, dot, sub};
use crate::state::offset;
use std::sync::atomic::AtomicU64;

/// The candidates of a spheropolygon scene (law hertz_cohesive, SPEC 2.4): each pair's
/// force is the sum over its sub-contacts (`spheropolygon::pair_force`), each with its
/// spring from the list's slot (`NeighbourList::sub_history`). A disk is a point core
/// swept by its radius; a wall a segment of sweep 0. When recording, a pair is reported
/// as one contact: its total force, at the point whose Σ f ⊗ l is nearest its
/// sub-contacts' (`centre_of_forces`), with its deepest sub-contact's normal and overlap.
pub(super) fn spheropolygon_candidates(
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
    crate::base::parallel::for_each2(&mut out.kicks, &mut out.sub_history, |k, kick, sub| {
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
pub(super) fn spheropolygon_candidate(
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
        let v = super::kinematics::wall_velocity(s, pair);
        let motion = (s.velocity[i], [v[0], v[1], 0.0]);
        crate::cpu::forces::rods::pair_force(
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
        crate::cpu::forces::rods::pair_force(
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
        // Rods take no rolling resistance (scene::validate).
        rolling: 0.0,
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
pub(super) fn centre_of_forces(
    subs: &[(SubContact, crate::law::ContactOutput)],
) -> Option<[f64; 2]> {
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

/// What a pair of spheropolygons does to its particles this step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairForce {
    /// The total force on i (on j: its opposite).
    pub force: P2,
    /// Torques on i and on j.
    pub torque: [f64; 2],
    /// The updated springs of the sub-contacts in range.
    pub springs: SubSprings,
    /// Each sub-contact in range with its law's output (forces along n and t).
    pub contacts: smallvec::SmallVec<[(SubContact, crate::law::ContactOutput); 4]>,
}

/// The motion of one body: velocity (x, z) and angular velocity.
pub type Motion = [f64; 3];

/// The force between spheropolygons i and j (`p`, `q`: their turned cores and sweep
/// radii; `d` = r_i − r_j; `m12` the reduced mass, the mass of i against a wall, and
/// `mass` the contact's mass scale for the cohesion, `ContactInput::mass`) under
/// paper 004's law, each sub-contact with its own spring from `springs` (SPEC 2.4). A
/// wall is a spheropolygon of sweep radius 0 that does not move.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn pair_force(
    law: &crate::law::hertz_cohesive::HertzCohesive,
    p: (&[P2], f64),
    q: (&[P2], f64),
    d: P2,
    (vi, vj): (Motion, Motion),
    (m12, mass): (f64, f64),
    springs: &SubSprings,
    dt: f64,
) -> PairForce {
    let mut subs = SubList::new();
    sub_contacts(p, q, d, law.d_c, &mut subs);
    // The deepest first: they keep their springs when there are more than MAX_SUB.
    subs.sort_by(|a, b| b.delta.total_cmp(&a.delta).then(a.key.cmp(&b.key)));
    let mut out = PairForce::default();
    for (k, &c) in subs.iter().enumerate() {
        // The contact point relative to each centre, and the velocity of each surface there.
        let (li, lj) = (c.arm, [c.arm[0] + d[0], c.arm[1] + d[1]]);
        let ui = [vi[0] - vi[2] * li[1], vi[1] + vi[2] * li[0]];
        let uj = [vj[0] - vj[2] * lj[1], vj[1] + vj[2] * lj[0]];
        let v12 = sub(ui, uj);
        let t = [-c.n[1], c.n[0]];
        let history = if k < MAX_SUB { springs.get(c.key) } else { 0.0 };
        let input = crate::law::ContactInput {
            delta: c.delta,
            delta_dot: -dot(v12, c.n),
            v_t: dot(v12, t),
            m12,
            mass,
            history,
            dt,
            ..Default::default()
        };
        let r = law.evaluate(&input);
        let f = [r.f_n * c.n[0] + r.f_t * t[0], r.f_n * c.n[1] + r.f_t * t[1]];
        out.force = [out.force[0] + f[0], out.force[1] + f[1]];
        out.torque[0] += cross(li, f);
        out.torque[1] -= cross(lj, f);
        if k < MAX_SUB {
            out.springs.push(c.key, r.history);
        }
        out.contacts.push((c, r));
    }
    out
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

    use crate::base::rng::Rng;
    use crate::law::hertz_cohesive::HertzCohesive;
    use crate::overlap::spheropolygon::VERTICES;
    use crate::shape::spheropolygon::Spheropolygon;
    use std::f64::consts::PI;

    #[test]
    fn a_rod_lying_on_a_floor_carries_its_weight_on_two_points() {
        // A rod of mass m on its flat side on a floor (a wall: a segment of sweep 0) at
        // the overlap where each end carries half its weight, k δ^{3/2} = m g / 2.
        let (m, g) = (0.785, 10.0);
        let law = HertzCohesive::paper(g, 0.0, 0.5, 1.0);
        let rod = Spheropolygon::rod(5.0, 1.0);
        let delta = (0.5 * m * g / law.k_n).powf(2.0 / 3.0);
        // The floor's segment relative to the rod's centre: d = r_rod − r_floor with the
        // floor's "centre" at its middle, 0.5 − δ below the rod's axis.
        let floor = [[-10.0, 0.0], [10.0, 0.0]];
        let d = [0.0, 0.5 - delta];
        let f = pair_force(
            &law,
            (&rod.core, 0.5),
            (&floor, 0.0),
            d,
            ([0.0; 3], [0.0; 3]),
            (m, m),
            &SubSprings::default(),
            5e-6,
        );
        assert_eq!(f.contacts.len(), 2);
        assert!((f.force[1] - m * g).abs() < 1e-12 * m * g, "{:?}", f.force);
        assert!(f.force[0].abs() < 1e-15 && f.torque[0].abs() < 1e-12);
        // On its tip (standing upright): one point carries it all.
        let upright = Spheropolygon {
            core: vec![[0.0, -2.0], [0.0, 2.0]],
            radius: 0.5,
        };
        let delta = (m * g / law.k_n).powf(2.0 / 3.0);
        let d = [0.0, 2.5 - delta];
        let f = pair_force(
            &law,
            (&upright.core, 0.5),
            (&floor, 0.0),
            d,
            ([0.0; 3], [0.0; 3]),
            (m, m),
            &SubSprings::default(),
            5e-6,
        );
        assert_eq!(f.contacts.len(), 1);
        assert!((f.force[1] - m * g).abs() < 1e-12 * m * g);
    }

    #[test]
    fn swapping_the_rods_gives_equal_and_opposite_forces() {
        let law = HertzCohesive::paper(10.0, 1e3, 0.4, 1.0);
        let mut rng = Rng::new(3);
        let mut touching = 0;
        for _ in 0..300 {
            let (s, t) = (
                Spheropolygon::random(&mut rng),
                Spheropolygon::random(&mut rng),
            );
            let reach = s.circumradius() + t.circumradius();
            let angle = rng.uniform() * 2.0 * PI;
            let dist = reach * (0.4 + 0.7 * rng.uniform());
            let d = [dist * angle.cos(), dist * angle.sin()];
            let vi = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let vj = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let none = SubSprings::default();
            let a = pair_force(
                &law,
                (&s.core, s.radius),
                (&t.core, t.radius),
                d,
                (vi, vj),
                (0.5, 1.0),
                &none,
                1e-3,
            );
            let b = pair_force(
                &law,
                (&t.core, t.radius),
                (&s.core, s.radius),
                [-d[0], -d[1]],
                (vj, vi),
                (0.5, 1.0),
                &none,
                1e-3,
            );
            let scale = 1.0 + a.force[0].abs() + a.force[1].abs();
            assert!(
                (a.force[0] + b.force[0]).abs() < 1e-9 * scale
                    && (a.force[1] + b.force[1]).abs() < 1e-9 * scale
            );
            assert!((a.torque[0] - b.torque[1]).abs() < 1e-9 * scale * reach);
            assert!((a.torque[1] - b.torque[0]).abs() < 1e-9 * scale * reach);
            touching += usize::from(!a.contacts.is_empty());
        }
        assert!(touching > 30, "only {touching} pairs in range");
    }

    #[test]
    fn each_sub_contact_keeps_its_own_spring_while_it_lasts() {
        // Rod i slides along rod j below it (parallel, overlapping by 0.001): both
        // sub-contacts' springs grow by v_t dt each step, and when i's end passes j's
        // end the sub-contact there is gone with its spring; a new one starts at 0.
        // No damping and no cap: the springs follow the kinematics alone.
        let law = HertzCohesive {
            mu: 1e6,
            gamma_n: 0.0,
            gamma_t: 0.0,
            ..HertzCohesive::paper(10.0, 0.0, 0.5, 1.0)
        };
        let rod = Spheropolygon::rod(3.0, 1.0);
        let dt = 1e-3;
        let v = 2.0;
        let mut springs = SubSprings::default();
        let mut x = -1.0;
        let mut seen_keys = Vec::new();
        // From x = −1 to 2.5: i's core [x − 1, x + 1] passes over j's [−1, 1].
        for step in 0..1750 {
            let d = [x, 0.999];
            let f = pair_force(
                &law,
                (&rod.core, 0.5),
                (&rod.core, 0.5),
                d,
                ([v, 0.0, 0.0], [0.0; 3]),
                (0.5, 1.0),
                &springs,
                dt,
            );
            for (c, r) in &f.contacts {
                let old = springs.get(c.key);
                let fresh = !(0..springs.count).any(|k| springs.key[k] == c.key);
                // t = (−n_z, n_x): v_t = −v n_z (−v where j lies straight below).
                let step_xi = -v * c.n[1] * dt;
                let expected = match (c.delta > 0.0, fresh) {
                    // In the cohesive range but not touching: no spring.
                    (false, _) => 0.0,
                    (true, true) => step_xi,
                    (true, false) => old + step_xi,
                };
                assert!(
                    (r.history - expected).abs() < 1e-12,
                    "step {step}, key {:x}: {} against {expected}, {c:?}, {r:?}, x = {x}",
                    c.key,
                    r.history
                );
                if !seen_keys.contains(&c.key) {
                    seen_keys.push(c.key);
                }
            }
            springs = f.springs;
            x += v * dt;
        }
        // i passed over j and beyond its right end: each end over the other's side
        // (vertex–edge), and the pairs of ends as they lined up (left ends, right ends,
        // i's left on j's right).
        seen_keys.sort();
        let ends = [0x0, 0x100, 0x10000, 0x10100];
        let lined_up = [VERTICES, VERTICES | 0x1, VERTICES | 0x101];
        assert_eq!(
            seen_keys,
            [&ends[..], &lined_up[..]].concat(),
            "{seen_keys:x?}"
        );
    }
}
