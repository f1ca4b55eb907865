//! The GPU's contacts against the CPU path's, anywhere in the domain and down to tiny
//! overlaps (issues 18 and 19): the random configurations of tests/common/pairs.rs,
//! every shape pair, at the origin and translated to 10², 10³ and 10⁴ d, one contact
//! stage on each path. And GPU snapshots carry the device's own contact geometry.
//!
//! The GPU keeps positions in fixed point and polygon corners in whole position units
//! (unit = cell/2³⁰ ≈ 1.2e-9 d here) turned by Q31 sin and cos (2e-9 rad): its shapes
//! differ from the CPU's f64 shapes by up to Q ≈ 3e-9 d. An area contact's force
//! changes with the shape by up to k^n (L/l) Q (its area by L Q), which is the absolute
//! floor of the comparison; above it, forces agree to 1e-3 relative and normals to
//! 1e-4 rad. For a corner-first contact the floor is below 1e-3 of the force from
//! A ≈ 1e-10 D² up; for face-to-face contacts from A/l ≈ 5e-6 d up (README,
//! "Precision").

mod common;

use common::pairs::{Config, Kind, PairSet, along_a_long_wall, pair_set};
use serde_json::json;
use std::collections::BTreeMap;
use talus::cpu::forces::area_contact;
use talus::gpu::GpuSimulation;
use talus::gpu::modules::Kernel;
use talus::sim::Simulation;

const K_N: f64 = 1e7;
/// How far the GPU's polygon corners may lie from the CPU's (see above), in d: a body
/// corner rounded to whole units (0.7 unit), rotated and rounded again (0.7 unit), with
/// sin and cos right to 2e-9 (at 0.7 d, 1.4e-9 d); a unit is 1.2e-9 d here.
const SHAPE: f64 = 3.1e-9;
/// A position unit (cell/2³⁰) in d: disks' radii and positions are exact to a unit.
const UNIT: f64 = 1.2e-9;
/// Every contact at least this deep (gap from touching, in d) is found on both paths.
const FOUND_FROM: f64 = 1e-6;

fn area_law() -> serde_json::Value {
    json!({ "law": "overlap_area", "k_n": K_N, "eta_n": 0.5, "mu": 0.5 })
}

fn spring_dashpot() -> serde_json::Value {
    json!({ "law": "spring_dashpot", "k_n": K_N, "gamma_n": 10.0, "k_t": 2e6, "gamma_t": 1.0, "mu": 0.5 })
}

/// One contact stage on the GPU, downloaded into the host mirror.
fn gpu_contacts(test: &str, sim: Simulation) -> Option<Simulation> {
    let gpu = common::gpu(test)?;
    let mut g = GpuSimulation::with_gpu(sim, gpu).expect("uploads");
    let mut ks = GpuSimulation::CELL_LIST.to_vec();
    ks.extend([
        Kernel::FindContacts,
        Kernel::GatherHistory,
        Kernel::ContactForces,
    ]);
    g.run_kernels(&ks);
    Some(g.download().clone())
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

/// Bands of the overlap area A (D² = d² here; disk laws: of the overlap δ in d),
/// largest first.
const BANDS: [(f64, &str); 5] = [
    (1e-4, ">= 1e-4"),
    (1e-6, "1e-6..1e-4"),
    (1e-8, "1e-8..1e-6"),
    (1e-9, "1e-9..1e-8"),
    (0.0, "< 1e-9"),
];

#[derive(Default, Debug)]
struct Band {
    contacts: usize,
    /// Largest relative force difference, normal angle (rad), and overlap difference
    /// |Δf|/k^n (for the area law |Δ(A/l)|, in d).
    force: f64,
    angle: f64,
    overlap: f64,
}

/// Compares the GPU's contacts in `gpu` with the CPU's in `cpu`; returns the number of
/// configurations the GPU missed (all shallower than FOUND_FROM) and fills the bands.
fn compare(
    name: &str,
    set: &PairSet,
    cpu: &Simulation,
    gpu: &Simulation,
    area_law: bool,
    bands: &mut BTreeMap<(Kind, &'static str, usize), Band>,
    worst: &mut f64,
) -> usize {
    let found: BTreeMap<_, _> = gpu.pairs.iter().zip(&gpu.contacts).collect();
    let mut missed = 0;
    for (p, c) in cpu.pairs.iter().zip(&cpu.contacts) {
        let config: &Config = set.config_of(p.i);
        let Some(g) = found.get(p) else {
            assert!(
                config.gap < FOUND_FROM,
                "{name}: the GPU misses {} {p:?} {} d deep",
                config.kind.name(),
                config.gap
            );
            missed += 1;
            continue;
        };
        // The GPU snapshot's geometry is the device's own (issue 19): a unit normal.
        assert!(
            (norm(g.n) - 1.0).abs() < 1e-5,
            "{name}: {} {p:?} (gap {:.1e}) has normal {:?} in the GPU's contacts",
            config.kind.name(),
            config.gap,
            g.n
        );
        let f = norm(c.force);
        let err = norm([g.force[0] - c.force[0], g.force[1] - c.force[1]]);
        // The floor: the shapes' difference, SHAPE for each polygon of the pair (whole
        // units for disks' radii and positions).
        let polygons = match config.kind {
            Kind::PolygonPolygon => 2.0,
            Kind::PolygonDisk | Kind::DiskPolygon | Kind::PolygonWall => 1.0,
            Kind::DiskDisk | Kind::DiskWall => 0.0,
        };
        let (area, floor) = if area_law {
            let a = area_contact(&cpu.particles, &cpu.corners, &cpu.walls, *p).unwrap();
            (a.area, K_N * a.chord / a.l * (polygons * SHAPE + UNIT))
        } else {
            (f64::INFINITY, K_N * UNIT)
        };
        let angle = (c.n[0] * g.n[1] - c.n[1] * g.n[0]).atan2(c.n[0] * g.n[0] + c.n[1] * g.n[1]);
        let bound = 1e-3 * f + floor;
        assert!(
            err <= bound,
            "{name}: {} {p:?} (gap {:.1e} d, A {area:.1e}, face {}, inclined {}): GPU force {:?}, CPU {:?}",
            config.kind.name(),
            config.gap,
            config.face,
            config.inclined,
            g.force,
            c.force
        );
        *worst = worst.max(err / bound);
        // Normals to 1e-4 rad wherever the shapes' difference is small against the
        // chord (from A ~ 1e-9 D² corner first; face to face the faces fix it).
        if area >= 1e-9 {
            assert!(
                angle.abs() < 1e-4,
                "{name}: {} {p:?} (A {area:.1e}): normals {:?} and {:?} differ by {angle:.1e} rad",
                config.kind.name(),
                g.n,
                c.n
            );
        }
        let size = if area_law { area } else { c.overlap };
        let band = BANDS.iter().position(|b| size >= b.0).unwrap();
        let shape = if config.face { "face" } else { "corner" };
        let b = bands.entry((config.kind, shape, band)).or_default();
        b.contacts += 1;
        b.force = b.force.max(err / f);
        b.angle = b.angle.max(angle.abs());
        b.overlap = b.overlap.max(err / K_N);
    }
    missed
}

#[test]
fn gpu_contacts_agree_with_the_cpu_anywhere_in_the_domain() {
    let sets = [
        (
            "area law",
            pair_set(area_law(), &Kind::AREA_LAW, 1200, 18),
            true,
        ),
        (
            "spring-dashpot",
            pair_set(spring_dashpot(), &Kind::DISK_LAWS, 400, 19),
            false,
        ),
    ];
    for (name, set, area) in sets {
        let mut bands = BTreeMap::new();
        let mut worst = 0.0f64;
        for t in [0.0, 1e2, 1e3, 1e4] {
            let cpu = set.at([t, t]);
            assert_eq!(
                cpu.pairs.len(),
                set.configs.len(),
                "{name}: one contact each"
            );
            let Some(gpu) = gpu_contacts("gpu_contacts_agree_with_the_cpu", cpu.clone()) else {
                return;
            };
            // No contact the CPU does not have.
            for p in &gpu.pairs {
                assert!(cpu.pairs.contains(p), "{name} at {t}: the GPU finds {p:?}");
            }
            let missed = compare(name, &set, &cpu, &gpu, area, &mut bands, &mut worst);
            eprintln!(
                "{name} at x = z = {t:e}: {} contacts, {missed} shallower than {FOUND_FROM:e} d missed",
                cpu.pairs.len()
            );
        }
        eprintln!("{name}: the largest difference is {worst:.2} of the bound");
        for ((kind, shape, band), b) in &bands {
            eprintln!(
                "{name}: {:>15} {shape:>6} {} {:>10}: {:4} contacts, force to {:.1e}, overlap to {:.1e} d, normal to {:.1e} rad",
                kind.name(),
                if area { "A" } else { "δ" },
                BANDS[*band].1,
                b.contacts,
                b.force,
                b.overlap,
                b.angle
            );
        }
    }
}

#[test]
fn long_inclined_walls_are_exact_all_along() {
    // Issue 18: the GPU's inclined walls kept f32 precision relative to their first end
    // point (6e-8 of the distance along them; 6e-5 d at 1000 d). Now a wall's distance
    // is exact in integers (geometry.wgsl `wall_line`): polygons and disks resting on a
    // wall 1500 d long, level, at 25° and at -35° (and disks under the spring-dashpot law
    // at 25°), from 0.6 d to 750 d from either end, with gaps of 1e-7..0.2 d, at the
    // origin and at 10⁴ d, agree with the CPU as in the test above.
    let walls = [
        (0.0, area_law()),
        (25f64.to_radians(), area_law()),
        ((-35f64).to_radians(), area_law()),
        (25f64.to_radians(), spring_dashpot()),
    ];
    for (k, (angle, law)) in walls.into_iter().enumerate() {
        let area = law["law"] == "overlap_area";
        let set = along_a_long_wall(law, 1500.0, angle, 60, 40 + k as u64);
        let mut bands = BTreeMap::new();
        let mut worst = 0.0f64;
        for t in [0.0, 1e4] {
            let cpu = set.at([t, t]);
            assert_eq!(
                cpu.pairs.len(),
                set.configs.len(),
                "every particle touches the wall"
            );
            let Some(gpu) = gpu_contacts("long_inclined_walls_are_exact_all_along", cpu.clone())
            else {
                return;
            };
            assert_eq!(gpu.pairs, cpu.pairs, "the same contacts at {t}");
            compare("long wall", &set, &cpu, &gpu, area, &mut bands, &mut worst);
        }
        eprintln!(
            "a wall at {:.0}° ({}): the largest difference is {worst:.2} of the bound",
            angle.to_degrees(),
            if area { "area law" } else { "spring-dashpot" }
        );
    }
}

#[test]
fn gpu_snapshots_hold_the_devices_contacts() {
    // Issue 19: the snapshot of a GPU run held normals and force points recomputed on the
    // host, (0, 0) where the host found no overlap. Now they come from the device: a
    // snapshot written from the GPU state and read back has a unit normal for every
    // contact, and its force points are the CPU path's to 1e-6 d.
    let set = pair_set(area_law(), &Kind::AREA_LAW, 300, 7);
    let cpu = set.at([1e4, 1e4]);
    let Some(gpu) = gpu_contacts("gpu_snapshots_hold_the_devices_contacts", cpu.clone()) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("talus-gpu-snapshot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = talus::io::snapshot::write(&gpu, &dir, "gpu").expect("snapshot written");
    let snap = talus::io::snapshot::read(&path).expect("snapshot read");
    let col = |k: &str| snap.f64(k).unwrap().to_vec();
    let (nx, nz, px, pz) = (
        col("contacts.nx"),
        col("contacts.nz"),
        col("contacts.px"),
        col("contacts.pz"),
    );
    assert_eq!(
        nx.len(),
        gpu.pairs.len(),
        "every device contact is in the snapshot"
    );
    let cpu_at: BTreeMap<_, _> = cpu.pairs.iter().zip(&cpu.contacts).collect();
    for (k, p) in gpu.pairs.iter().enumerate() {
        if (nx[k].hypot(nz[k]) - 1.0).abs() >= 1e-5 {
            eprintln!(
                "DEBUG {:?} {:?} cpu {:?}",
                set.config_of(p.i),
                gpu.contacts[k],
                cpu_at[p]
            );
        }
        assert!(
            (nx[k].hypot(nz[k]) - 1.0).abs() < 1e-5,
            "contact {p:?} has normal ({}, {}) in the snapshot",
            nx[k],
            nz[k]
        );
        let c = cpu_at[p];
        let d = (px[k] - c.point[0]).hypot(pz[k] - c.point[1]);
        assert!(
            d < 1e-6,
            "contact {p:?}: force point {d:.1e} d from the CPU's"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
