//! VTK PolyData (`.vtp`, XML, ASCII) for ParaView: the grains as polygons (disks as
//! 32-gons) with per-grain fields, and the contact network as lines with forces.

use super::RenderError;
use crate::analyze::Analysis;
use crate::files::write_atomic;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn array(
    out: &mut String,
    name: &str,
    kind: &str,
    comps: usize,
    values: impl Iterator<Item = String>,
) {
    let _ = writeln!(
        out,
        r#"        <DataArray type="{kind}" Name="{name}" NumberOfComponents="{comps}" format="ascii">"#
    );
    let v: Vec<String> = values.collect();
    for chunk in v.chunks(12) {
        let _ = writeln!(out, "          {}", chunk.join(" "));
    }
    out.push_str("        </DataArray>\n");
}

/// A PolyData piece: points (x, z → x, y, 0), cells as polygons or lines, cell data.
struct Piece {
    points: Vec<[f64; 2]>,
    cells: Vec<Vec<usize>>,
    lines: bool,
    data: Vec<(String, &'static str, Vec<String>)>,
}

fn write_piece(path: &Path, p: &Piece) -> Result<(), RenderError> {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n");
    let (nl, np) = if p.lines {
        (p.cells.len(), 0)
    } else {
        (0, p.cells.len())
    };
    let _ = writeln!(
        s,
        r#"    <Piece NumberOfPoints="{}" NumberOfVerts="0" NumberOfLines="{nl}" NumberOfStrips="0" NumberOfPolys="{np}">"#,
        p.points.len()
    );
    s.push_str("      <Points>\n");
    array(
        &mut s,
        "Points",
        "Float64",
        3,
        p.points.iter().map(|q| format!("{:e} {:e} 0", q[0], q[1])),
    );
    s.push_str("      </Points>\n      <CellData>\n");
    for (name, kind, values) in &p.data {
        array(&mut s, name, kind, 1, values.iter().cloned());
    }
    s.push_str("      </CellData>\n");
    let tag = if p.lines { "Lines" } else { "Polys" };
    let _ = writeln!(s, "      <{tag}>");
    array(
        &mut s,
        "connectivity",
        "Int64",
        1,
        p.cells.iter().flatten().map(|k| k.to_string()),
    );
    let mut end = 0;
    array(
        &mut s,
        "offsets",
        "Int64",
        1,
        p.cells.iter().map(|c| {
            end += c.len();
            end.to_string()
        }),
    );
    let _ = writeln!(s, "      </{tag}>");
    s.push_str("    </Piece>\n  </PolyData>\n</VTKFile>\n");
    write_atomic(path, s.as_bytes()).map_err(RenderError::write(path))
}

/// Writes `grains.vtp` and `contacts.vtp` into `dir`.
pub fn write(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, RenderError> {
    write_named(a, dir, "")
}

/// A ParaView collection of (time, grains file, contacts file), relative to its folder.
pub fn collection(entries: &[(f64, String, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n",
    );
    for (t, g, c) in entries {
        let _ = writeln!(s, r#"    <DataSet timestep="{t:e}" part="0" file="{g}"/>"#);
        let _ = writeln!(s, r#"    <DataSet timestep="{t:e}" part="1" file="{c}"/>"#);
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// Writes `{prefix}grains.vtp` and `{prefix}contacts.vtp` into `dir`.
pub fn write_named(a: &Analysis, dir: &Path, prefix: &str) -> Result<Vec<PathBuf>, RenderError> {
    let grains = &a.input.grains;
    let mut points = Vec::new();
    let mut cells = Vec::new();
    for g in grains {
        let outline: Vec<[f64; 2]> = if g.corners.len() >= 3 {
            g.corners.clone()
        } else {
            (0..32)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / 32.0;
                    [g.x + g.radius * t.cos(), g.z + g.radius * t.sin()]
                })
                .collect()
        };
        cells.push((points.len()..points.len() + outline.len()).collect());
        points.extend(outline);
    }
    let e = |x: f64| format!("{x:e}");
    let pressure: Vec<String> = grains
        .iter()
        .enumerate()
        .map(|(k, g)| {
            let (s1, s2, _) = a.moments[k].scaled(1.0 / g.area).principal();
            e(0.5 * (s1 + s2))
        })
        .collect();
    let piece = Piece {
        points,
        cells,
        lines: false,
        data: vec![
            (
                "id".into(),
                "UInt32",
                grains.iter().map(|g| g.id.to_string()).collect(),
            ),
            (
                "radius".into(),
                "Float64",
                grains.iter().map(|g| e(g.radius)).collect(),
            ),
            (
                "mass".into(),
                "Float64",
                grains.iter().map(|g| e(g.mass)).collect(),
            ),
            (
                "theta".into(),
                "Float64",
                grains.iter().map(|g| e(g.theta)).collect(),
            ),
            (
                "fixed".into(),
                "UInt8",
                grains.iter().map(|g| (g.fixed as u8).to_string()).collect(),
            ),
            (
                "contacts".into(),
                "UInt32",
                a.counts.iter().map(|c| c.to_string()).collect(),
            ),
            (
                "rattler".into(),
                "UInt8",
                a.rattler.iter().map(|&r| (r as u8).to_string()).collect(),
            ),
            ("pressure".into(), "Float64", pressure),
            (
                "sigma_zz".into(),
                "Float64",
                grains
                    .iter()
                    .enumerate()
                    .map(|(k, g)| e(a.moments[k].zz / g.area))
                    .collect(),
            ),
            (
                "sigma_xx".into(),
                "Float64",
                grains
                    .iter()
                    .enumerate()
                    .map(|(k, g)| e(a.moments[k].xx / g.area))
                    .collect(),
            ),
        ],
    };
    let mut files = Vec::new();
    let p = dir.join(format!("{prefix}grains.vtp"));
    write_piece(&p, &piece)?;
    files.push(p);
    // Contacts: lines from centre to centre, or to the contact point on a wall.
    let mut points = Vec::new();
    let mut cells = Vec::new();
    let (mut fnv, mut fmag, mut wall) = (Vec::new(), Vec::new(), Vec::new());
    for t in &a.input.touches {
        let ga = &grains[t.a];
        let end = match t.b {
            Some(b) => [grains[b].x, grains[b].z],
            None => t.point,
        };
        cells.push(vec![points.len(), points.len() + 1]);
        points.push([ga.x, ga.z]);
        points.push(end);
        fnv.push(e(t.normal_force));
        fmag.push(e(t.force[0].hypot(t.force[1])));
        wall.push((t.b.is_none() as u8).to_string());
    }
    let piece = Piece {
        points,
        cells,
        lines: true,
        data: vec![
            ("normal_force".into(), "Float64", fnv),
            ("force".into(), "Float64", fmag),
            ("wall".into(), "UInt8", wall),
        ],
    };
    let p = dir.join(format!("{prefix}contacts.vtp"));
    write_piece(&p, &piece)?;
    files.push(p);
    Ok(files)
}
