//! Single WGSL functions against their Rust twins on random inputs (issue 14 item 7),
//! through `common::wgsl::run_wgsl_fn`: the contact laws of laws.wgsl (f32) against
//! src/law/ (f64, fed the same f32-rounded inputs), and the pair hash bit for bit.

mod common;

use common::wgsl::{COMMON, LAWS, floats, run_wgsl_fn, word};
use serde_json::json;
use talus::base::rng::Rng;
use talus::gpu::layout::{Params, hash_pair};
use talus::law::{ContactInput, ContactLaw};

/// The law of a contact block (gravity 1, so that the continuous laws' force scale m g
/// is the mass).
fn law(contact: serde_json::Value) -> ContactLaw {
    let mut v = common::scene_value(
        contact,
        json!([{ "kind": "list", "material": "m", "particles": [
            { "position": [0.0, 0.0], "diameter": 1.0 }
        ]}]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    common::sim(&v).law
}

/// Random contact inputs, rounded to f32 as the device holds them: overlaps up to 5 %
/// of σ = 1 (for the disk laws at centre distance r = σ − δ, exactly so in f32, as the
/// kernels' geometry gives them; `tail`: also separations up to 2 % of σ, the
/// continuous laws' range), rates and tangential velocities of ±1, springs of ±10⁻³.
/// `area`: the overlap-area law's δ = A/l and depth A/L.
/// `slots`: how many slots the law's pair table has (1 without one: the kernels then
/// always pass slot 0).
fn inputs(n: usize, area: bool, tail: bool, slots: u32, seed: u64) -> Vec<ContactInput> {
    let mut rng = Rng::new(seed);
    let f = |x: f64| x as f32 as f64;
    (0..n)
        .map(|_| {
            let lowest = if tail { -0.02 } else { 1e-6 };
            let r = f(1.0 - rng.range(lowest, 0.05));
            let m12 = rng.range(0.2, 1.0);
            ContactInput {
                // 1 − r is exact in f32 for r near 1 (Sterbenz).
                delta: if area {
                    f(rng.range(0.0, 0.05))
                } else {
                    1.0 - r
                },
                r: if area { f(rng.range(0.0, 0.05)) } else { r },
                sigma: if area { 0.0 } else { 1.0 },
                delta_dot: f(rng.range(-1.0, 1.0)),
                v_t: f(rng.range(-1.0, 1.0)),
                m12: f(m12),
                mass: f(2.0 * m12),
                history: f(rng.range(-1e-3, 1e-3)),
                dt: f(1e-4),
                m_eff: f(rng.range(0.2, 1.0)),
                pair: (rng.range(0.0, slots as f64) as u32).min(slots - 1),
                v_centres: f(rng.range(-1.0, 1.0)),
                spin: f(rng.range(-2.0, 2.0)),
            }
        })
        .collect()
}

#[test]
fn wgsl_laws_match_their_rust_twins() {
    let laws = [
        (
            "linear spring-dashpot",
            json!({ "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 5.0, "k_t": 500.0, "gamma_t": 1.0, "mu": 0.5 }),
            1e-5,
        ),
        (
            "material form, a pair of its own",
            json!({ "law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.05,
                    "gamma_t_ratio": 0.3, "mu": 0.5,
                    "pairs": [{ "materials": ["m", "walls"], "restitution": 0.4, "mu": 0.8 }] }),
            1e-5,
        ),
        (
            "overlap area, material form",
            json!({ "law": "overlap_area", "restitution": 0.5, "contact_time": 0.05, "mu": 0.5,
                    "pairs": [{ "materials": ["m", "walls"], "restitution": 0.3 }] }),
            1e-5,
        ),
        (
            "Hertz-like, clamped",
            json!({ "law": "spring_dashpot", "k_n": 2000.0, "nu": 1.5, "psi": 0.5, "delta0": 0.01,
                    "gamma_n": 5.0, "k_t": 500.0, "gamma_t": 1.0, "mu": 0.4, "clamp": true }),
            1e-5,
        ),
        (
            "overlap area",
            json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 }),
            1e-5,
        ),
        // (σ/r)^(n+1) carries n + 1 times the f32 rounding of σ/r.
        (
            "continuous, n = 36",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5 }),
            5e-5,
        ),
        (
            "Hooke-equivalent",
            json!({ "law": "hooke_equivalent", "n": 36.0, "r0": 1.2, "mu": 0.5 }),
            1e-5,
        ),
        // Paper 001's readings (issue 39): each switch away from the text.
        (
            "continuous, clamped",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5, "clamp": true }),
            5e-5,
        ),
        (
            "continuous, slip damped",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5,
                    "tangential_damping": "slip" }),
            5e-5,
        ),
        (
            "continuous, spins on their own arms",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5,
                    "rolling_arm": "contact_point" }),
            5e-5,
        ),
        (
            "continuous, δ_F accumulated beyond δ_max",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5,
                    "tangential_limit": "accumulate" }),
            5e-5,
        ),
        (
            "continuous, δ_F capped by sliding only",
            json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5,
                    "tangential_limit": "slide" }),
            5e-5,
        ),
        (
            "Hooke-equivalent, as talus read it before issue 39",
            json!({ "law": "hooke_equivalent", "n": 36.0, "r0": 1.2, "mu": 0.5, "clamp": true,
                    "tangential_damping": "slip", "rolling_arm": "contact_point" }),
            1e-5,
        ),
    ];
    for (name, contact, tol) in laws {
        let law = law(contact);
        let area = matches!(law, ContactLaw::OverlapArea(_));
        let mut params = Params::default();
        talus::gpu::law_params(&law, &mut params);
        let tail = matches!(law, ContactLaw::Continuous(_));
        let slots = talus::gpu::gpu_pair_side(&law).unwrap().pow(2) as u32;
        let cases = inputs(4096, area, tail, slots, 11);
        let words: Vec<[u32; 4]> = (cases.iter())
            .flat_map(|c| {
                [
                    word([c.delta, c.r, c.sigma, c.delta_dot]),
                    word([c.v_t, c.m12, c.mass, c.history]),
                    {
                        let mut w = word([c.dt, c.m_eff, 0.0, c.v_centres]);
                        w[2] = c.pair;
                        w
                    },
                    word([c.spin, 0.0, 0.0, 0.0]),
                ]
            })
            .collect();
        let body = "
    let a = bitcast<vec4<f32>>(wgsl_arg(k, 0u));
    let b = bitcast<vec4<f32>>(wgsl_arg(k, 1u));
    let c = bitcast<vec4<f32>>(wgsl_arg(k, 2u));
    let d = bitcast<vec4<f32>>(wgsl_arg(k, 3u));
    let r = evaluate(ContactInput(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, c.y,
                                  bitcast<u32>(c.z), c.w, d.x));
    wgsl_put(k, 0u, bitcast<vec4<u32>>(vec4<f32>(r.f_n, r.f_t, r.history, r.energy)));
    wgsl_put(k, 1u, bitcast<vec4<u32>>(vec4<f32>(r.lever, 0.0, 0.0, 0.0)));";
        let Some(out) = run_wgsl_fn(name, &[COMMON, LAWS], &params, (4, 2), body, &words) else {
            return;
        };
        // The torques' lever (paper 001 eq. 13): r in f32, or 0 for the contact point.
        for (k, (c, w)) in cases.iter().zip(out.chunks(2)).enumerate() {
            let (cpu, gpu) = (law.evaluate(c).lever, f32::from_bits(w[1][0]) as f64);
            assert!(
                (gpu - cpu).abs() <= 1e-6 * cpu,
                "{name}: case {k}: lever CPU {cpu}, GPU {gpu}"
            );
        }
        let out: Vec<[u32; 4]> = out.into_iter().step_by(2).collect();
        let cpu: Vec<[f64; 4]> = (cases.iter())
            .map(|c| {
                let r = law.evaluate(c);
                [r.f_n, r.f_t, r.history, r.energy]
            })
            .collect();
        let gpu: Vec<[f64; 4]> = out.into_iter().map(floats).collect();
        // Each output to `tol` of itself, with a floor of 10⁻⁶ of its largest value over
        // the cases (about 16 f32 roundings: where terms cancel, as the tangential
        // spring and its damping do, the result keeps the rounding of the terms).
        let scale: Vec<f64> = (0..4)
            .map(|q| cpu.iter().map(|v| v[q].abs()).fold(0.0, f64::max))
            .collect();
        assert!(scale[0] > 0.0 && scale[1] > 0.0, "{name}: forces");
        let mut off_boundary = 0;
        for (k, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
            let close = (0..4).all(|q| (g[q] - c[q]).abs() <= tol * c[q].abs() + 1e-6 * scale[q]);
            if close {
                continue;
            }
            // f32 and f64 may take different sides of the Coulomb cap (stick or slip)
            // only where the trial force is at the cap: then |f_t| = μ f_n on both.
            let mu = law.mu();
            let at_cap = |v: &[f64; 4]| (v[1].abs() - mu * v[0].abs()).abs() <= 1e-3 * scale[1];
            if !(at_cap(c) && at_cap(g)) {
                off_boundary += 1;
                if off_boundary <= 5 {
                    eprintln!("{name}: case {k} {:?}: CPU {c:?}, GPU {g:?}", cases[k]);
                }
            }
        }
        assert_eq!(
            off_boundary,
            0,
            "{name}: {off_boundary} of {} cases differ beyond {tol:e}",
            cases.len()
        );
    }
}

#[test]
fn wgsl_pair_hash_is_its_rust_twin_bit_for_bit() {
    // The spring table's slots are found by this hash on the host (checkpoints, tests)
    // and on the device (store_history, gather_history).
    let mut rng = Rng::new(5);
    let pairs: Vec<[u32; 4]> = (0..8192)
        .map(|k| {
            let i = (rng.uniform() * 4_294_967_296.0) as u32;
            let j = if k % 3 == 0 {
                // A wall's code.
                0xFFFF_0000 | (k as u32 & 0xFF)
            } else {
                (rng.uniform() * 4_294_967_296.0) as u32
            };
            [i, j, 0, 0]
        })
        .collect();
    let body = "
    let a = wgsl_arg(k, 0u);
    wgsl_put(k, 0u, vec4<u32>(hash_pair(a.x, a.y), 0u, 0u, 0u));";
    let Some(out) = run_wgsl_fn(
        "wgsl_pair_hash_is_its_rust_twin",
        &[COMMON],
        &Params::default(),
        (1, 1),
        body,
        &pairs,
    ) else {
        return;
    };
    for (p, o) in pairs.iter().zip(&out) {
        assert_eq!(o[0], hash_pair(p[0], p[1]), "hash of ({}, {})", p[0], p[1]);
    }
}
