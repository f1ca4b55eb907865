//! A reader of the `.vtp` files talus writes (VTK XML PolyData with its arrays
//! appended raw, zlib-compressed, UInt64 headers), written from the VTK file-format
//! documentation for the tests: every array by its section and name, as f64.

use std::collections::BTreeMap;
use std::path::Path;

pub struct Vtp {
    /// The XML before the appended data.
    pub header: String,
    /// (section, name) → (components, values).
    pub arrays: BTreeMap<(String, String), (usize, Vec<f64>)>,
}

fn attr<'a>(line: &'a str, name: &str) -> &'a str {
    let at = line
        .find(&format!(" {name}=\""))
        .unwrap_or_else(|| panic!("no {name} in {line}"));
    let rest = &line[at + name.len() + 3..];
    &rest[..rest.find('"').unwrap()]
}

pub fn read(path: &Path) -> Vtp {
    let bytes = std::fs::read(path).unwrap();
    let tag = b"<AppendedData encoding=\"raw\">";
    let at = (bytes.windows(tag.len()))
        .position(|w| w == tag)
        .unwrap_or_else(|| panic!("{}: no raw appended data", path.display()));
    let header = String::from_utf8(bytes[..at].to_vec()).expect("the XML is UTF-8");
    assert!(
        header.contains(
            r#"byte_order="LittleEndian" header_type="UInt64" compressor="vtkZLibDataCompressor""#
        ),
        "{header}"
    );
    let underscore = at + bytes[at..].iter().position(|&b| b == b'_').unwrap();
    let data = &bytes[underscore + 1..];
    let mut arrays = BTreeMap::new();
    let mut section = String::new();
    for line in header.lines().map(str::trim) {
        if let Some(s) = line.strip_prefix('<')
            && let Some(s) = s.strip_suffix('>')
            && ["PointData", "CellData", "Points", "Verts", "Lines", "Polys"].contains(&s)
        {
            section = s.to_string();
        }
        if !line.starts_with("<DataArray") {
            continue;
        }
        assert_eq!(attr(line, "format"), "appended", "{line}");
        let offset: usize = attr(line, "offset").parse().unwrap();
        let raw = decompress(&data[offset..]);
        let raw = &raw[..];
        let values: Vec<f64> = match attr(line, "type") {
            "Float32" => raw
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()) as f64)
                .collect(),
            "Int32" => raw
                .chunks_exact(4)
                .map(|b| i32::from_le_bytes(b.try_into().unwrap()) as f64)
                .collect(),
            "UInt32" => raw
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes(b.try_into().unwrap()) as f64)
                .collect(),
            "UInt8" => raw.iter().map(|&b| b as f64).collect(),
            other => panic!("type {other}"),
        };
        let comps: usize = attr(line, "NumberOfComponents").parse().unwrap();
        assert_eq!(values.len() % comps, 0, "{line}");
        let name = attr(line, "Name").to_string();
        arrays.insert((section.clone(), name), (comps, values));
    }
    let tail = &data[data.len().saturating_sub(30)..];
    assert!(
        String::from_utf8_lossy(tail).contains("</AppendedData>\n</VTKFile>"),
        "{}: the file ends as XML",
        path.display()
    );
    Vtp { header, arrays }
}

/// One array's block: [blocks, block size, last block's size, compressed sizes...]
/// (UInt64), then the zlib streams.
fn decompress(data: &[u8]) -> Vec<u8> {
    use std::io::Read as _;
    let word = |k: usize| u64::from_le_bytes(data[8 * k..8 * k + 8].try_into().unwrap()) as usize;
    let (blocks, size, last) = (word(0), word(1), word(2));
    let mut at = 8 * (3 + blocks);
    let mut out = Vec::new();
    for b in 0..blocks {
        let n = word(3 + b);
        let mut block = Vec::new();
        flate2::read::ZlibDecoder::new(&data[at..at + n])
            .read_to_end(&mut block)
            .unwrap();
        let want = if b + 1 == blocks { last } else { size };
        assert_eq!(block.len(), want, "block {b} of {blocks}");
        out.extend(block);
        at += n;
    }
    out
}

impl Vtp {
    pub fn get(&self, section: &str, name: &str) -> &[f64] {
        &(self.arrays.get(&(section.into(), name.into())))
            .unwrap_or_else(|| panic!("no {section}/{name}"))
            .1
    }
    /// A count of the piece: NumberOfPoints, NumberOfVerts, NumberOfLines, NumberOfPolys.
    pub fn count(&self, name: &str) -> usize {
        let line = (self.header.lines())
            .find(|l| l.contains("<Piece"))
            .unwrap();
        attr(line, name).parse().unwrap()
    }
}
