//! `talus analyze` (SPEC 5): measurements against analytic answers on small static
//! packings, and the command's files and errors.

mod common;
use common::*;
use serde_json::json;
use std::path::{Path, PathBuf};
use talus::analyze::{self, Options};

fn tmp(name: &str) -> PathBuf {
    common::tmp("analyze", name)
}

/// Writes a snapshot of `sim` into `dir` and analyses it.
fn analyse(sim: &talus::sim::Simulation, dir: &Path, g: f64) -> analyze::Analysis {
    analyse_with(sim, dir, g, &Options::default())
}

fn analyse_with(
    sim: &talus::sim::Simulation,
    dir: &Path,
    g: f64,
    opt: &Options,
) -> analyze::Analysis {
    let json = talus::io::snapshot::write(sim, dir, "snap").unwrap();
    let input = analyze::input::load(&json, Some(g)).unwrap();
    analyze::analyze(input, opt).unwrap()
}

const N: usize = 6;

/// A column of N unit disks (m = 1, g = 1) on a floor, settled with strong damping.
fn settled_column() -> talus::sim::Simulation {
    let list: Vec<_> = (0..N)
        .map(|k| json!({ "position": [0.0, 0.5 + k as f64], "diameter": 1.0 }))
        .collect();
    let law = json!({ "law": "spring_dashpot", "k_n": 1e5, "gamma_n": 100.0, "k_t": 1e4, "gamma_t": 10.0, "mu": 0.5 });
    let mut v = scene_value(
        law,
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-5.0, 0.0], "to": [5.0, 0.0] }]);
    let mut s = sim(&v);
    for _ in 0..40_000 {
        s.step().unwrap();
    }
    s
}

#[test]
fn a_resting_column_carries_its_weight_grain_by_grain() {
    // Grain k from the bottom has (N − k) m g pushing up at its bottom and (N − k − 1) m g
    // pushing down at its top, both about r from its centre: Σ f ⊗ l in zz (compression
    // positive) is (2(N − k) − 1) m g r, up to the overlaps (δ/r ~ 1e-4 here).
    let s = settled_column();
    let a = analyse(&s, &tmp("column"), 1.0);
    for k in 0..N {
        let expect = (2 * (N - k) - 1) as f64 * 0.5;
        let m = a.moments[k];
        assert!(
            (m.zz / expect - 1.0).abs() < 2e-3,
            "grain {k}: m_zz = {} against {expect}",
            m.zz
        );
        assert!(
            m.xx.abs() < 1e-6 && m.xz.abs() < 1e-6,
            "grain {k}: no shear or side stress"
        );
    }
    // The virial of the vertical forces: ∫ σ_zz dA = W (z_cm − base).
    let sm = &a.summary;
    assert!(
        (sm.stress_integral_zz / sm.weight_times_height - 1.0).abs() < 2e-3,
        "{} against {}",
        sm.stress_integral_zz,
        sm.weight_times_height
    );
    // Contacts: floor + one above for the lowest, two for the middle ones, one for the
    // top grain, which is the column's only rattler (fewer than 2 with friction).
    let c = &sm.coordination;
    assert!(
        (c.all - (2 * N - 1) as f64 / N as f64).abs() < 1e-12,
        "Z = {}",
        c.all
    );
    assert_eq!(c.rattlers, 1);
    // The force distribution is a probability density with mean 1.
    let bin = a.force_pdf[1].0 - a.force_pdf[0].0;
    let total: f64 = a.force_pdf.iter().map(|p| p.1 * bin).sum();
    let mean: f64 = a.force_pdf.iter().map(|p| p.0 * p.1 * bin).sum();
    assert!((total - 1.0).abs() < 1e-12, "∫P = {total}");
    assert!((mean - 1.0).abs() < 0.05, "mean f/<f> = {mean}");
    // Every grain is compressed vertically: P(φ) has all its weight at φ = π/2.
    let width = a.principal_directions[1].0 - a.principal_directions[0].0;
    let vertical: f64 = a
        .principal_directions
        .iter()
        .filter(|p| (p.0 - std::f64::consts::FRAC_PI_2).abs() < 0.6 * width)
        .map(|p| p.1 * width)
        .sum();
    assert!(
        (vertical - 1.0).abs() < 1e-12,
        "P(φ): {:?}",
        a.principal_directions
    );
}

#[test]
fn the_stress_against_depth_of_a_column_is_hydrostatic() {
    // Grain j/2 below the column's top carries m_zz = j m g (above): a slab five
    // diameters high holds five grains, so its σ_zz is m g × (its centre's depth) / (W ·
    // d), hydrostatic at the packing fraction π/4 of disks stacked in a column one wide:
    // in units of ρ g W, σ = (π/4) x with x the depth in widths.
    let s = settled_column();
    let a = analyse(&s, &tmp("column-depth"), 1.0);
    let o = &a.summary.outline;
    assert!((o.width - 1.0).abs() < 1e-3, "width {}", o.width);
    let p = &a.stress_depth;
    // Slabs wholly in the column of 6, every diameter from the top: centres 2.5 and 3.5
    // deep.
    assert_eq!(p.len(), 2, "{p:?}");
    for (k, (x, sigma)) in p.iter().enumerate() {
        assert!((x - (2.5 + k as f64)).abs() < 2e-3, "{p:?}");
        let expect = 0.25 * std::f64::consts::PI * x;
        assert!(
            (sigma / expect - 1.0).abs() < 2e-3,
            "{sigma} against {expect}"
        );
    }
    // Two slabs are too few for a Janssen fit.
    assert!(a.summary.janssen.is_none());
}

#[test]
fn a_lattice_pile_has_its_slope_and_the_triangular_packing_fraction() {
    // The reduced R1 pile as built: a 30° triangle of touching disks on a triangular
    // lattice, whose packing fraction is π/(2√3) = 0.9069. Layers two rows high, so that
    // each holds whole rows.
    let scene = talus::scene::load(Path::new("scenes/r1_pile_reduced.json"), &[]).unwrap();
    let s = talus::sim::Simulation::new(scene).unwrap();
    let opt = Options {
        layer: 3f64.sqrt(),
        ..Default::default()
    };
    let a = analyse_with(&s, &tmp("lattice"), 9.81, &opt);
    let sm = &a.summary;
    for slope in [&sm.repose_left, &sm.repose_right] {
        assert!(slope.points >= 5, "{} points fitted", slope.points);
        assert!(
            (slope.angle_deg - 30.0).abs() < 1.5,
            "angle {}",
            slope.angle_deg
        );
    }
    let phi = std::f64::consts::PI / (2.0 * 3f64.sqrt());
    assert!(
        (sm.packing_fraction_lower_half / phi - 1.0).abs() < 0.03,
        "packing fraction {} against {phi}",
        sm.packing_fraction_lower_half
    );
}

#[test]
fn aligned_ellipse_polygons_peak_in_f_theta_and_correlate_fully() {
    // 40 heptagons on an ellipse of axes 2 : 1, all turned by 0.6 rad: f(θ) has all its
    // weight in the bin of 0.6, and Q(r) = 1 at every distance.
    let list: Vec<_> = (0..40)
        .map(|k| {
            json!({ "position": [3.0 * (k % 8) as f64, 3.0 * (k / 8) as f64 + 2.0],
                         "theta": 0.6, "diameter": 2.0 })
        })
        .collect();
    let law = json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 });
    let block =
        json!({ "kind": "list", "material": "m", "particles": list, "polygon": { "corners": 7 } });
    let mut s = sim(&scene_value(law, json!([block])));
    // Lists make regular polygons (no long axis): give each the ellipse shape.
    let body = talus::shape::ellipse_polygon(7, 2.0, 1.0, 0.3);
    s.particles.shape.iter_mut().for_each(|c| *c = body.clone());
    let a = analyse(&s, &tmp("aligned"), 1.0);
    assert_eq!(a.summary.oriented_grains, 40);
    let width = std::f64::consts::PI / 18.0;
    let peak = a
        .orientation
        .iter()
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap();
    assert!((peak.0 - 0.6).abs() <= 0.5 * width, "peak at {}", peak.0);
    assert!(
        (peak.1 * width - 1.0).abs() < 1e-12,
        "all weight in one bin"
    );
    assert!(!a.correlation.is_empty());
    assert!(a.correlation.iter().all(|c| (c.1 - 1.0).abs() < 1e-9));
}

#[test]
fn the_command_writes_its_tables_and_rejects_bad_input() {
    let s = settled_column();
    let dir = tmp("command");
    let json = talus::io::snapshot::write(&s, &dir, "snap").unwrap();
    let run = |args: &[&str]| {
        let (code, _, err) = common::talus(args);
        (code, err)
    };
    let out = dir.join("analysis");
    let (code, err) = run(&[
        "analyze",
        json.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--g",
        "1",
    ]);
    assert_eq!(code, 0, "{err}");
    for f in [
        "summary.json",
        "grains.csv",
        "stress.csv",
        "base_profile.csv",
        "surface.csv",
        "force_distribution.csv",
        "packing.csv",
        "orientation.csv",
        "orientation_correlation.csv",
        "principal_directions.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    let header = std::fs::read_to_string(out.join("stress.csv")).unwrap();
    assert!(
        header.starts_with("row,z_lo [sigma],z_hi [sigma],x [sigma]"),
        "units in the header: {}",
        &header[..60]
    );
    let (code, err) = run(&["analyze", "/nonexistent/run"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no such file or folder") && !err.contains("panicked"),
        "{err}"
    );
    let (code, err) = run(&["analyze", json.to_str().unwrap(), "--window=-3"]);
    assert_eq!(code, 2);
    assert!(err.contains("--window"), "{err}");
    // Windows a billionth of a diameter apart would be billions of windows.
    let (code, err) = run(&["analyze", json.to_str().unwrap(), "--step", "1e-9"]);
    assert_eq!(code, 2);
    assert!(err.contains("--step"), "{err}");
}

#[test]
fn damaged_snapshots_are_refused_by_analyze_and_render() {
    // Issue 16: a snapshot whose data do not match its JSON, or hold NaN, is refused with
    // a message (exit 2), neither indexed out of bounds nor drawn.
    let s = settled_column();
    let dir = tmp("damaged");
    let json = talus::io::snapshot::write(&s, &dir, "snap").unwrap();
    assert!(talus::io::snapshot::read(&json).is_ok());
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // As a file from before the checksum (version 1, still read), so that the checks of
    // its contents are what refuses it (tests/snapshots.rs: the checksum).
    meta.as_object_mut().unwrap().remove("checksum");
    meta["version"] = serde_json::json!(1);
    let bin = std::fs::read(dir.join("snap.bin")).unwrap();
    let column = |name: &str| {
        let c = (meta["columns"].as_array().unwrap().iter())
            .find(|c| {
                format!(
                    "{}.{}",
                    c["table"].as_str().unwrap(),
                    c["name"].as_str().unwrap()
                ) == name
            })
            .unwrap()
            .clone();
        c["offset"].as_u64().unwrap() as usize
    };
    let cases: Vec<(&str, serde_json::Value, Vec<u8>, &str)> = vec![
        (
            "nan",
            meta.clone(),
            {
                let mut b = bin.clone();
                let at = column("particles.x") + 8;
                b[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
                b
            },
            "particles.x",
        ),
        (
            "truncated",
            meta.clone(),
            bin[..bin.len() / 2].to_vec(),
            "past the end",
        ),
        (
            "count",
            {
                let mut m = meta.clone();
                m["particles"] = serde_json::json!(meta["particles"].as_u64().unwrap() + 1);
                m
            },
            bin.clone(),
            "holds",
        ),
        (
            "contact",
            meta.clone(),
            {
                let mut b = bin.clone();
                let at = column("contacts.i");
                b[at..at + 4].copy_from_slice(&123_456u32.to_le_bytes());
                b
            },
            "not in the snapshot",
        ),
    ];
    for (name, m, b, must) in cases {
        let d = tmp(&format!("damaged-{name}"));
        std::fs::write(d.join("snap.json"), m.to_string()).unwrap();
        std::fs::write(d.join("snap.bin"), &b).unwrap();
        let e = (talus::io::snapshot::read(&d.join("snap.json")).err()).map(|e| e.to_string());
        assert!(
            e.as_deref().is_some_and(|e| e.contains(must)),
            "{name}: {e:?}"
        );
        for cmd in ["analyze", "render"] {
            let (code, _, err) = common::talus([cmd, d.join("snap.json").to_str().unwrap()]);
            assert_ne!(code, 0, "{cmd} {name}");
            assert!(!err.contains("panicked"), "{cmd} {name}: {err}");
        }
    }
}

#[test]
fn render_draws_pictures_and_vtk_files_of_the_column() {
    let s = settled_column();
    let dir = tmp("render");
    let json = talus::io::snapshot::write(&s, &dir, "snap").unwrap();
    let out = dir.join("pictures");
    let o = common::command([
        "render",
        json.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "400",
        "--g",
        "1",
    ])
    .output()
    .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for stem in ["grains", "forces", "stress_crosses"] {
        let png = std::fs::read(out.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png is a PNG");
        // Width in the IHDR chunk.
        assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), 400);
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }
    // One line per contact in the force network, the widest for the largest force (the
    // floor contact carries all N grains, the top one only itself).
    let svg = std::fs::read_to_string(out.join("forces.svg")).unwrap();
    let widths: Vec<f64> = svg
        .lines()
        .filter(|l| l.starts_with("<line"))
        .map(|l| {
            let w = l.split("stroke-width=\"").nth(1).unwrap();
            w[..w.find('"').unwrap()].parse().unwrap()
        })
        .collect();
    assert_eq!(widths.len(), N, "N contacts: {} lines", widths.len());
    let (wmin, wmax) = widths
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), &w| (a.min(w), b.max(w)));
    assert!(
        (wmax / wmin - N as f64).abs() < 0.05 * N as f64,
        "widths ∝ force: {wmin} .. {wmax}"
    );
    // The grains picture shows the grains: decoded, the view of the heap is as tall as
    // the outline with its margin (the legend strip below it; tests/pictures.rs), every
    // grain's centre is painted, and the painted share of the view is the grains' share
    // of it (N π r² at the picture's scale).
    let a = analyse(&s, &dir, 1.0);
    let o = &a.summary.outline;
    let pad = 0.04 * o.width.max(o.height);
    let scale = 400.0 / (o.width + 2.0 * pad);
    let png = tiny_skia::Pixmap::load_png(out.join("grains.png")).unwrap();
    assert_eq!(png.width(), 400);
    let view = ((o.height + 2.0 * pad) * scale).ceil() as u32;
    assert!(png.height() > view, "a legend strip under the view");
    let white = |x: u32, y: u32| {
        let p = png.pixel(x, y).unwrap();
        p.red() > 250 && p.green() > 250 && p.blue() > 250
    };
    for g in &a.input.grains {
        let x = ((g.x - (o.left - pad)) * scale) as u32;
        let y = ((o.top + pad - g.z) * scale) as u32;
        assert!(!white(x, y), "grain at ({}, {}) painted", g.x, g.z);
    }
    assert!(white(2, 2), "the margin stays white");
    let painted = (0..view)
        .flat_map(|y| (0..png.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| !white(x, y))
        .count() as f64;
    let grains_px = N as f64 * std::f64::consts::PI * (0.5 * scale).powi(2);
    assert!(
        (painted / grains_px - 1.0).abs() < 0.05,
        "{painted} pixels painted against {grains_px} for the grains"
    );
    // VTK, read back: N disks as points at the grains' centres with their radii, the
    // net contact force on each balancing its weight (settled, g = 1), and N contacts
    // as lines.
    let vtp = common::vtp::read(&out.join("grains.vtp"));
    assert_eq!(
        (vtp.count("NumberOfVerts"), vtp.count("NumberOfPolys")),
        (N, 0)
    );
    let points = vtp.get("Points", "Points");
    let (radius, force) = (vtp.get("PointData", "radius"), vtp.get("CellData", "force"));
    let (ids, velocity) = (vtp.get("CellData", "id"), vtp.get("CellData", "velocity"));
    // Float32 in the file.
    let f32 = |x: f64| x as f32 as f64;
    for (k, g) in a.input.grains.iter().enumerate() {
        assert_eq!(
            [points[3 * k], points[3 * k + 1]],
            [f32(g.x), f32(g.z)],
            "grain {k}"
        );
        assert_eq!(radius[k], f32(g.radius));
        assert_eq!(ids[k], g.id as f64);
        assert_eq!(
            [velocity[3 * k], velocity[3 * k + 1]],
            [f32(g.velocity[0]), f32(g.velocity[1])]
        );
        assert!(
            force[3 * k].abs() < 1e-6 && (force[3 * k + 1] - g.mass).abs() < 1e-3 * g.mass,
            "grain {k}: net contact force ({}, {}) against its weight {}",
            force[3 * k],
            force[3 * k + 1],
            g.mass
        );
    }
    let torque = vtp.get("CellData", "torque");
    assert!(torque.iter().all(|t| t.abs() < 1e-9), "{torque:?}");
    let vtp = common::vtp::read(&out.join("contacts.vtp"));
    assert_eq!(vtp.count("NumberOfLines"), N, "one line per contact");
    assert_eq!(vtp.get("Lines", "offsets").len(), N);
    let (f, m) = (
        vtp.get("CellData", "force"),
        vtp.get("CellData", "force_magnitude"),
    );
    for k in 0..N {
        assert!((f[3 * k].hypot(f[3 * k + 1]) - m[k]).abs() <= 1e-6 * m[k]);
    }
    for f in ["base_profile.svg", "force_distribution.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn stresses_average_over_snapshots() {
    // The same column twice, once with every contact force tripled: the averaged
    // stress tables are twice the single one; everything else is the last snapshot's.
    let s = settled_column();
    let json = talus::io::snapshot::write(&s, &tmp("series"), "snap").unwrap();
    let one = analyze::input::load(&json, Some(1.0)).unwrap();
    let mut tripled = one.clone();
    tripled.touches.iter_mut().for_each(|t| {
        t.force = [3.0 * t.force[0], 3.0 * t.force[1]];
        t.normal_force *= 3.0;
    });
    let single = analyze::analyze(one.clone(), &Options::default()).unwrap();
    let avg = analyze::analyze_series(one, vec![tripled], &Options::default()).unwrap();
    assert_eq!(avg.summary.averaged_snapshots, 2);
    for (a, b) in avg.windows.iter().zip(&single.windows) {
        assert!((a.sigma.zz - 2.0 * b.sigma.zz).abs() <= 1e-12 * b.sigma.zz.abs().max(1e-300));
        assert!((a.sigma.xx - 2.0 * b.sigma.xx).abs() <= 1e-12 + 1e-12 * b.sigma.xx.abs());
    }
    // So is the stress against depth, slab by slab.
    assert!(!single.stress_depth.is_empty());
    assert_eq!(avg.stress_depth.len(), single.stress_depth.len());
    for (a, b) in avg.stress_depth.iter().zip(&single.stress_depth) {
        assert!(
            a.0 == b.0 && (a.1 - 2.0 * b.1).abs() <= 1e-12 * b.1,
            "{a:?} {b:?}"
        );
    }
    assert_eq!(
        avg.summary.forces.mean_normal,
        single.summary.forces.mean_normal
    );
}

#[test]
fn grains_that_rolled_away_do_not_widen_the_heap() {
    // The lattice pile with three grains moved far out onto the floor: the outline, and
    // with it X = x/l and the slopes, stay those of the pile.
    let scene = talus::scene::load(Path::new("scenes/r1_pile_reduced.json"), &[]).unwrap();
    let mut s = talus::sim::Simulation::new(scene).unwrap();
    let plain = analyse(&s, &tmp("plain"), 9.81).summary;
    let n = s.particles.len();
    let r = s.particles.radius[n - 1];
    for (k, x) in [(n - 1, 0.2), (n - 2, -0.15), (n - 3, 0.3)] {
        s.particles.q[0][k] = [x, r, 0.0];
    }
    let strays = analyse(&s, &tmp("strays"), 9.81).summary;
    let (a, b) = (&plain.outline, &strays.outline);
    assert!(
        (a.left - b.left).abs() < 1e-12 && (a.right - b.right).abs() < 1e-12,
        "{a:?} vs {b:?}"
    );
    assert!((plain.repose_left.angle_deg - strays.repose_left.angle_deg).abs() < 1.0);
}

#[test]
fn a_run_with_output_vtk_writes_a_paraview_time_series() {
    let dir = tmp("vtk-run");
    common::talus_ok([
        "run",
        "-q",
        "--backend",
        "cpu",
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "output.vtk=true",
        "--set",
        "output.snapshot_every=1",
        "--set",
        "stop.time=3",
        "--set",
        "stop.kinetic_fraction=null",
    ]);
    let pvd = std::fs::read_to_string(dir.join("snapshots/snapshots.pvd")).unwrap();
    // Snapshots at t = 1, 2, 3 have grains (t = 0 is before the first one falls in).
    let files: Vec<&str> = pvd
        .lines()
        .filter_map(|l| {
            l.split("file=\"")
                .nth(1)
                .map(|f| &f[..f.find('"').unwrap()])
        })
        .collect();
    assert!(files.len() >= 6 && files.len().is_multiple_of(2), "{pvd}");
    for f in &files {
        let vtp = common::vtp::read(&dir.join("snapshots").join(f));
        assert!(vtp.header.contains("<PolyData>"), "{f}");
    }
    // The run writes them from the state in memory (issue 16 item 7): byte for byte what
    // `talus render` writes from the snapshot files.
    let last = files[files.len() - 2].trim_end_matches("_grains.vtp");
    let out = dir.join("rendered");
    render(&dir.join("snapshots").join(format!("{last}.json")), &out);
    for part in ["grains", "contacts"] {
        let run = std::fs::read(dir.join(format!("snapshots/{last}_{part}.vtp"))).unwrap();
        let rendered = std::fs::read(out.join(format!("{part}.vtp"))).unwrap();
        assert!(run == rendered, "{last}_{part}.vtp differs from render's");
    }
}

/// Disks of diameter 1 listed at `centres`, as a scene list block.
fn disks(centres: &[[f64; 2]]) -> serde_json::Value {
    let list: Vec<_> = centres
        .iter()
        .map(|c| json!({ "position": c, "diameter": 1.0 }))
        .collect();
    json!({ "kind": "list", "material": "m", "particles": list })
}

#[test]
fn a_compressed_triangular_packing_has_the_isotropic_stress_computed_by_hand() {
    // A triangular lattice of unit disks at spacing s = 1 − δ, no gravity, linear springs:
    // every interior contact pushes with f = k δ along the line of centres, at the
    // contact point s/2 from each centre. Per grain, Σ_c f ⊗ l (compression positive) is
    // f (s/2) Σ_c n ⊗ n = (3/2) f s I over its six neighbours, and the grain's Voronoi
    // cell is (√3/2) s², so σ = √3 f / s · I (paper 000 eq. 8) with no shear.
    let (delta, k) = (1e-3, 1e5);
    let s = 1.0 - delta;
    let h = 0.5 * 3f64.sqrt() * s;
    let (rows, cols) = (21, 40);
    let mut centres = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            centres.push([i as f64 * s + 0.5 * s * (j % 2) as f64, j as f64 * h]);
        }
    }
    let law = json!({ "law": "spring_dashpot", "k_n": k, "gamma_n": 10.0, "k_t": 2e4, "gamma_t": 1.0, "mu": 0.5 });
    let mut sim = sim(&scene_value(law, json!([disks(&centres)])));
    // One step evaluates the contacts. Gear starts from the true accelerations, so only
    // the outermost grains (whose forces do not balance) move in it.
    sim.step().unwrap();
    let f = k * delta;
    // Rows one lattice row high from the lowest bottom (each holds one lattice row), and
    // windows 8 spacings wide, so that a window holds 8 grains of each row it covers:
    // its edges never meet a centre (the left end is at −1/2, and 1/2 is no multiple of
    // s/4).
    let opt = Options {
        row: h,
        window: 8.0 * s,
        step: 0.25 * s,
        ..Default::default()
    };
    let a = analyse_with(&sim, &tmp("lattice-compressed"), 1.0, &opt);
    let by_hand = 3f64.sqrt() * f / s;
    let x_max = (cols - 1) as f64 * s + 0.5 * s;
    let mut checked = 0;
    for w in &a.windows {
        // Interior: two grains' spacing from every edge of the patch.
        let inside = w.row >= 2
            && w.row + 3 <= rows
            && w.x - 4.0 * s >= 2.0 * s
            && w.x + 4.0 * s <= x_max - 2.0 * s;
        if !inside {
            continue;
        }
        assert_eq!(w.particles, 8, "window at x = {}, row {}", w.x, w.row);
        let t = w.sigma;
        assert!(
            (t.xx / by_hand - 1.0).abs() < 1e-9 && (t.zz / by_hand - 1.0).abs() < 1e-9,
            "window at x = {}, row {}: σ_xx = {}, σ_zz = {} against {by_hand}",
            w.x,
            w.row,
            t.xx,
            t.zz
        );
        assert!(
            t.xz.abs() < 1e-9 * by_hand && t.zx.abs() < 1e-9 * by_hand,
            "no shear: {t:?}"
        );
        let (s1, s2, _) = t.principal();
        assert!((s1 - s2).abs() < 1e-9 * by_hand, "isotropic: {s1} {s2}");
        checked += 1;
    }
    assert!(checked > 100, "{checked} interior windows");
    // Grain by grain: an interior grain carries (3/2) f s in xx and zz.
    let middle = (rows / 2) * cols + cols / 2;
    let m = a.moments[middle];
    assert!((m.xx / (1.5 * f * s) - 1.0).abs() < 1e-9, "{m:?}");
    assert!((m.zz / (1.5 * f * s) - 1.0).abs() < 1e-9, "{m:?}");
    assert_eq!(a.counts[middle], 6);
}

/// A 30° pile of `base` unit disks (m = 1) on a triangular lattice standing on a floor
/// at z = 0, with friction, settled under g = 1.
fn settled_pile_on_a_floor(base: usize) -> talus::sim::Simulation {
    let h = 0.5 * 3f64.sqrt();
    let mut centres = Vec::new();
    for j in 0..base {
        for i in 0..base - j {
            centres.push([i as f64 + 0.5 * j as f64, 0.5 + j as f64 * h]);
        }
    }
    let law = json!({ "law": "spring_dashpot", "k_n": 1e5, "gamma_n": 150.0, "k_t": 2e4, "gamma_t": 15.0, "mu": 0.5 });
    // Round grains on a flat floor roll apart under the pile's outward thrust; these
    // do not turn, so friction holds the pile.
    let mut block = disks(&centres);
    for p in block["particles"].as_array_mut().unwrap() {
        p["fixed_rotation"] = json!(true);
    }
    let mut v = scene_value(law, json!([block]));
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-10.0, 0.0], "to": [base as f64 + 10.0, 0.0] }]);
    let mut s = sim(&v);
    for _ in 0..60_000 {
        s.step().unwrap();
    }
    s
}

#[test]
fn the_stress_at_the_base_integrates_to_the_weight_of_the_pile() {
    // A settled pile of 136 disks on a flat floor. Windows that tile the row (width =
    // step = 0.7 d, whose edges never meet a lattice column) count every grain once.
    let base = 16;
    let s = settled_pile_on_a_floor(base);
    let h = 0.5 * 3f64.sqrt();
    let (r, dz) = (0.5, 0.5 + 0.5 * h);
    let opt = Options {
        row: dz,
        window: 0.7,
        step: 0.7,
        ..Default::default()
    };
    let a = analyse_with(&s, &tmp("pile-on-floor"), 1.0, &opt);
    let grains = &a.input.grains;
    let weight: f64 = grains.iter().map(|g| g.mass).sum();
    let ke = s.energies();
    assert!(
        ke.kinetic() < 1e-5 * ke.elastic,
        "settled: {} against {}",
        ke.kinetic(),
        ke.elastic
    );
    // The floor's pressure profile carries the whole weight.
    let on_floor: f64 = a.wall_pressure.iter().map(|p| p.1 * opt.step).sum();
    assert!(
        (on_floor / weight - 1.0).abs() < 2e-3,
        "floor carries {on_floor} of {weight}"
    );
    // The lowest row, from the floor up to the contacts with the second lattice row
    // (dz = r + h/2), holds the grains that stand on the floor. Its coarse-grained σ_zz,
    // integrated along x, is the vertical force through the row averaged over its height:
    // the whole weight from the floor up to the centres at r, and the weight of the rows
    // above from there on, W − W_0 (1 − r/dz).
    let row0: Vec<_> = a.windows.iter().filter(|w| w.row == 0).collect();
    let integral: f64 = row0.iter().map(|w| w.sigma.zz * opt.step).sum();
    let counted: usize = row0.iter().map(|w| w.particles).sum();
    assert_eq!(counted, base, "each grain of the bottom row counted once");
    let w0 = base as f64 * grains[0].mass;
    let carried = weight - w0 * (1.0 - r / dz);
    assert!(
        (integral / carried - 1.0).abs() < 2e-3,
        "∫σ_zz dx = {integral} against {carried} (W = {weight})"
    );
}

#[test]
fn the_slopes_of_a_synthetic_heap_are_recovered() {
    // A heap 40 d high built to known slopes, 26° on the left and 34° on the right:
    // its surface a layer of unit disks along each slope (one diameter apart along it,
    // their tops on the line), its inside a triangular lattice kept below that layer.
    let (height, left, right) = (40.0, 26f64.to_radians(), 34f64.to_radians());
    let line = |x: f64| {
        if x < 0.0 {
            height + x * left.tan()
        } else {
            height - x * right.tan()
        }
    };
    let mut centres = Vec::new();
    for (angle, side) in [(left, -1.0), (right, 1.0)] {
        let toe = (height - 1.0) / angle.tan();
        let n = (toe / angle.cos()).floor() as usize;
        for m in 0..=n {
            let x = side * (toe - m as f64 * angle.cos());
            centres.push([x, line(x) - 0.5]);
        }
    }
    let h = 0.5 * 3f64.sqrt();
    for j in 0.. {
        let z = 0.5 + j as f64 * h;
        if z > height {
            break;
        }
        for i in -200..200 {
            let x = i as f64 + 0.5 * (j % 2) as f64;
            if z + 0.5 <= line(x) - 0.8 {
                centres.push([x, z]);
            }
        }
    }
    let law = json!({ "law": "spring_dashpot", "k_n": 1e5, "gamma_n": 10.0, "k_t": 2e4, "gamma_t": 1.0, "mu": 0.5 });
    let mut v = scene_value(law, json!([disks(&centres)]));
    v["domain"] = json!({ "x": [-200.0, 200.0], "z": [-10.0, 100.0] });
    // The surface layer sits where it must for the slopes, into the lattice below.
    v["limits"] = json!({ "initial_overlap": 1e9 });
    let s = sim(&v);
    let a = analyse(&s, &tmp("synthetic-heap"), 1.0);
    let sm = &a.summary;
    assert!((sm.outline.height - height).abs() < 0.6, "{:?}", sm.outline);
    for (slope, want) in [(&sm.repose_left, 26.0), (&sm.repose_right, 34.0)] {
        assert!(slope.points >= 30, "{} points fitted", slope.points);
        assert!(
            (slope.angle_deg - want).abs() < 0.5,
            "{} against {want}°",
            slope.angle_deg
        );
        assert!(slope.residual < 0.5, "RMS residual {}", slope.residual);
    }
}

#[test]
fn parallel_and_perpendicular_pairs_give_the_known_orientation_statistics() {
    // Pairs of elongated octagons (axes 2 : 1, symmetric, so the long axis is exactly the
    // body's x axis) far apart from each other (more than Q's reach of 10 d). Twelve
    // pairs 3 apart are parallel, both turned by 0.4; twelve 6 apart are perpendicular,
    // turned by 1.0 and 1.0 + π/2. Then Q = cos 2(θ_i − θ_j) is +1 at r = 3 and −1 at
    // r = 6, and f(θ) holds 1/2 of the grains at 0.4 and 1/4 each at 1.0 and 1.0 + π/2.
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut list = Vec::new();
    for p in 0..24 {
        let (cx, cz) = (-75.0 + 30.0 * (p % 6) as f64, -60.0 + 30.0 * (p / 6) as f64);
        let (gap, a, b) = if p % 2 == 0 {
            (3.0, 0.4, 0.4)
        } else {
            (6.0, 1.0, 1.0 + half_pi)
        };
        list.push(json!({ "position": [cx, cz], "theta": a, "diameter": 2.0 }));
        list.push(json!({ "position": [cx + gap, cz], "theta": b, "diameter": 2.0 }));
    }
    let law = json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 });
    let block =
        json!({ "kind": "list", "material": "m", "particles": list, "polygon": { "corners": 8 } });
    let mut s = sim(&scene_value(law, json!([block])));
    let body = talus::shape::ellipse_polygon(8, 2.0, 1.0, 0.0);
    s.particles.shape.iter_mut().for_each(|c| *c = body.clone());
    let a = analyse(&s, &tmp("pairs"), 1.0);
    assert_eq!(a.summary.oriented_grains, 48);
    for g in a.axes.iter().zip(&a.input.grains) {
        let want = if (g.1.theta - 0.4).abs() < 1e-12 {
            0.4
        } else {
            g.1.theta
        };
        assert!((g.0.unwrap() - want).abs() < 1e-9, "long axis {:?}", g.0);
    }
    let d = a.summary.mean_diameter;
    assert!(a.correlation.len() == 2, "{:?}", a.correlation);
    for (r, q, pairs) in &a.correlation {
        assert_eq!(*pairs, 12);
        let (gap, want) = if (r - 3.0).abs() < 0.5 * d {
            (3.0, 1.0)
        } else {
            (6.0, -1.0)
        };
        assert!(
            (r - gap).abs() <= 0.25 * d,
            "bin at {r} for pairs {gap} apart"
        );
        assert!((q - want).abs() < 1e-12, "Q({r}) = {q}, want {want}");
    }
    let width = std::f64::consts::PI / 18.0;
    let weight_at = |theta: f64| {
        a.orientation
            .iter()
            .find(|b| (b.0 - theta).abs() <= 0.5 * width)
            .map(|b| b.1 * width)
            .unwrap()
    };
    assert!((weight_at(0.4) - 0.5).abs() < 1e-12);
    assert!((weight_at(1.0) - 0.25).abs() < 1e-12);
    assert!((weight_at(1.0 + half_pi) - 0.25).abs() < 1e-12);
    let total: f64 = a.orientation.iter().map(|b| b.1 * width).sum();
    assert!((total - 1.0).abs() < 1e-12, "∫f = {total}");
}

#[test]
fn the_base_particles_carry_the_weight_above_them() {
    // Two columns of N unit disks (m = 1, g = 1), each standing on a fixed disk: each
    // base particle carries its column, N m g (paper 001 Fig. 3b's F_B), and together
    // they carry every mobile grain.
    let mut list = Vec::new();
    for x in [0.0, 3.0] {
        list.push(json!({ "position": [x, 0.5], "diameter": 1.0, "fixed": true }));
        for k in 1..=N {
            list.push(json!({ "position": [x, 0.5 + k as f64], "diameter": 1.0 }));
        }
    }
    let law = json!({ "law": "spring_dashpot", "k_n": 1e5, "gamma_n": 100.0, "k_t": 1e4, "gamma_t": 10.0, "mu": 0.5 });
    let mut v = scene_value(
        law,
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    let mut s = sim(&v);
    for _ in 0..40_000 {
        s.step().unwrap();
    }
    let dir = tmp("base-particles");
    let a = analyse(&s, &dir, 1.0);
    assert_eq!(a.base_forces.len(), 2);
    for b in &a.base_forces {
        assert!(
            (b.load / N as f64 - 1.0).abs() < 2e-3,
            "base particle at x = {} carries {}",
            b.x,
            b.load
        );
    }
    let load = a.summary.base_load.as_ref().unwrap();
    assert!(
        (load.total / load.mobile_weight - 1.0).abs() < 2e-3,
        "{load:?}"
    );
    assert!((load.grain_weight - 1.0).abs() < 1e-12);
    // The table: one row per base particle, F_B/mg = N.
    analyze::write(&a, &dir.join("analysis")).unwrap();
    let csv = std::fs::read_to_string(dir.join("analysis/base_forces.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(
        rows[0].contains("F_B [m g]"),
        "units in the header: {}",
        rows[0]
    );
    assert_eq!(rows.len(), 3, "{csv}");
    let mg: f64 = rows[1].split(',').nth(4).unwrap().parse().unwrap();
    assert!((mg - N as f64).abs() < 2e-2, "F_B/mg = {mg}");
}

#[test]
fn an_m_shaped_base_load_has_its_side_maxima_above_the_centre() {
    // 25 fixed base particles at x = 0..24 under 25 mobile grains (the one at x = 12
    // highest: the apex), each pressing its base particle down with
    // F_k = 10 + 10 exp(−(k − 4)²/2) + 10 exp(−(k − 20)²/2): an M. The summary gives the
    // load under the apex and the side maxima, each averaged over 5 base particles.
    use analyze::input::{Grain, Input, Touch};
    let f = |k: usize| {
        let k = k as f64;
        10.0 + 10.0 * (-(k - 4.0).powi(2) / 2.0).exp() + 10.0 * (-(k - 20.0).powi(2) / 2.0).exp()
    };
    let grain = |id: u32, x: f64, z: f64, fixed: bool| Grain {
        id,
        x,
        z,
        theta: 0.0,
        radius: 0.5,
        mass: 1.0,
        fixed,
        area: std::f64::consts::FRAC_PI_4,
        corners: Vec::new(),
        ..Default::default()
    };
    let mut grains = Vec::new();
    let mut touches = Vec::new();
    for k in 0..25 {
        grains.push(grain(k, k as f64, 0.5, true));
        let top = if k == 12 { 1.6 } else { 1.5 };
        grains.push(grain(100 + k, k as f64, top, false));
        touches.push(Touch {
            a: 2 * k as usize + 1,
            b: Some(2 * k as usize),
            force: [0.0, f(k as usize)],
            normal_force: f(k as usize),
            point: [k as f64, 1.0],
        });
    }
    let input = Input {
        source: PathBuf::from("m-profile"),
        scene: "m-profile".into(),
        units: "reduced".into(),
        step: 0,
        time: 0.0,
        grains,
        touches,
        g: 1.0,
        mu: None,
        log: None,
        length_unit: "sigma".into(),
        force_unit: "m g".into(),
        period_x: 0.0,
        walls: Vec::new(),
    };
    let a = analyze::analyze(input, &Options::default()).unwrap();
    assert_eq!(a.base_forces.len(), 25);
    let load = a.summary.base_load.clone().unwrap();
    let mean = |c: usize| (c - 2..=c + 2).map(f).sum::<f64>() / 5.0;
    assert!((load.centre - mean(12)).abs() < 1e-12, "{load:?}");
    assert!((load.left_max - mean(4)).abs() < 1e-12, "{load:?}");
    assert!((load.right_max - mean(20)).abs() < 1e-12, "{load:?}");
    assert!(load.left_max > 1.2 * load.centre && load.right_max > 1.2 * load.centre);
    let total: f64 = (0..25).map(f).sum();
    assert!((load.total - total).abs() < 1e-9);
    // Drawn as paper 001 Fig. 3b: the force on each base particle and its average.
    let dir = tmp("m-profile");
    talus::render::render(&a, &dir, talus::render::Field::Plain, 400).unwrap();
    let svg = std::fs::read_to_string(dir.join("base_forces.svg")).unwrap();
    assert!(
        svg.contains("F_B / (m g)") && svg.contains("over 5"),
        "axis and legend"
    );
}

/// A row of fixed base particles at x = 0, 1, … each pressed down by the mobile grain
/// on it with `loads[k]` (the one at the middle highest: the apex there).
fn base_input(name: &str, loads: &[f64]) -> analyze::input::Input {
    use analyze::input::{Grain, Input, Touch};
    let grain = |id: u32, x: f64, z: f64, fixed: bool| Grain {
        id,
        x,
        z,
        theta: 0.0,
        radius: 0.5,
        mass: 1.0,
        fixed,
        area: std::f64::consts::FRAC_PI_4,
        corners: Vec::new(),
        ..Default::default()
    };
    let mut grains = Vec::new();
    let mut touches = Vec::new();
    for (k, &f) in loads.iter().enumerate() {
        grains.push(grain(k as u32, k as f64, 0.5, true));
        let top = if k == loads.len() / 2 { 1.6 } else { 1.5 };
        grains.push(grain(1000 + k as u32, k as f64, top, false));
        touches.push(Touch {
            a: 2 * k + 1,
            b: Some(2 * k),
            force: [0.0, f],
            normal_force: f,
            point: [k as f64, 1.0],
        });
    }
    Input {
        source: PathBuf::from(name),
        scene: name.into(),
        units: "reduced".into(),
        step: 0,
        time: 0.0,
        grains,
        touches,
        g: 1.0,
        mu: None,
        log: None,
        length_unit: "sigma".into(),
        force_unit: "m g".into(),
        period_x: 0.0,
        walls: Vec::new(),
    }
}

#[test]
fn the_base_load_summary_tells_an_m_from_force_chain_noise() {
    // Issue 20 item 6. 81 base loads 10 (1 − u)(1 + a u), u = x² for x from −1 to 1,
    // times 1 + 0.1 N(0, 1): a = 3.3 is a broad M (maxima 40 % above the centre), a = 0
    // a parabola. The summary carries standard errors and a verdict: M with z > 2 for
    // the first, not M for the second; the same input gives the same bytes.
    let mut rng = talus::base::rng::Rng::new(42);
    let mut normal = || {
        let u = 1.0 - rng.uniform();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * rng.uniform()).cos()
    };
    let noise: Vec<f64> = (0..81).map(|_| 0.1 * normal()).collect();
    let loads = |a: f64| -> Vec<f64> {
        (0..81)
            .map(|k| {
                let u = ((k as f64 - 40.0) / 40.0).powi(2);
                10.0 * (1.0 - u) * (1.0 + a * u) * (1.0 + noise[k])
            })
            .collect()
    };
    let m = analyze::analyze(base_input("m", &loads(3.3)), &Options::default()).unwrap();
    let b = m.summary.base_load.clone().unwrap();
    assert_eq!(b.spread.verdict, "M", "{b:?}");
    assert!(b.spread.dip_z > 2.0 && b.spread.dip_p < 0.025, "{b:?}");
    assert!(b.left_max - b.centre > 2.0 * b.spread.dip_se, "{b:?}");
    // Standard errors of the order of the noise of a 5-particle average (10 % of ~10,
    // over √5: ~0.45), not zero and not the loads themselves.
    for se in [
        b.spread.centre_se,
        b.spread.left_max_se,
        b.spread.right_max_se,
    ] {
        assert!(se > 0.2 && se < 1.5, "{b:?}");
    }
    let hump = analyze::analyze(base_input("hump", &loads(0.0)), &Options::default()).unwrap();
    let h = hump.summary.base_load.unwrap();
    assert_ne!(h.spread.verdict, "M", "{h:?}");
    assert!(h.spread.dip_z < 2.0, "{h:?}");
    // Written: the summary's new fields, a se column of the base forces and of the
    // windows; twice the same bytes.
    let (one, two) = (tmp("m-verdict-1"), tmp("m-verdict-2"));
    analyze::write(&m, &one).unwrap();
    let again = analyze::analyze(base_input("m", &loads(3.3)), &Options::default()).unwrap();
    analyze::write(&again, &two).unwrap();
    for f in [
        "summary.json",
        "base_forces.csv",
        "stress.csv",
        "base_profile.csv",
    ] {
        let (a, b) = (
            std::fs::read(one.join(f)).unwrap(),
            std::fs::read(two.join(f)).unwrap(),
        );
        assert!(a == b, "{f} differs between two analyses of the same input");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(one.join("summary.json")).unwrap()).unwrap();
    for key in [
        "centre_se",
        "dip",
        "dip_se",
        "dip_null",
        "dip_z",
        "dip_p",
        "verdict",
    ] {
        assert!(
            summary["base_load"].get(key).is_some(),
            "summary.json lacks {key}"
        );
    }
    let csv = std::fs::read_to_string(one.join("base_forces.csv")).unwrap();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .ends_with("se of F_B over 5 base particles/mg")
    );
    let se: f64 = csv
        .lines()
        .nth(40)
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(se > 0.0 && se < 1.5, "{csv}");
    let stress = std::fs::read_to_string(one.join("stress.csv")).unwrap();
    assert!(stress.lines().next().unwrap().ends_with("se S_xx,se S_zz"));
}

#[test]
fn vtk_draws_disks_as_points_and_polygons_as_their_outlines() {
    // Issue 41 item 2: eight disks in a row on a floor and a pentagon resting on them.
    // VTK orders vertices before polygons: the disks first (points at their centres
    // with their radii), then the pentagon (its five world corners, radius 0 at each).
    let mut v = common::disks_and_a_pentagon();
    let (disks, pentagon) = (v["particles"][0].clone(), v["particles"][1].clone());
    v["particles"] = json!([pentagon, disks]);
    let mut s = common::sim(&v);
    s.advance(400).unwrap();
    let dir = tmp("vtk-mixed");
    let json_path = talus::io::snapshot::write(&s, &dir, "snap").unwrap();
    let out = dir.join("pictures");
    render(&json_path, &out);
    let snap = talus::io::snapshot::read(&json_path).unwrap();
    let vtp = common::vtp::read(&out.join("grains.vtp"));
    assert_eq!(
        (vtp.count("NumberOfVerts"), vtp.count("NumberOfPolys")),
        (8, 1)
    );
    assert_eq!(vtp.count("NumberOfPoints"), 8 + 5);
    // The pentagon was created first (id 0): it comes last, after the disks 1–8.
    let ids = vtp.get("CellData", "id");
    assert_eq!(ids, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 0.0]);
    let points = vtp.get("Points", "Points");
    let radius = vtp.get("PointData", "radius");
    let f32 = |x: f64| x as f32 as f64;
    let (x, z) = (
        snap.f64("particles.x").unwrap(),
        snap.f64("particles.z").unwrap(),
    );
    for k in 0..8 {
        assert_eq!(
            [points[3 * k], points[3 * k + 1]],
            [f32(x[k + 1]), f32(z[k + 1])]
        );
        assert_eq!(radius[k], 0.5);
    }
    assert_eq!(
        vtp.get("Verts", "connectivity"),
        [0., 1., 2., 3., 4., 5., 6., 7.]
    );
    assert_eq!(vtp.get("Polys", "connectivity"), [8., 9., 10., 11., 12.]);
    assert_eq!(vtp.get("Polys", "offsets"), [5.0]);
    let theta = snap.f64("particles.theta").unwrap()[0];
    let (cx, cz) = (
        snap.f64("corners.x").unwrap(),
        snap.f64("corners.z").unwrap(),
    );
    for c in 0..5 {
        let (sn, cs) = theta.sin_cos();
        let want = [
            x[0] + cs * cx[c] - sn * cz[c],
            z[0] + sn * cx[c] + cs * cz[c],
        ];
        let p = 3 * (8 + c);
        assert!(
            (points[p] - want[0]).abs() < 1e-6 && (points[p + 1] - want[1]).abs() < 1e-6,
            "corner {c}"
        );
        assert_eq!(radius[8 + c], 0.0);
    }
}

/// `talus render` of a snapshot into `out`, small pictures.
fn render(snapshot: &Path, out: &Path) {
    let (out, snapshot) = (out.to_str().unwrap(), snapshot.to_str().unwrap());
    common::talus_ok(["render", "--width", "64", "--out", out, snapshot]);
}

/// A LAMMPS-style dump (`dump custom`'s layout, `render::dump`), parsed as OVITO and
/// LAMMPS's tools do: the ITEM sections, then one row per atom under the named columns.
struct Dump {
    step: u64,
    time: f64,
    columns: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Dump {
    fn read(path: &Path) -> Dump {
        let text = std::fs::read_to_string(path).unwrap();
        let l: Vec<&str> = text.lines().collect();
        for (k, item) in [
            (0, "TIMESTEP"),
            (2, "TIME"),
            (4, "NUMBER OF ATOMS"),
            (6, "BOX BOUNDS ff ff ff"),
        ] {
            assert_eq!(l[k], format!("ITEM: {item}"));
        }
        let n: usize = l[5].parse().unwrap();
        for b in &l[7..10] {
            let v: Vec<f64> = b.split(' ').map(|x| x.parse().unwrap()).collect();
            assert!(v.len() == 2 && v[0] <= v[1], "bounds {b}");
        }
        let columns: Vec<String> = (l[10].strip_prefix("ITEM: ATOMS ").unwrap())
            .split(' ')
            .map(String::from)
            .collect();
        let rows: Vec<Vec<f64>> = (l[11..].iter())
            .map(|r| r.split(' ').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), n, "NUMBER OF ATOMS");
        assert!(rows.iter().all(|r| r.len() == columns.len()));
        Dump {
            step: l[1].parse().unwrap(),
            time: l[3].parse().unwrap(),
            columns,
            rows,
        }
    }

    fn column(&self, name: &str) -> Vec<f64> {
        let k = (self.columns.iter().position(|c| c == name))
            .unwrap_or_else(|| panic!("column {name}"));
        self.rows.iter().map(|r| r[k]).collect()
    }
}

/// `talus render` writes the grains as a LAMMPS-style dump beside the VTK files, with
/// OVITO's column names, and the snapshot's values exactly (shortest round-trip text).
#[test]
fn render_writes_a_lammps_style_dump_that_holds_the_snapshot_exactly() {
    let mut s = common::sim(&common::disks_and_a_pentagon());
    s.advance(400).unwrap();
    let dir = tmp("dump");
    let json_path = talus::io::snapshot::write(&s, &dir, "snap").unwrap();
    let out = dir.join("pictures");
    render(&json_path, &out);
    let d = Dump::read(&out.join("grains.dump"));
    let snap = talus::io::snapshot::read(&json_path).unwrap();
    assert_eq!(d.step, 400);
    assert_eq!(d.time, snap.meta.time);
    for c in [
        "id", "type", "x", "y", "z", "vx", "vy", "radius", "mass", "omegaz", "fx",
    ] {
        assert!(d.columns.iter().any(|x| x == c), "OVITO's column {c}");
    }
    let ids = d.column("id");
    assert_eq!(ids.len(), 9);
    let by_id = |name: &str| -> Vec<f64> {
        let v = d.column(name);
        let mut pairs: Vec<(f64, f64)> = ids.iter().copied().zip(v).collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs.into_iter().map(|p| p.1).collect()
    };
    // The plane x–z is the dump's x–y; the pentagon (listed after the disks: id 8) is
    // type 2, the disks 1.
    assert_eq!(by_id("x"), snap.f64("particles.x").unwrap());
    assert_eq!(by_id("y"), snap.f64("particles.z").unwrap());
    assert_eq!(by_id("theta"), snap.f64("particles.theta").unwrap());
    assert!(by_id("z").iter().all(|&z| z == 0.0));
    let types = by_id("type");
    assert_eq!(types[8], 2.0);
    assert!(types[..8].iter().all(|&t| t == 1.0));
    // The quaternion turns by θ about z.
    for (k, th) in by_id("theta").iter().enumerate() {
        let (w, qz) = (by_id("quatw")[k], by_id("quatk")[k]);
        assert!((w - (0.5 * th).cos()).abs() < 1e-15 && (qz - (0.5 * th).sin()).abs() < 1e-15);
    }
    // Each grain–grain contact adds a force and its opposite, so the net forces sum to
    // what the walls push with: upwards, holding the grains up.
    let fy = by_id("fy").iter().sum::<f64>();
    assert!(fy > 0.0, "Σ fy {fy}");
}

/// A run with `output.dump` writes a dump beside each snapshot that has grains; the last
/// one is byte for byte what `talus render` writes from that snapshot.
#[test]
fn a_run_with_output_dump_writes_one_dump_per_snapshot() {
    let dir = tmp("dump-run");
    common::talus_ok([
        "run",
        "-q",
        "--backend",
        "cpu",
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "output.dump=true",
        "--set",
        "output.snapshot_every=1",
        "--set",
        "stop.time=3",
        "--set",
        "stop.kinetic_fraction=null",
    ]);
    let mut dumps: Vec<PathBuf> = (std::fs::read_dir(dir.join("snapshots")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dump"))
        .collect();
    dumps.sort();
    assert!(dumps.len() >= 3, "{dumps:?}");
    assert!(
        !dir.join("snapshots/snapshots.pvd").exists(),
        "no VTK asked for"
    );
    let last = dumps.last().unwrap();
    let stem = (last.file_name().unwrap().to_str().unwrap()).trim_end_matches("_grains.dump");
    let out = dir.join("rendered");
    render(&dir.join("snapshots").join(format!("{stem}.json")), &out);
    let run = std::fs::read(last).unwrap();
    assert!(
        run == std::fs::read(out.join("grains.dump")).unwrap(),
        "{stem}"
    );
    assert!(!Dump::read(last).rows.is_empty());
}
