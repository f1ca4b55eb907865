//! The runs of each reproduction (R1–R9, SPEC 6): the built-in scene files, the
//! overrides that make each variant, and the analysis sizes (`Variant`).

use super::{ReproductionError, Size, Variant};
use std::f64::consts::PI;

/// Height of a lattice row, √3/2 d: window rows this high hold one row of a lattice pile.
const LATTICE_ROW: f64 = 0.8660254037844386;
const R1: &str = include_str!("../../scenes/r1_pile.json");
const R1_REDUCED: &str = include_str!("../../scenes/r1_pile_reduced.json");
const R4: &str = include_str!("../../scenes/r4_pour.json");
const R4_REDUCED: &str = include_str!("../../scenes/r4_pour_reduced.json");
const R6: &str = include_str!("../../scenes/r6_heap.json");
const R6_REDUCED: &str = include_str!("../../scenes/r6_heap_reduced.json");
const R7_MONO: &str = include_str!("../../scenes/r7_wedge_mono.json");
const R7_MEDIUM: &str = include_str!("../../scenes/r7_wedge_medium.json");
const R7_POLY: &str = include_str!("../../scenes/r7_wedge_poly.json");
const R7_LAYERED: &str = include_str!("../../scenes/r7_layered_medium.json");
const R8: &str = include_str!("../../scenes/r8_polygon_pile.json");
/// Grains per second of the R7 wedge sources (one every 0.075 s, as in R6).
const R7_RATE: f64 = 40.0 / 3.0;
const R8_REDUCED: &str = include_str!("../../scenes/r8_polygon_pile_reduced.json");
const R8_LAYERED: &str = include_str!("../../scenes/r8_polygon_pile_layered.json");
const R8_LAYERED_REDUCED: &str = include_str!("../../scenes/r8_polygon_pile_layered_reduced.json");
const R9_REDUCED: &str = include_str!("../../scenes/r9_rods_reduced.json");

fn v(name: &str, scene: &'static str, overrides: &[&str], window: f64, row: f64) -> Variant {
    Variant {
        name: name.into(),
        scene,
        overrides: overrides.iter().map(|s| s.to_string()).collect(),
        window,
        row,
    }
}

/// The runs of reproduction `id` (R1–R9).
pub fn variants(id: &str, size: Size) -> Result<Vec<Variant>, ReproductionError> {
    match size {
        Size::Rods(_) if id != "R9" => return Err(ReproductionError::NotRods(id.into())),
        Size::Rods(n) if n < 10 => return Err(ReproductionError::TooFewRods(n)),
        _ => {}
    }
    let full = size != Size::Reduced;
    let r7 = |name: &str, scene: &'static str| v(name, scene, &[], 14.0, 2.0);
    // The layered heap without an outline that sets its slope (issue 40): rows laid
    // under a 60° outline, far steeper than the grains stand, and stopped after `rows`
    // rows (about the paper's 3400 grains at full width), so that the flanks take the
    // slope the gently dropped grains hold.
    let r7_layered_free = |rows: u32| {
        let mut x = r7("layered-free", R7_LAYERED);
        x.overrides = vec![
            "particles[0].slope=60".into(),
            format!("particles[0].rows={rows}"),
            "stop.time=100".into(),
        ];
        x
    };
    let lattice = |name: &str, set: Vec<String>| {
        let mut x = v(
            name,
            if full { R1 } else { R1_REDUCED },
            &[],
            if full { 14.0 } else { 6.0 },
            LATTICE_ROW,
        );
        x.overrides = set;
        x
    };
    Ok(match id {
        // ν = 1 and the Hertz exponent 3/2 (paper 000 eq. 2, Fig. 6), δ0 = d0: the
        // same stress in row 1.
        "R1" => vec![
            lattice("pile", Vec::new()),
            lattice(
                "pile-nu1.5",
                vec!["contact.nu=1.5".into(), "contact.delta0=1.5e-3".into()],
            ),
        ],
        // R2 and R3: the R1 pile (frictionless, fixed bumpy bottom), its bottom row
        // squeezed or stretched by c, or with size disorder r_d over several seeds. The
        // lattice builder starts them without overlaps, as the paper does
        // (src/create/lattice.rs). R2 is the paper's size at once: L1 = 19 mobile disks
        // in row 1, 22 at the bottom. It runs at k_n = 1e5 N/m, where the overlaps
        // under gravity (1–3 µm, measured) are comparable to the squeeze of c = −1/750
        // (|c| d0 = 2 µm) and smaller than that of −1/150: the dip then deepens with |c|
        // as in the paper. At 1e6 and 1e7 N/m both squeezes jam the row fully and give
        // the same dip, 28–29 % (tried).
        "R2" => {
            // The paper's size either way (L1 = 19). The paper gives no stiffness for these
            // piles; --full adds the two squeezes at 10⁶ and 10⁷ N/m beside the 10⁵ N/m
            // of the claim (issue 40 item 4: what the dip owes to δ against |c| d0).
            let mut runs: Vec<(String, f64, &str)> = [
                ("1_15", 1.0 / 15.0),
                ("0", 0.0),
                ("-1_750", -1.0 / 750.0),
                ("-1_150", -1.0 / 150.0),
            ]
            .iter()
            .map(|&(name, c)| (format!("c={name}"), c, "1e5"))
            .collect();
            if full {
                for k_n in ["1e6", "1e7"] {
                    for (name, c) in [("-1_750", -1.0 / 750.0), ("-1_150", -1.0 / 150.0)] {
                        runs.push((format!("c={name}-kn={k_n}"), c, k_n));
                    }
                }
            }
            (runs.iter())
                .map(|(name, c, k_n)| {
                    v(
                        name,
                        R1_REDUCED,
                        &[
                            &format!("particles[0].spacing_c={c}"),
                            "particles[0].bottom_row=22",
                            &format!("contact.k_n={k_n}"),
                        ],
                        6.0,
                        LATTICE_ROW,
                    )
                })
                .collect()
        }
        "R3" => {
            let seeds = if full { 10 } else { 5 };
            // ϱ = r_d k_n/(σ d) = r_d d/δ (paper 000 sec. 4.4): these stiffnesses give
            // the same overlaps in both piles, δ ≈ 5e-4 d on average and 1.5e-3 d at
            // most (measured), so ϱ ≈ 0.5–1 for r_d = 2/3000 and 20–70 for r_d = 1/30:
            // the paper's two regimes. (At R1's 1e7 N/m both are ϱ ≫ 1.)
            let k_n = if full { 3e5 } else { 1e5 };
            let mut out = Vec::new();
            for (name, rd) in [("rd=2_3000", 2.0 / 3000.0), ("rd=1_30", 1.0 / 30.0)] {
                for seed in 1..=seeds {
                    out.push(lattice(
                        &format!("{name}-seed{seed}"),
                        vec![
                            format!("particles[0].size_disorder={rd}"),
                            format!("seed={seed}"),
                            format!("contact.k_n={k_n}"),
                        ],
                    ));
                }
            }
            out
        }
        // The law as paper 001 writes it (the default) integrated as the paper does
        // (leapfrog, eq. 9-12), and as talus ran it before issue 39: clamped, the slip
        // damped, the spins on their own arms, with Gear. (Unclamped, the damping of a
        // 100-sigma impact at its closest approach, C_N dt/m12 = 0.64, made 7 of 8
        // full-size seeds diverge under Gear at dt = 0.001: `scene::stability`.)
        "R4" => {
            let base = if full { R4 } else { R4_REDUCED };
            vec![
                v("pour", base, &[], 14.0, 1.0),
                v(
                    "pour-clamped-slip",
                    base,
                    &[
                        "contact.clamp=true",
                        "contact.tangential_damping=slip",
                        "contact.rolling_arm=contact_point",
                        "integrator=gear5",
                    ],
                    14.0,
                    1.0,
                ),
            ]
        }
        // R5: R4 with the Hooke law of equal work, a short tail, and polydispersity.
        "R5" => {
            let base = if full { R4 } else { R4_REDUCED };
            vec![
                v("continuous-n36", base, &[], 14.0, 1.0),
                // The linear spring of equal work is far softer than n = 36 at the impact
                // speed of a 30σ drop: impacts overlap by more than half a radius.
                v(
                    "hooke",
                    base,
                    &["contact.law=hooke_equivalent", "limits.max_overlap=0.95"],
                    14.0,
                    1.0,
                ),
                // The stiffness paper 001's Fig. 5 states, k = 500 m g/σ, beside the one
                // eq. 14 gives from the continuous run's closest approach (188 m g/σ).
                v(
                    "hooke-k500",
                    base,
                    &[
                        "contact.law=hooke_equivalent",
                        "contact.k=500",
                        "limits.max_overlap=0.95",
                    ],
                    14.0,
                    1.0,
                ),
                // The short tail is four times as steep: a quarter of the step. With R4's
                // long tail (r0 = 1.2σ), and with the short tail r0 = 1.047σ the paper's
                // "M profile lost" is about (Fig. 6a/7a).
                v("n144", base, &["contact.n=144", "dt=0.00025"], 14.0, 1.0),
                v(
                    "n144-short",
                    base,
                    &["contact.n=144", "contact.r0=1.047", "dt=0.00025"],
                    14.0,
                    1.0,
                ),
                // δ % polydispersity: diameters uniform in [(1 − δ) σ, σ] (paper 001
                // sec. II).
                v(
                    "poly5",
                    base,
                    &["particles[1].diameter={\"uniform\":[0.95,1.0]}"],
                    14.0,
                    1.0,
                ),
                v(
                    "poly10",
                    base,
                    &["particles[1].diameter={\"uniform\":[0.9,1.0]}"],
                    14.0,
                    1.0,
                ),
            ]
        }
        "R6" => vec![v(
            "heap",
            if full { R6 } else { R6_REDUCED },
            &[],
            14.0,
            2.0,
        )],
        // R7 reduced: about 30 % of the paper's grains, from the same source. (With
        // 10 % the wedge heaps spread into a layer a few grains high, tried.) Each pour
        // stops 15 s after its last grain, and not before 2 s after it; the layered pile
        // is √0.3 as wide, for 30 % of the grains, and stops once built and settled.
        // Tens of minutes each on a 2-core CPU.
        "R7" if !full => {
            let wedge = |name: &str, scene: &'static str, count: u32| {
                let pour = count as f64 / R7_RATE;
                let mut x = r7(name, scene);
                x.overrides = vec![
                    format!("particles[0].count={count}"),
                    format!("stop.time={}", pour + 15.0),
                    format!("stop.not_before={}", pour + 2.0),
                ];
                x
            };
            let mut layered = r7("layered-medium", R7_LAYERED);
            layered.overrides = vec![
                "particles[0].base_width=0.38".into(),
                "stop.time=100".into(),
            ];
            let mut free = r7_layered_free(22);
            free.overrides.push("particles[0].base_width=0.38".into());
            vec![
                wedge("wedge-mono", R7_MONO, 800),
                wedge("wedge-medium", R7_MEDIUM, 1200),
                wedge("wedge-poly", R7_POLY, 600),
                layered,
                free,
            ]
        }
        "R7" => vec![
            r7("wedge-mono", R7_MONO),
            r7("wedge-medium", R7_MEDIUM),
            r7("wedge-poly", R7_POLY),
            r7("layered-medium", R7_LAYERED),
            r7_layered_free(27),
        ],
        // The pile created whole on its lattice and settled (`mu-…`), and built as paper
        // 000 sec. 5.2 builds it, layer by layer onto the fixed bottom row
        // (`layered-mu-…`: rows of the lattice dropped 0.2 d every 0.05 s, then relaxed),
        // so that friction acts while it is built.
        "R8" => {
            let (whole, layered) = if full {
                (R8, R8_LAYERED)
            } else {
                (R8_REDUCED, R8_LAYERED_REDUCED)
            };
            let mut out = Vec::new();
            for (prefix, scene) in [("", whole), ("layered-", layered)] {
                for mu in ["0", "0.3", "0.6"] {
                    let mut x = v(
                        &format!("{prefix}mu-{mu}"),
                        scene,
                        &[],
                        if full { 14.0 } else { 6.0 },
                        LATTICE_ROW,
                    );
                    x.overrides = vec![format!("contact.mu={mu}")];
                    out.push(x);
                }
            }
            out
        }
        // R9 (paper 004): rods of aspect d poured into a box 20 d wide. Reduced: 300 rods
        // per run, d ∈ {2, 5, 10} at Bo = 0, Bo ∈ {10², 10³, 10⁴} at d = 5, d = 2 at
        // Bo = 10³ and d = 10 at Bo = 10⁴. Full: the
        // paper's 6000 rods, d ∈ {2, 5, 10} × Bo ∈ {0, 10³, 10⁴}; at Bo = 10⁴ the
        // cohesive pull of k^N = 10⁷ would
        // press contacts by a fifth of a width, so those runs take k^N, k^T 100 times
        // stiffer (δ ~ 10⁻² width) and a step 6 times smaller (the contact time goes as
        // k^(−2/5)).
        "R9" => {
            let count = match size {
                Size::Rods(n) => n,
                _ => 6000,
            };
            let rods = |d: f64, bond: f64| {
                let half = 10.0 * d;
                let mut x = v(&format!("d{d}-bo{bond}"), R9_REDUCED, &[], 4.0 * d, 2.0 * d);
                // The box's height and the source: above the deposit the run can build
                // (`count` rods of area (d − 1) + π/4 at a packing fraction of ~0.7, and
                // with cohesion ~0.25: 1000 rods of d = 10 at Bo = 10⁴ packed at 0.27
                // and, in a box sized for 0.4, stood up to the outlet after 943).
                let (top, source) = if full {
                    let packing = if bond > 0.0 { 0.25 } else { 0.7 };
                    let deposit = count as f64 * (d - 1.0 + 0.25 * PI) / (packing * 2.0 * half);
                    let top = (deposit + 4.0 * d + 20.0).ceil();
                    (top, top - d - 2.0)
                } else {
                    (70.0, 50.0)
                };
                x.overrides = vec![
                    format!("particles[0].rod.aspect={d}"),
                    format!("particles[0].spread={}", half - 0.5 * d - 1.0),
                    format!("particles[0].position=[0,{source}]"),
                    format!("contact.bond={bond}"),
                    format!("domain.x=[{},{}]", -half - 5.0, half + 5.0),
                    format!("domain.z=[-5,{}]", top + 10.0),
                    format!("walls[0].from=[{},0]", -half),
                    format!("walls[0].to=[{half},0]"),
                    format!("walls[1].from=[{},0]", -half),
                    format!("walls[1].to=[{},{top}]", -half),
                    format!("walls[2].from=[{half},0]"),
                    format!("walls[2].to=[{half},{top}]"),
                ];
                if bond >= 1e4 {
                    x.overrides.extend([
                        "contact.k_n=1e9".to_string(),
                        "contact.k_t=1e8".to_string(),
                        "dt=2.5e-5".to_string(),
                    ]);
                }
                if full {
                    // The rods due at 60 a second and thrown down at 50 widths a second;
                    // a rod waits until the outlet is free within its circumscribed
                    // circle, which limits the feed (for d = 10, to ~20 a second). The
                    // paper's 6000 rods get 800 time units; fewer get the time to feed
                    // at 20 a second and 50 more to settle (the cohesive runs do not
                    // reach the kinetic-drop rule: they run to the end).
                    let end = match size {
                        Size::Rods(n) => (n as f64 / 20.0 + 50.0).ceil(),
                        _ => 800.0,
                    };
                    x.overrides.extend([
                        "name=r9_rods".to_string(),
                        format!("particles[0].count={count}"),
                        "particles[0].rate=60".to_string(),
                        "particles[0].velocity=[0,-50]".to_string(),
                        format!("stop.time={end}"),
                        format!("output.snapshot_every={}", (end / 16.0).round()),
                    ]);
                }
                x
            };
            if full {
                let mut all = Vec::new();
                for d in [2.0, 5.0, 10.0] {
                    for bond in [0.0, 1e3, 1e4] {
                        all.push(rods(d, bond));
                    }
                }
                all
            } else {
                vec![
                    rods(2.0, 0.0),
                    rods(5.0, 0.0),
                    rods(10.0, 0.0),
                    rods(5.0, 100.0),
                    rods(5.0, 1000.0),
                    rods(5.0, 1e4),
                    // Paper 004 Fig. 4a (Q(r) of d = 2 with and without cohesion) and
                    // Fig. 5 (principal stress directions of d = 10 at Bo = 0 and 10⁴).
                    rods(2.0, 1000.0),
                    rods(10.0, 1e4),
                ]
            }
        }
        _ => return Err(ReproductionError::Unknown(id.into())),
    })
}
