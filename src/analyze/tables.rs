//! An analysis written out: one CSV table per measurement and summary.json
//! (docs/FORMATS.md), each file atomically.

use super::{Analysis, AnalyzeError, BASE_SPAN, heap, stress};
use crate::base::files::write_atomic;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Number formatting for the tables: full precision, NaN written as "nan".
fn v(x: f64) -> String {
    format!("{x:e}")
}

fn table(header: &[String], rows: impl Iterator<Item = Vec<String>>) -> String {
    let mut s = header.join(",");
    s.push('\n');
    for r in rows {
        let _ = writeln!(s, "{}", r.join(","));
    }
    s
}

/// Writes the tables and summary.json into `dir` (each file atomically); returns the
/// files written.
pub fn write(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, AnalyzeError> {
    std::fs::create_dir_all(dir).map_err(|source| AnalyzeError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let (l, f) = (&a.input.length_unit, &a.input.force_unit);
    let stress_unit = format!("{f}/{l}");
    let s = &a.summary;
    let o = &s.outline;
    let xs = |x: f64| (x - o.left) / o.width;
    let mut files = Vec::new();
    let mut put = |name: &str, text: String| -> Result<(), AnalyzeError> {
        let p = dir.join(name);
        write_atomic(&p, text.as_bytes()).map_err(|source| AnalyzeError::Write {
            path: p.clone(),
            source,
        })?;
        files.push(p);
        Ok(())
    };
    let h = |names: &[&str]| names.iter().map(|n| n.to_string()).collect::<Vec<_>>();
    let su = |n: &str| format!("{n} [{stress_unit}]");
    // Per grain: the moments Σ f ⊗ l (compression positive) and the grain's own
    // stress (moment over its area) in principal form.
    let mom = format!("[{f} {l}]");
    put(
        "grains.csv",
        table(
            &[
                "id".into(),
                format!("x [{l}]"),
                format!("z [{l}]"),
                "theta [rad]".into(),
                format!("area [{l}^2]"),
                "contacts".into(),
                "rattler".into(),
                "surface".into(),
                "long_axis [rad]".into(),
                format!("m_xx {mom}"),
                format!("m_xz {mom}"),
                format!("m_zx {mom}"),
                format!("m_zz {mom}"),
                su("sigma_max"),
                su("sigma_min"),
                "phi [rad]".into(),
            ],
            a.input.grains.iter().enumerate().map(|(k, g)| {
                let m = a.moments[k];
                // The grain's own stress: its moment over its area.
                let (smax, smin, phi) = m.scaled(1.0 / g.area).principal();
                vec![
                    g.id.to_string(),
                    v(g.x),
                    v(g.z),
                    v(g.theta),
                    v(g.area),
                    a.counts[k].to_string(),
                    (a.rattler[k] as u8).to_string(),
                    (a.on_surface[k] as u8).to_string(),
                    a.axes[k].map_or("nan".into(), v),
                    v(m.xx),
                    v(m.xz),
                    v(m.zx),
                    v(m.zz),
                    v(smax),
                    v(smin),
                    v(phi),
                ]
            }),
        ),
    )?;
    let window_header = |first: &[String]| {
        let mut hd = first.to_vec();
        hd.extend([
            format!("x [{l}]"),
            "X = (x - left)/width".into(),
            "grains".into(),
            su("sigma_xx"),
            su("sigma_xz"),
            su("sigma_zx"),
            su("sigma_zz"),
            su("sigma_max"),
            su("sigma_min"),
            "phi [rad]".into(),
            "S_xx".into(),
            "S_xz".into(),
            "S_zz".into(),
            "S_max".into(),
            "S_min".into(),
        ]);
        hd
    };
    let window_row = |w: &stress::Window| {
        let (smax, smin, phi) = w.sigma.principal();
        let sc = s.stress_scale;
        vec![
            v(w.x),
            v(xs(w.x)),
            w.particles.to_string(),
            v(w.sigma.xx),
            v(w.sigma.xz),
            v(w.sigma.zx),
            v(w.sigma.zz),
            v(smax),
            v(smin),
            v(phi),
            v(w.sigma.xx / sc),
            v(0.5 * (w.sigma.xz + w.sigma.zx) / sc),
            v(w.sigma.zz / sc),
            v(smax / sc),
            v(smin / sc),
        ]
    };
    // The bootstrap standard errors of a window's σ_xx and σ_zz, and of S_xx and S_zz;
    // after the other columns, so that those keep their places.
    let se_header = [
        format!("se sigma_xx [{stress_unit}]"),
        format!("se sigma_zz [{stress_unit}]"),
        "se S_xx".into(),
        "se S_zz".into(),
    ];
    let se_row = |k: usize| {
        let [xx, zz] = a.window_se[k];
        vec![v(xx), v(zz), v(xx / s.stress_scale), v(zz / s.stress_scale)]
    };
    put(
        "stress.csv",
        table(
            &{
                let mut hd =
                    window_header(&["row".into(), format!("z_lo [{l}]"), format!("z_hi [{l}]")]);
                hd.extend(se_header.clone());
                hd
            },
            a.windows.iter().enumerate().map(|(k, w)| {
                let mut r = vec![w.row.to_string(), v(w.z_lo), v(w.z_hi)];
                r.extend(window_row(w));
                r.extend(se_row(k));
                r
            }),
        ),
    )?;
    put(
        "base_profile.csv",
        table(
            &{
                let mut hd = window_header(&[]);
                hd.push(format!("wall pressure [{stress_unit}]"));
                hd.push("S_wall".into());
                hd.extend(se_header.clone());
                hd
            },
            (a.windows.iter().enumerate())
                .filter(|(_, w)| w.row == 0)
                .zip(&a.wall_pressure)
                .map(|((k, w), &(_, p))| {
                    let mut r = window_row(w);
                    r.push(v(p));
                    r.push(v(p / s.stress_scale));
                    r.extend(se_row(k));
                    r
                }),
        ),
    )?;
    if !a.base_forces.is_empty() {
        let smooth = heap::smoothed_loads(&a.base_forces, BASE_SPAN);
        let mg = s.base_load.as_ref().map_or(f64::NAN, |b| b.grain_weight);
        put(
            "base_forces.csv",
            table(
                &h(&[
                    "id",
                    &format!("x [{l}]"),
                    "X = (x - left)/width",
                    &format!("F_B [{f}]"),
                    "F_B/mg",
                    &format!("F_B over {BASE_SPAN} base particles/mg"),
                    &format!("se of F_B over {BASE_SPAN} base particles/mg"),
                ]),
                (a.base_forces.iter().zip(&smooth).zip(&a.base_load_se)).map(|((b, sm), se)| {
                    vec![
                        a.input.grains[b.grain].id.to_string(),
                        v(b.x),
                        v(xs(b.x)),
                        v(b.load),
                        v(b.load / mg),
                        v(sm.1 / mg),
                        v(se / mg),
                    ]
                }),
            ),
        )?;
    }
    put(
        "surface.csv",
        table(
            &h(&[&format!("x [{l}]"), &format!("z [{l}]"), "side", "fitted"]),
            a.surface.iter().map(|p| {
                vec![
                    v(p.x),
                    v(p.z),
                    p.side.to_string(),
                    (p.fitted as u8).to_string(),
                ]
            }),
        ),
    )?;
    put(
        "force_distribution.csv",
        table(
            &h(&["f/<f>", "P(f/<f>)"]),
            a.force_pdf.iter().map(|&(x, p)| vec![v(x), v(p)]),
        ),
    )?;
    put(
        "packing.csv",
        table(
            &h(&[
                &format!("z [{l}]"),
                &format!("depth [{l}]"),
                &format!("width [{l}]"),
                "grains",
                "packing fraction",
            ]),
            a.layers.iter().map(|y| {
                vec![
                    v(y.z),
                    v(y.depth),
                    v(y.width),
                    y.grains.to_string(),
                    v(y.fraction),
                ]
            }),
        ),
    )?;
    put(
        "orientation.csv",
        table(
            &h(&["theta [rad]", "f(theta) [1/rad]"]),
            a.orientation.iter().map(|&(t, p)| vec![v(t), v(p)]),
        ),
    )?;
    put(
        "principal_directions.csv",
        table(
            &h(&["phi [rad]", "P(phi) [1/rad]"]),
            a.principal_directions
                .iter()
                .map(|&(t, p)| vec![v(t), v(p)]),
        ),
    )?;
    put(
        "stress_depth.csv",
        table(
            &h(&["depth / W", "sigma_xx + sigma_zz / (rho g W)"]),
            a.stress_depth.iter().map(|&(x, p)| vec![v(x), v(p)]),
        ),
    )?;
    put(
        "orientation_correlation.csv",
        table(
            &h(&[&format!("r [{l}]"), "Q(r)", "pairs"]),
            a.correlation
                .iter()
                .map(|&(r, q, n)| vec![v(r), v(q), n.to_string()]),
        ),
    )?;
    if let Some((hd, rows)) = &a.input.log {
        let e = if a.input.units == "si" {
            "J"
        } else {
            "m g sigma"
        };
        let t = if a.input.units == "si" {
            "s"
        } else {
            "sqrt(sigma/g)"
        };
        let named: Vec<String> = hd
            .iter()
            .map(|c| match c.as_str() {
                "time" => format!("time [{t}]"),
                "step" | "particles" | "contacts" => c.clone(),
                other => format!("{other} [{e}]"),
            })
            .collect();
        put(
            "energy.csv",
            table(
                &named,
                rows.iter().map(|r| r.iter().map(|&x| v(x)).collect()),
            ),
        )?;
    }
    // Plain numbers and strings (NaN becomes null): serialising cannot fail.
    let json = serde_json::to_string_pretty(&a.summary).expect("a summary serialises");
    put("summary.json", json)?;
    Ok(files)
}
