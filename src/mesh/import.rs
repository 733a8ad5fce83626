//! Format detection and the import steps every format shares: validation,
//! degenerate-triangle removal, units and up axis (spec "Inputs").

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::DVec3;

use super::{cloud, gltf, obj, pcd, ply, stl, xyz};
use super::{ImportOptions, ImportedMesh, MeshError, MeshFormat, ScanUnits, TriMesh, UpAxis};

/// What a format parser hands to the shared steps: positions in the file's
/// own units and axes, indices already resolved to 0-based.
#[derive(Debug, Default)]
pub(super) struct Parsed {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub warnings: Vec<String>,
}

/// Guesses the format: the file name's extension first, then the content.
///
/// `file` is only a display name; nothing is opened.
pub fn detect_format(bytes: &[u8], file: &str) -> Option<MeshFormat> {
    from_extension(file).or_else(|| sniff(bytes))
}

fn from_extension(file: &str) -> Option<MeshFormat> {
    let (_, ext) = file.rsplit_once('.')?;
    match ext.to_ascii_lowercase().as_str() {
        "obj" => Some(MeshFormat::Obj),
        "ply" => Some(MeshFormat::Ply),
        "stl" => Some(MeshFormat::Stl),
        "gltf" => Some(MeshFormat::Gltf),
        "glb" => Some(MeshFormat::Glb),
        "xyz" | "csv" | "txt" | "asc" | "pts" => Some(MeshFormat::Xyz),
        "pcd" => Some(MeshFormat::Pcd),
        _ => None,
    }
}

fn sniff(bytes: &[u8]) -> Option<MeshFormat> {
    if bytes.starts_with(b"glTF") {
        return Some(MeshFormat::Glb);
    }
    // Binary STL has no magic; its exact size is the best evidence, checked
    // before the text forms because its free header may say "solid".
    if stl::is_binary_size(bytes) {
        return Some(MeshFormat::Stl);
    }
    let text = skip_bom_and_space(bytes);
    if text.starts_with(b"ply\n") || text.starts_with(b"ply\r\n") {
        return Some(MeshFormat::Ply);
    }
    if pcd::looks_like_pcd(text) {
        return Some(MeshFormat::Pcd);
    }
    if text.starts_with(b"solid") {
        return Some(MeshFormat::Stl);
    }
    if text.starts_with(b"{") {
        let head = &text[..text.len().min(1 << 16)];
        return head
            .windows(7)
            .any(|w| w == b"\"asset\"")
            .then_some(MeshFormat::Gltf);
    }
    if looks_like_obj(text) {
        return Some(MeshFormat::Obj);
    }
    if xyz::looks_like_xyz(text) {
        return Some(MeshFormat::Xyz);
    }
    None
}

fn skip_bom_and_space(bytes: &[u8]) -> &[u8] {
    let b = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    &b[start..]
}

/// The first statements (up to 64 lines) are all OBJ keywords or comments,
/// and at least one is a vertex or face.
fn looks_like_obj(text: &[u8]) -> bool {
    const KEYWORDS: &[&[u8]] = &[
        b"v", b"vt", b"vn", b"vp", b"f", b"o", b"g", b"s", b"l", b"p", b"usemtl", b"mtllib",
    ];
    let mut saw_geometry = false;
    for line in text.split(|&c| c == b'\n').take(64) {
        let line = line.trim_ascii();
        if line.is_empty() || line.starts_with(b"#") {
            continue;
        }
        let word = line
            .split(|c| c.is_ascii_whitespace())
            .next()
            .unwrap_or_default();
        if !KEYWORDS.contains(&word) {
            return false;
        }
        saw_geometry |= word == b"v" || word == b"f";
    }
    saw_geometry
}

/// Reads a scan from bytes into millimetres, +Z up.
///
/// `file` names the scan in messages and selects the format by extension
/// (content sniffing otherwise). Units and up axis default to the format's
/// convention ([`MeshFormat::default_units`]); degenerate triangles are
/// dropped with a warning, everything else wrong is an error.
pub fn import_mesh(
    bytes: &[u8],
    file: &str,
    options: &ImportOptions,
) -> Result<ImportedMesh, MeshError> {
    check_scan_size(bytes.len(), file)?;
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(MeshError::invalid(file, "the file is empty"));
    }
    if bytes.starts_with(&[0xFE, 0xFF]) || bytes.starts_with(&[0xFF, 0xFE]) {
        return Err(MeshError::invalid(
            file,
            "the file is UTF-16 text; save it as UTF-8 or ASCII (OBJ, PLY and STL text must be)",
        ));
    }
    let format =
        detect_format(bytes, file).ok_or_else(|| MeshError::UnknownFormat { file: file.into() })?;
    let parsed = match format {
        MeshFormat::Obj => obj::parse(bytes, file)?,
        MeshFormat::Ply => ply::parse(bytes, file)?,
        MeshFormat::Stl => stl::parse(bytes, file)?,
        MeshFormat::Gltf | MeshFormat::Glb => gltf::parse(bytes, file)?,
        MeshFormat::Xyz => Parsed {
            vertices: xyz::parse(bytes, file)?,
            ..Parsed::default()
        },
        MeshFormat::Pcd => {
            let (vertices, warnings) = pcd::parse(bytes, file)?;
            Parsed {
                vertices,
                warnings,
                ..Parsed::default()
            }
        }
    };
    let units = options.units.unwrap_or(format.default_units());
    let up_axis = options.up_axis.unwrap_or(format.default_up_axis());
    // A PLY with vertices and no faces is a point cloud too.
    let cloud = match format {
        MeshFormat::Xyz | MeshFormat::Pcd => true,
        MeshFormat::Ply => parsed.triangles.is_empty() && !parsed.vertices.is_empty(),
        _ => false,
    };
    if cloud {
        return import_cloud(parsed, file, format, options.max_edge_mm, units, up_axis);
    }
    // STL and glTF parsers weld as they read; OBJ and PLY files from
    // exporters often split vertices at UV seams too (a Blender PLY cube has
    // 24 vertices), which would turn every seam into fake holes for the
    // fiducial detector, so they are welded here.
    let weld = matches!(format, MeshFormat::Obj | MeshFormat::Ply);
    let (mesh, warnings) = finish(parsed, file, units.to_mm(), up_axis, weld)?;
    Ok(ImportedMesh {
        mesh,
        format,
        units,
        up_axis,
        warnings,
        cloud: None,
    })
}

/// A point cloud into millimetres and printer axes, then meshed as a
/// height field over the printer's XY ([`cloud::triangulate`]).
fn import_cloud(
    parsed: Parsed,
    file: &str,
    format: MeshFormat,
    max_edge_mm: Option<f64>,
    units: ScanUnits,
    up_axis: UpAxis,
) -> Result<ImportedMesh, MeshError> {
    let Parsed {
        mut vertices,
        mut warnings,
        ..
    } = parsed;
    check_finite(&vertices, file)?;
    to_printer_frame(&mut vertices, units.to_mm(), up_axis);
    let (mesh, info) = cloud::triangulate(vertices, max_edge_mm, file)?;
    check_triangle_count(mesh.triangle_count(), file)?;
    if info.merged > 0 {
        warnings.push(format!(
            "{file}: {} point(s) shared their XY with another; the highest of each was kept",
            info.merged
        ));
    }
    Ok(ImportedMesh {
        mesh,
        format,
        units,
        up_axis,
        warnings,
        cloud: Some(info),
    })
}

/// The file's units to mm and its up axis to the printer's +Z.
fn to_printer_frame(vertices: &mut [DVec3], scale: f64, up_axis: UpAxis) {
    for v in vertices {
        let p = *v * scale;
        *v = match up_axis {
            UpAxis::Z => p,
            // +90 deg about X takes the file's +Y to the printer's +Z.
            UpAxis::Y => DVec3::new(p.x, -p.z, p.y),
        };
    }
}

/// The first vertex with a non-finite coordinate, as an error.
fn check_finite(vertices: &[DVec3], file: &str) -> Result<(), MeshError> {
    match vertices.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((vertex, v)) => Err(MeshError::NonFiniteVertex {
            file: file.into(),
            vertex,
            line: None,
            value: v
                .to_array()
                .into_iter()
                .find(|c| !c.is_finite())
                .unwrap_or(f64::NAN),
        }),
        None => Ok(()),
    }
}

/// Refuses files past [`super::MAX_SCAN_BYTES`] before reading them.
fn check_scan_size(len: usize, file: &str) -> Result<(), MeshError> {
    if len > super::MAX_SCAN_BYTES {
        return Err(MeshError::invalid(
            file,
            format!(
                "the file is {:.1} MB, more than the {:.0} MB this program reads; decimate the \
                 scan (e.g. MeshLab's quadric edge collapse) or crop it to the printed area",
                len as f64 / 1e6,
                super::MAX_SCAN_BYTES as f64 / 1e6
            ),
        ));
    }
    Ok(())
}

/// Refuses meshes past [`super::MAX_TRIANGLES`].
fn check_triangle_count(n: usize, file: &str) -> Result<(), MeshError> {
    if n > super::MAX_TRIANGLES {
        return Err(MeshError::invalid(
            file,
            format!(
                "{n} triangles, more than the {} this program plans on; decimate the scan",
                super::MAX_TRIANGLES
            ),
        ));
    }
    Ok(())
}

/// The shared steps after parsing. Parsers already report bad values with
/// their line or element; these checks are the backstop that guarantees the
/// invariants downstream stages rely on (finite, in range, non-degenerate).
fn finish(
    parsed: Parsed,
    file: &str,
    scale: f64,
    up_axis: UpAxis,
    weld: bool,
) -> Result<(TriMesh, Vec<String>), MeshError> {
    let Parsed {
        mut vertices,
        triangles,
        mut warnings,
    } = parsed;
    check_finite(&vertices, file)?;
    let n = vertices.len();
    // remap[i]: the welded index of vertex i (bit-identical positions merge).
    let remap: Option<Vec<u32>> = if weld {
        let mut welder = Welder::with_capacity(n);
        let mut remap = Vec::with_capacity(n);
        for &v in &vertices {
            // At most n <= u32::MAX + 1 vertices were indexable, so this holds.
            remap.push(welder.index(v).unwrap_or(u32::MAX));
        }
        if welder.vertices.len() < n {
            vertices = welder.vertices;
            Some(remap)
        } else {
            None
        }
    } else {
        None
    };
    let mut kept = Vec::with_capacity(triangles.len());
    let mut degenerate = 0usize;
    for (face, tri) in triangles.into_iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::IndexOutOfRange {
                file: file.into(),
                face,
                line: None,
                index: i64::from(bad),
                vertex_count: n,
            });
        }
        let tri = match &remap {
            Some(r) => tri.map(|i| r[i as usize]),
            None => tri,
        };
        let [a, b, c] = tri.map(|i| vertices[i as usize]);
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || zero_area(a, b, c) {
            degenerate += 1;
        } else {
            kept.push(tri);
        }
    }
    if degenerate > 0 {
        warnings.push(format!(
            "{file}: skipped {degenerate} degenerate triangle(s) (repeated vertex or zero area)"
        ));
    }
    if kept.is_empty() {
        return Err(MeshError::Empty { file: file.into() });
    }
    check_triangle_count(kept.len(), file)?;
    to_printer_frame(&mut vertices, scale, up_axis);
    Ok((
        TriMesh {
            vertices,
            triangles: kept,
        },
        warnings,
    ))
}

/// Zero area relative to the triangle's size: the sine of its largest angle
/// vanishes to round-off, so scaling the scan never changes the verdict.
fn zero_area(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let (ab, ac, bc) = (b - a, c - a, c - b);
    let longest = ab
        .length_squared()
        .max(ac.length_squared())
        .max(bc.length_squared());
    ab.cross(ac).length() <= 1e-12 * longest
}

/// FxHash (rustc's hasher) with a final mix: welding hashes millions of
/// positions, and the keys are not attacker-chosen collisions we need
/// SipHash against. The mix matters: coordinates read as f32 have 29 zero
/// low bits as f64, and Fx's multiply leaves its low bits (the hash map's
/// bucket index) a function of the input's low bits only, so without it a
/// real scan's vertices pile into a few buckets (a 10 M triangle PLY took
/// 19.7 s to weld instead of 1.8 s).
#[derive(Default)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }
    fn finish(&self) -> u64 {
        // Fold the high bits, which depend on every input bit, into the low.
        let h = self.0 ^ (self.0 >> 32);
        h.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (h >> 29)
    }
}

/// Merges bit-identical positions into one vertex. STL stores each facet's
/// corners separately and glTF exporters split vertices at normal/UV seams;
/// unwelded, every edge would look like a boundary to the fiducial detector.
#[derive(Default)]
pub(super) struct Welder {
    map: HashMap<[u64; 3], u32, BuildHasherDefault<FxHasher>>,
    pub vertices: Vec<DVec3>,
}

impl Welder {
    pub fn with_capacity(n: usize) -> Self {
        Welder {
            map: HashMap::with_capacity_and_hasher(n, Default::default()),
            vertices: Vec::with_capacity(n),
        }
    }

    /// The index of `p`, `None` once more than `u32::MAX` vertices exist.
    pub fn index(&mut self, p: DVec3) -> Option<u32> {
        // +0.0 makes -0.0 and 0.0 the same key: the same point in space.
        let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
        if let Some(&i) = self.map.get(&key) {
            return Some(i);
        }
        let i = u32::try_from(self.vertices.len()).ok()?;
        self.vertices.push(p);
        self.map.insert(key, i);
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use crate::mesh::{MAX_SCAN_BYTES, MAX_TRIANGLES};

    #[test]
    fn weld_hash_spreads_f32_coordinates_over_the_low_bits() {
        use std::hash::{BuildHasher, BuildHasherDefault};
        let build = BuildHasherDefault::<super::FxHasher>::default();
        // A scan read as f32: 4096 positions on a 0.1 mm grid with noise.
        let mut low = std::collections::HashSet::new();
        for i in 0..64 {
            for j in 0..64 {
                let p = [
                    i as f32 * 0.1 + 0.0013 * j as f32,
                    j as f32 * 0.1,
                    2.5 + 0.01 * i as f32,
                ];
                let key = p.map(|c| (c as f64).to_bits());
                low.insert(build.hash_one(key) & 0xfff);
            }
        }
        // 4096 keys into 4096 buckets: a good hash fills about 63%.
        assert!(
            low.len() > 2000,
            "only {} of 4096 low-bit buckets used",
            low.len()
        );
    }

    #[test]
    fn limits_are_errors_that_say_what_to_do() {
        let e = check_scan_size(MAX_SCAN_BYTES + 1, "huge.stl")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("huge.stl: ") && e.contains("MB") && e.contains("decimate"),
            "{e}"
        );
        assert!(check_scan_size(MAX_SCAN_BYTES, "ok.stl").is_ok());
        let e = check_triangle_count(MAX_TRIANGLES + 1, "big.ply")
            .unwrap_err()
            .to_string();
        assert!(e.contains("20000001 triangles"), "{e}");
        assert!(check_triangle_count(MAX_TRIANGLES, "ok.ply").is_ok());
    }

    use super::*;

    #[test]
    fn extension_wins_over_content() {
        assert_eq!(detect_format(b"solid x", "a.OBJ"), Some(MeshFormat::Obj));
        assert_eq!(detect_format(b"", "scan.glb"), Some(MeshFormat::Glb));
    }

    #[test]
    fn sniffs_each_format() {
        assert_eq!(detect_format(b"glTF\x02\0\0\0", "x"), Some(MeshFormat::Glb));
        assert_eq!(
            detect_format(b" {\"asset\":{\"version\":\"2.0\"}}", "x"),
            Some(MeshFormat::Gltf)
        );
        assert_eq!(
            detect_format(b"ply\nformat ascii 1.0\n", "x"),
            Some(MeshFormat::Ply)
        );
        assert_eq!(
            detect_format(b"solid a\nendsolid a\n", "x"),
            Some(MeshFormat::Stl)
        );
        assert_eq!(
            detect_format(b"# scan\nmtllib a.mtl\nv 0 0 0\n", "x"),
            Some(MeshFormat::Obj)
        );
        let mut binary = vec![0u8; 84 + 50];
        binary[80] = 1;
        assert_eq!(detect_format(&binary, "x"), Some(MeshFormat::Stl));
        assert_eq!(detect_format(b"hello world", "x"), None);
        assert_eq!(detect_format(b"{\"a\":1}", "x"), None);
    }

    #[test]
    fn degenerate_triangles_are_counted_in_one_warning() {
        let parsed = Parsed {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(2.0, 0.0, 0.0)],
            triangles: vec![[0, 1, 2], [0, 0, 1], [0, 1, 3]],
            warnings: vec![],
        };
        let (mesh, warnings) = finish(parsed, "t", 1.0, UpAxis::Z, false).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("2 degenerate"), "{warnings:?}");
    }

    #[test]
    fn up_axis_y_turns_y_into_z() {
        let parsed = Parsed {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
            warnings: vec![],
        };
        let (mesh, _) = finish(parsed, "t", 2.0, UpAxis::Y, false).unwrap();
        assert_eq!(mesh.vertices[2], DVec3::new(0.0, 0.0, 2.0));
    }

    #[test]
    fn welder_merges_signed_zeros() {
        let mut w = Welder::default();
        assert_eq!(w.index(DVec3::new(0.0, 1.0, 2.0)), Some(0));
        assert_eq!(w.index(DVec3::new(-0.0, 1.0, 2.0)), Some(0));
        assert_eq!(w.index(DVec3::new(0.0, 1.0, 3.0)), Some(1));
    }
}
