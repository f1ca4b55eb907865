//! VTK PolyData (`.vtp`) for ParaView and OVITO, in the XML format with its data
//! appended raw and zlib-compressed (binary, little-endian, UInt64 headers; the VTK
//! file-format documentation's "appended" encoding with `vtkZLibDataCompressor`): the
//! grains, disks as points (a vertex each, with a `radius` point array for glyphs) and
//! polygons and rods as outlines, with per-grain vectors (velocity, net contact force)
//! and scalars; the contact network as lines with their forces. The files are for
//! viewing: values are Float32 (the snapshots hold them exactly). `collection` writes
//! the `.pvd` time series of a run.

use super::RenderError;
use crate::analyze::Analysis;
use crate::base::files::write_atomic;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One data array: its name, VTK type, components and little-endian values.
struct Array {
    name: &'static str,
    kind: &'static str,
    comps: usize,
    bytes: Vec<u8>,
}

fn f64s(name: &'static str, comps: usize, values: impl IntoIterator<Item = f64>) -> Array {
    let bytes = (values.into_iter())
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect();
    Array {
        name,
        kind: "Float32",
        comps,
        bytes,
    }
}

fn u32s(name: &'static str, values: impl IntoIterator<Item = u32>) -> Array {
    let bytes = values.into_iter().flat_map(u32::to_le_bytes).collect();
    Array {
        name,
        kind: "UInt32",
        comps: 1,
        bytes,
    }
}

fn u8s(name: &'static str, values: impl IntoIterator<Item = u8>) -> Array {
    Array {
        name,
        kind: "UInt8",
        comps: 1,
        bytes: values.into_iter().collect(),
    }
}

fn i32s(name: &'static str, values: impl IntoIterator<Item = usize>) -> Array {
    let bytes = (values.into_iter())
        .flat_map(|v| (v as i32).to_le_bytes())
        .collect();
    Array {
        name,
        kind: "Int32",
        comps: 1,
        bytes,
    }
}

/// Uncompressed bytes per compressed block (VTK's default).
const BLOCK: usize = 1 << 15;

/// An array's appended block as `vtkZLibDataCompressor` writes it: the number of
/// blocks, the block size, the last block's size and each block's compressed size (all
/// UInt64), then the compressed blocks.
fn compressed(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write as _;
    let blocks: Vec<Vec<u8>> = (bytes.chunks(BLOCK))
        .map(|chunk| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            z.write_all(chunk).expect("writes to memory");
            z.finish().expect("writes to memory")
        })
        .collect();
    let last = match bytes.len() % BLOCK {
        0 if !bytes.is_empty() => BLOCK,
        r => r,
    };
    let mut out = Vec::new();
    for v in [blocks.len(), BLOCK, last]
        .into_iter()
        .chain(blocks.iter().map(Vec::len))
    {
        out.extend_from_slice(&(v as u64).to_le_bytes());
    }
    blocks.iter().for_each(|b| out.extend_from_slice(b));
    out
}

/// 2D vectors (x, z) as VTK's 3-component vectors in the x–y plane.
fn vectors(name: &'static str, values: impl IntoIterator<Item = [f64; 2]>) -> Array {
    f64s(name, 3, values.into_iter().flat_map(|v| [v[0], v[1], 0.0]))
}

/// A PolyData piece: points (x, z → x, y, 0) and its cells by kind, in VTK's cell
/// order (vertices, lines, polygons), with point and cell data in that order.
#[derive(Default)]
struct Piece {
    points: Vec<[f64; 2]>,
    verts: Vec<Vec<usize>>,
    lines: Vec<Vec<usize>>,
    polys: Vec<Vec<usize>>,
    point_data: Vec<Array>,
    cell_data: Vec<Array>,
}

fn write_piece(path: &Path, p: Piece) -> Result<(), RenderError> {
    let mut xml = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\" \
         compressor=\"vtkZLibDataCompressor\">\n  <PolyData>\n",
    );
    let _ = writeln!(
        xml,
        r#"    <Piece NumberOfPoints="{}" NumberOfVerts="{}" NumberOfLines="{}" NumberOfStrips="0" NumberOfPolys="{}">"#,
        p.points.len(),
        p.verts.len(),
        p.lines.len(),
        p.polys.len()
    );
    let mut blocks: Vec<u8> = Vec::new();
    let mut section = |xml: &mut String, tag: &str, arrays: Vec<Array>| {
        let _ = writeln!(xml, "      <{tag}>");
        for a in arrays {
            let _ = writeln!(
                xml,
                r#"        <DataArray type="{}" Name="{}" NumberOfComponents="{}" format="appended" offset="{}"/>"#,
                a.kind,
                a.name,
                a.comps,
                blocks.len()
            );
            blocks.extend_from_slice(&compressed(&a.bytes));
        }
        let _ = writeln!(xml, "      </{tag}>");
    };
    section(&mut xml, "PointData", p.point_data);
    section(&mut xml, "CellData", p.cell_data);
    section(
        &mut xml,
        "Points",
        vec![f64s(
            "Points",
            3,
            p.points.iter().flat_map(|q| [q[0], q[1], 0.0]),
        )],
    );
    for (tag, cells) in [
        ("Verts", &p.verts),
        ("Lines", &p.lines),
        ("Polys", &p.polys),
    ] {
        if cells.is_empty() {
            continue;
        }
        let mut end = 0;
        let offsets: Vec<usize> = (cells.iter())
            .map(|c| {
                end += c.len();
                end
            })
            .collect();
        section(
            &mut xml,
            tag,
            vec![
                i32s("connectivity", cells.iter().flatten().copied()),
                i32s("offsets", offsets),
            ],
        );
    }
    xml.push_str("    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _");
    let mut bytes = xml.into_bytes();
    bytes.extend_from_slice(&blocks);
    bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    write_atomic(path, &bytes).map_err(RenderError::write(path))
}

/// Writes `grains.vtp`, `contacts.vtp` and, where the scene has walls, `walls.vtp`
/// into `dir`.
pub fn write(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, RenderError> {
    write_named(a, dir, "")
}

/// A ParaView collection of (time, files: grains, contacts and walls if any), relative
/// to its folder; each file its part.
pub fn collection(entries: &[(f64, Vec<String>)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n",
    );
    for (t, files) in entries {
        for (part, f) in files.iter().enumerate() {
            let _ = writeln!(
                s,
                r#"    <DataSet timestep="{t:e}" part="{part}" file="{f}"/>"#
            );
        }
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// Each grain's net contact force and torque about its centre (2D: out of the plane,
/// counter-clockwise in the x–z plane positive), from the snapshot's contacts.
pub(super) fn net_loads(a: &Analysis) -> Vec<([f64; 2], f64)> {
    let grains = &a.input.grains;
    let mut loads = vec![([0.0; 2], 0.0); grains.len()];
    let mut add = |k: usize, f: [f64; 2], point: [f64; 2]| {
        let (dx, dz) = (point[0] - grains[k].x, point[1] - grains[k].z);
        let (force, torque) = &mut loads[k];
        force[0] += f[0];
        force[1] += f[1];
        *torque += dx * f[1] - dz * f[0];
    };
    for t in &a.input.touches {
        add(t.a, t.force, t.point);
        if let Some(b) = t.b {
            add(b, [-t.force[0], -t.force[1]], t.point);
        }
    }
    loads
}

/// Writes `{prefix}grains.vtp`, `{prefix}contacts.vtp` and, where the scene has walls,
/// `{prefix}walls.vtp` into `dir`; returns the files in that order.
pub fn write_named(a: &Analysis, dir: &Path, prefix: &str) -> Result<Vec<PathBuf>, RenderError> {
    let grains = &a.input.grains;
    // VTK orders cells vertices first, then polygons: the disks, then the rest.
    let is_disk = |k: &usize| grains[*k].corners.len() < 3;
    let order: Vec<usize> = (0..grains.len())
        .filter(is_disk)
        .chain((0..grains.len()).filter(|k| !is_disk(k)))
        .collect();
    let mut piece = Piece::default();
    let mut point_radius = Vec::new();
    for &k in &order {
        let g = &grains[k];
        let first = piece.points.len();
        if is_disk(&k) {
            piece.points.push([g.x, g.z]);
            point_radius.push(g.radius);
            piece.verts.push(vec![first]);
        } else {
            piece.points.extend(&g.corners);
            point_radius.extend(std::iter::repeat_n(0.0, g.corners.len()));
            piece.polys.push((first..first + g.corners.len()).collect());
        }
    }
    let loads = net_loads(a);
    let stress = |k: usize| a.moments[k].scaled(1.0 / grains[k].area);
    let each = |f: &dyn Fn(usize) -> f64| order.iter().map(|&k| f(k)).collect::<Vec<_>>();
    piece.point_data = vec![f64s("radius", 1, point_radius)];
    piece.cell_data = vec![
        u32s("id", order.iter().map(|&k| grains[k].id)),
        f64s("radius", 1, each(&|k| grains[k].radius)),
        f64s("mass", 1, each(&|k| grains[k].mass)),
        f64s("theta", 1, each(&|k| grains[k].theta)),
        u8s("fixed", order.iter().map(|&k| grains[k].fixed as u8)),
        vectors("velocity", order.iter().map(|&k| grains[k].velocity)),
        f64s("omega", 1, each(&|k| grains[k].omega)),
        vectors("force", order.iter().map(|&k| loads[k].0)),
        f64s("torque", 1, each(&|k| loads[k].1)),
        u32s("contacts", order.iter().map(|&k| a.counts[k] as u32)),
        u8s("rattler", order.iter().map(|&k| a.rattler[k] as u8)),
        f64s(
            "pressure",
            1,
            each(&|k| {
                let (s1, s2, _) = stress(k).principal();
                0.5 * (s1 + s2)
            }),
        ),
        f64s("sigma_zz", 1, each(&|k| stress(k).zz)),
        f64s("sigma_xx", 1, each(&|k| stress(k).xx)),
    ];
    let mut files = Vec::new();
    let p = dir.join(format!("{prefix}grains.vtp"));
    write_piece(&p, piece)?;
    files.push(p);
    // Contacts: lines from centre to centre, or to the contact point on a wall.
    let mut piece = Piece::default();
    for t in &a.input.touches {
        let ga = &grains[t.a];
        let end = match t.b {
            // Across a periodic seam, to the partner's image beside ga.
            Some(b) => [
                ga.x + crate::state::nearest_image(grains[b].x - ga.x, a.input.period_x),
                grains[b].z,
            ],
            None => t.point,
        };
        piece
            .lines
            .push(vec![piece.points.len(), piece.points.len() + 1]);
        piece.points.extend([[ga.x, ga.z], end]);
    }
    let touches = &a.input.touches;
    piece.cell_data = vec![
        f64s("normal_force", 1, touches.iter().map(|t| t.normal_force)),
        vectors("force", touches.iter().map(|t| t.force)),
        f64s(
            "force_magnitude",
            1,
            touches.iter().map(|t| t.force[0].hypot(t.force[1])),
        ),
        vectors("point", touches.iter().map(|t| t.point)),
        u8s("wall", touches.iter().map(|t| t.b.is_none() as u8)),
    ];
    let p = dir.join(format!("{prefix}contacts.vtp"));
    write_piece(&p, piece)?;
    files.push(p);
    // Walls: one line each, where it was at the snapshot's time (a moving wall placed).
    let walls = &a.input.walls;
    if !walls.is_empty() {
        let mut piece = Piece::default();
        for w in walls {
            piece
                .lines
                .push(vec![piece.points.len(), piece.points.len() + 1]);
            piece.points.extend(w);
        }
        piece.cell_data = vec![u32s("wall", 0..walls.len() as u32)];
        let p = dir.join(format!("{prefix}walls.vtp"));
        write_piece(&p, piece)?;
        files.push(p);
    }
    Ok(files)
}
