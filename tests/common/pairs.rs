//! Random contact configurations of every pair of shapes, at rest, each pair on a site
//! of its own (issues 18 and 19): polygon–polygon (corner first and face to face,
//! regular and ellipse-inscribed, 3–16 corners), polygon–disk (either as i), polygon–
//! wall and disk–wall (axis-aligned and inclined walls), disk–disk. Each pair is pushed
//! together from touching by a gap drawn log-uniformly from `GAPS` (in d ≈ 1).
//!
//! Positions and wall ends lie on a grid of 2⁻³⁶ and sites on whole numbers, so a
//! translation by a whole number below 2¹⁶ is exact in f64: a translated set is the same
//! configuration, number for number, and any difference in its contacts is the code's.

use serde_json::{Value, json};
use talus::base::geometry::WallSegment;
use talus::base::rng::Rng;
use talus::overlap::{polygon_disk, polygon_polygon};
use talus::shape::{P2, circumradius, ellipse_polygon, rotate};
use talus::sim::Simulation;
use talus::state::{NewParticle, Particles};

/// Penetrations from touching, log-uniform between these (in d).
pub const GAPS: [f64; 2] = [1e-7, 0.2];

/// Distance between sites.
const SPACING: f64 = 6.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    PolygonPolygon,
    /// The polygon is particle i.
    PolygonDisk,
    /// The disk is particle i.
    DiskPolygon,
    PolygonWall,
    DiskDisk,
    DiskWall,
}

impl Kind {
    pub const AREA_LAW: [Kind; 6] = [
        Kind::PolygonPolygon,
        Kind::PolygonDisk,
        Kind::DiskPolygon,
        Kind::PolygonWall,
        Kind::DiskDisk,
        Kind::DiskWall,
    ];
    pub const DISK_LAWS: [Kind; 2] = [Kind::DiskDisk, Kind::DiskWall];

    pub fn name(self) -> &'static str {
        match self {
            Kind::PolygonPolygon => "polygon-polygon",
            Kind::PolygonDisk => "polygon-disk",
            Kind::DiskPolygon => "disk-polygon",
            Kind::PolygonWall => "polygon-wall",
            Kind::DiskDisk => "disk-disk",
            Kind::DiskWall => "disk-wall",
        }
    }
}

/// One configuration: its first particle (i; j = i + 1 unless it meets a wall).
#[derive(Clone, Copy, Debug)]
pub struct Config {
    pub kind: Kind,
    pub i: usize,
    /// Face to face (or a face on the wall, a disk on a face) rather than corner first.
    pub face: bool,
    /// An inclined wall (not along an axis).
    pub inclined: bool,
    /// The gap from touching, in d.
    pub gap: f64,
}

/// A set of configurations laid out from the origin.
#[derive(Clone, Debug)]
pub struct PairSet {
    pub law: Value,
    pub particles: Particles,
    pub walls: Vec<WallSegment>,
    pub configs: Vec<Config>,
    /// The extent of the sites: [0, size] in x and z.
    pub size: f64,
}

fn snap(x: f64) -> f64 {
    let g = (36f64).exp2();
    (x * g).round() / g
}

fn unit(angle: f64) -> P2 {
    [angle.cos(), angle.sin()]
}

fn shape(rng: &mut Rng) -> Vec<P2> {
    let corners = 3 + (rng.next_u64() % 14) as u32;
    let a = rng.range(0.8, 1.2);
    let b = if rng.uniform() < 0.5 {
        a
    } else {
        a * rng.range(0.5, 1.0)
    };
    ellipse_polygon(corners, a, b, rng.range(0.0, std::f64::consts::TAU))
}

/// A particle's body corners and radius: a random polygon and its circumradius, or a
/// disk (no corners) of diameter 0.8–1.2.
fn body(rng: &mut Rng, polygon: bool) -> (Vec<P2>, f64) {
    if polygon {
        let v = shape(rng);
        let r = circumradius(&v);
        (v, r)
    } else {
        (Vec::new(), rng.range(0.4, 0.6))
    }
}

/// The outward normal of edge k of corners v (counter-clockwise).
fn edge_normal(v: &[P2], k: usize) -> P2 {
    let (a, b) = (v[k], v[(k + 1) % v.len()]);
    let e = [b[0] - a[0], b[1] - a[1]];
    let l = e[0].hypot(e[1]);
    [e[1] / l, -e[0] / l]
}

fn angle_of(v: P2) -> f64 {
    v[1].atan2(v[0])
}

/// The largest s in [0, hi] at which `touch(s)` still holds (touch(0) must).
fn touching(hi: f64, touch: impl Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (0.0, hi);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if touch(mid) { lo = mid } else { hi = mid }
    }
    lo
}

fn new_particle(position: P2, theta: f64, corners: Vec<P2>, radius: f64) -> NewParticle {
    NewParticle {
        position,
        theta,
        velocity: [0.0; 2],
        omega: 0.0,
        radius,
        fixed: false,
        fixed_rotation: false,
        material: 0,
        corners,
        sweep: 0.0,
    }
}

/// `n` configurations of the given kinds (in turn), from `seed`.
pub fn pair_set(law: Value, kinds: &[Kind], n: usize, seed: u64) -> PairSet {
    let mut rng = Rng::new(seed);
    let cols = (n as f64).sqrt().ceil() as usize;
    let mut particles = Particles::default();
    let mut walls = Vec::new();
    let mut configs = Vec::new();
    let add = |p: &mut Particles, d: NewParticle| p.push_particle(&d, 1.0, 1.0, 1e-5) as usize;
    for k in 0..n {
        let kind = kinds[k % kinds.len()];
        let site = [
            SPACING * (k % cols) as f64 + 2.0,
            SPACING * (k / cols) as f64 + 2.0,
        ];
        let gap = 10f64.powf(rng.range(GAPS[0].log10(), GAPS[1].log10()));
        let face = rng.uniform() < 0.5;
        let mut inclined = false;
        let i = particles.len();
        let polygon_i = matches!(
            kind,
            Kind::PolygonPolygon | Kind::PolygonDisk | Kind::PolygonWall
        );
        let (body_i, radius_i) = body(&mut rng, polygon_i);
        let mut theta_i = rng.range(-3.2, 3.2);
        let mut rot_i = Vec::new();
        rotate(&body_i, theta_i, &mut rot_i);
        match kind {
            Kind::PolygonWall | Kind::DiskWall => {
                inclined = rng.uniform() < 0.5;
                // m: the wall's normal towards the particle.
                let m = if inclined {
                    unit(rng.range(-3.2, 3.2))
                } else {
                    [[0.0, 1.0], [0.0, -1.0], [1.0, 0.0], [-1.0, 0.0]]
                        [(rng.next_u64() % 4) as usize]
                };
                if polygon_i && face {
                    // A face down on the wall: its outward normal along −m.
                    let e = (rng.next_u64() as usize) % body_i.len();
                    theta_i += angle_of([-m[0], -m[1]]) - angle_of(edge_normal(&rot_i, e));
                    rotate(&body_i, theta_i, &mut rot_i);
                }
                // The wall's line touches at the particle's farthest point along −m.
                let reach = if polygon_i {
                    rot_i
                        .iter()
                        .map(|v| -(v[0] * m[0] + v[1] * m[1]))
                        .fold(f64::MIN, f64::max)
                } else {
                    radius_i
                };
                let s = reach - gap;
                let t = [-m[1], m[0]];
                let along = rng.range(-0.3, 0.3);
                let half = 0.5 * rng.range(1.6, 3.0);
                let c = [
                    site[0] - s * m[0] + along * t[0],
                    site[1] - s * m[1] + along * t[1],
                ];
                walls.push(WallSegment {
                    a: [snap(c[0] - half * t[0]), snap(c[1] - half * t[1])],
                    b: [snap(c[0] + half * t[0]), snap(c[1] + half * t[1])],
                });
                add(
                    &mut particles,
                    new_particle(site, theta_i, body_i, radius_i),
                );
            }
            _ => {
                let polygon_j = matches!(kind, Kind::PolygonPolygon | Kind::DiskPolygon);
                let (body_j, radius_j) = body(&mut rng, polygon_j);
                let mut theta_j = rng.range(-3.2, 3.2);
                // u: from i towards j.
                let mut u = unit(rng.range(-3.2, 3.2));
                if face && polygon_i {
                    u = edge_normal(&rot_i, (rng.next_u64() as usize) % rot_i.len());
                }
                let mut rot_j = Vec::new();
                rotate(&body_j, theta_j, &mut rot_j);
                if face && polygon_j {
                    let f = (rng.next_u64() as usize) % rot_j.len();
                    if !polygon_i {
                        u = [-edge_normal(&rot_j, f)[0], -edge_normal(&rot_j, f)[1]];
                    } else {
                        // j's face f turned to face i's: its outward normal along −u.
                        theta_j += angle_of([-u[0], -u[1]]) - angle_of(edge_normal(&rot_j, f));
                        rotate(&body_j, theta_j, &mut rot_j);
                    }
                }
                let t = [-u[1], u[0]];
                let lateral = if face { rng.range(-0.25, 0.25) } else { 0.0 };
                // d = r_i − r_j for j at s along u.
                let d_at = |s: f64| [-(s * u[0] + lateral * t[0]), -(s * u[1] + lateral * t[1])];
                let touch = |s: f64| {
                    let d = d_at(s);
                    match kind {
                        Kind::PolygonPolygon => polygon_polygon(&rot_i, &rot_j, d).is_some(),
                        Kind::PolygonDisk => polygon_disk(&rot_i, d, radius_j, true).is_some(),
                        Kind::DiskPolygon => {
                            polygon_disk(&rot_j, [-d[0], -d[1]], radius_i, false).is_some()
                        }
                        _ => d[0].hypot(d[1]) < radius_i + radius_j,
                    }
                };
                let s = touching(3.0, touch) - gap;
                let d = d_at(s);
                let pj = [site[0] - snap(d[0]), site[1] - snap(d[1])];
                add(
                    &mut particles,
                    new_particle(site, theta_i, body_i, radius_i),
                );
                add(&mut particles, new_particle(pj, theta_j, body_j, radius_j));
            }
        }
        configs.push(Config {
            kind,
            i,
            face,
            inclined,
            gap,
        });
    }
    let size = SPACING * cols as f64;
    PairSet {
        law,
        particles,
        walls,
        configs,
        size,
    }
}

/// `n` particles resting on one long wall, `length` d long and inclined by `angle`
/// (radians): polygons (face down or corner first, under the overlap-area law) and disks
/// in turn, from either end
/// towards the middle (0.6 d from the ends, then 2 d apart and growing geometrically),
/// each pushed into it by a gap drawn from `GAPS`.
pub fn along_a_long_wall(law: Value, length: f64, angle: f64, n: usize, seed: u64) -> PairSet {
    let mut rng = Rng::new(seed);
    let t = unit(angle);
    let m = [-t[1], t[0]];
    let a = [1.0, 1.0 + length * (-angle.sin()).max(0.0)];
    let b = [snap(a[0] + length * t[0]), snap(a[1] + length * t[1])];
    let wall = WallSegment { a, b };
    let mut particles = Particles::default();
    let mut configs = Vec::new();
    for k in 0..n {
        // From either end in turn, 2 d apart and then farther apart, up to the middle.
        let j = (k / 2) as f64;
        let along = (0.6 + 2.0 * j + 0.3 * 1.3f64.powf(j)).min(0.5 * length - 2.0 - j);
        let s = if k % 2 == 0 { along } else { length - along };
        let gap = 10f64.powf(rng.range(GAPS[0].log10(), GAPS[1].log10()));
        let polygons = law["law"] == "overlap_area";
        let kind = if k % 3 == 2 || !polygons {
            Kind::DiskWall
        } else {
            Kind::PolygonWall
        };
        let face = k % 3 == 0;
        let (body, radius) = body(&mut rng, kind == Kind::PolygonWall);
        let mut theta = rng.range(-3.2, 3.2);
        let mut rot = Vec::new();
        rotate(&body, theta, &mut rot);
        if face && !body.is_empty() {
            let e = (rng.next_u64() as usize) % body.len();
            theta += angle_of([-m[0], -m[1]]) - angle_of(edge_normal(&rot, e));
            rotate(&body, theta, &mut rot);
        }
        let reach = if body.is_empty() {
            radius
        } else {
            rot.iter()
                .map(|v| -(v[0] * m[0] + v[1] * m[1]))
                .fold(f64::MIN, f64::max)
        };
        let c = [
            snap(a[0] + s * t[0] + (reach - gap) * m[0]),
            snap(a[1] + s * t[1] + (reach - gap) * m[1]),
        ];
        let i = particles.push_particle(&new_particle(c, theta, body, radius), 1.0, 1.0, 1e-5);
        configs.push(Config {
            kind,
            i: i as usize,
            face,
            inclined: true,
            gap,
        });
    }
    let size = (a[0].max(b[0]) + 2.0).max(a[1].max(b[1]) + 2.0);
    PairSet {
        law,
        particles,
        walls: vec![wall],
        configs,
        size,
    }
}

impl PairSet {
    /// The set translated by t (both coordinates), as a simulation whose contacts are
    /// evaluated.
    pub fn at(&self, t: [f64; 2]) -> Simulation {
        let walls: Vec<Value> = self
            .walls
            .iter()
            .map(|w| {
                json!({ "from": [w.a[0] + t[0], w.a[1] + t[1]], "to": [w.b[0] + t[0], w.b[1] + t[1]] })
            })
            .collect();
        // A scene needs a creation block; its particle is not made here (the state is
        // ours, `from_parts`), it only sizes the time-step check.
        let block = json!([{ "kind": "list", "material": "m",
                             "particles": [{ "position": [t[0], t[1]], "diameter": 1.0 }] }]);
        let mut v = super::scene_value(self.law.clone(), block);
        v["dt"] = json!(1e-5);
        v["domain"] = json!({ "x": [t[0] - 2.0, t[0] + self.size + 2.0],
                              "z": [t[1] - 2.0, t[1] + self.size + 2.0] });
        v["walls"] = json!(walls);
        // Gaps up to 0.2 d are deep for small disks; the GPU's divergence check must not
        // halt the kernels.
        v["limits"] = json!({ "max_overlap": 10.0 });
        let mut p = self.particles.clone();
        for q in &mut p.q[0] {
            q[0] += t[0];
            q[1] += t[1];
        }
        let scene = super::parse(&v);
        let mut sim =
            Simulation::from_parts(scene, p, Default::default(), Vec::new(), Rng::new(1), 0, 0)
                .expect("the pair set builds");
        sim.evaluate_contacts();
        sim
    }

    /// The same set with every particle moved by up to `size` in each coordinate, off the
    /// grid: its translations round, particle by particle.
    pub fn jittered(&self, size: f64, seed: u64) -> PairSet {
        let mut rng = Rng::new(seed);
        let mut out = self.clone();
        for q in &mut out.particles.q[0] {
            q[0] += rng.range(-size, size);
            q[1] += rng.range(-size, size);
        }
        out
    }

    /// The configuration a contact belongs to.
    pub fn config_of(&self, i: u32) -> &Config {
        let k = self.configs.partition_point(|c| c.i <= i as usize) - 1;
        &self.configs[k]
    }
}
