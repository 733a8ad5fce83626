//! Integration tests: importers. Every file is built in memory by the small
//! writers below, so each variant the importers claim to read is pinned
//! without checked-in binaries.

use std::collections::BTreeSet;

use base64::Engine as _;
use glam::DQuat;
use pcpp::demo::glb_container as glb;
use pcpp::mesh::{
    detect_format, import_mesh, ImportOptions, ImportedMesh, MeshError, MeshFormat, ScanUnits,
    TriMesh, UpAxis,
};
use pcpp::{DMat4, DVec3};

/// The file's own coordinates, untouched: lets every format be compared.
const RAW: ImportOptions = ImportOptions {
    units: Some(ScanUnits::Mm),
    up_axis: Some(UpAxis::Z),
    max_edge_mm: None,
};

/// A small bumpy grid of quads; all coordinates are exact in f32 so binary
/// STL and glTF store the same values as the text formats.
struct Shape {
    vertices: Vec<[f64; 3]>,
    quads: Vec<[u32; 4]>,
}

impl Shape {
    fn grid() -> Shape {
        let n = 4u32;
        let mut vertices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let h = ((i * j + i) % 3) as f64 * 0.25;
                vertices.push([i as f64 * 0.5, j as f64 * 0.75, h]);
            }
        }
        let mut quads = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                quads.push([a, a + 1, a + 1 + n, a + n]);
            }
        }
        Shape { vertices, quads }
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        self.quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect()
    }

    fn f32_vertices(&self) -> Vec<[f32; 3]> {
        self.vertices.iter().map(|v| v.map(|c| c as f32)).collect()
    }
}

pub(crate) fn import(bytes: &[u8], file: &str, options: &ImportOptions) -> ImportedMesh {
    import_mesh(bytes, file, options).unwrap_or_else(|e| panic!("{file}: {e}"))
}

pub(crate) fn error(bytes: &[u8], file: &str) -> String {
    match import_mesh(bytes, file, &ImportOptions::DEFAULT) {
        Ok(m) => panic!("{file}: imported {} triangles", m.mesh.triangle_count()),
        Err(e) => e.to_string(),
    }
}

/// The error names the file and says each of `needles`.
pub(crate) fn assert_error(bytes: &[u8], file: &str, needles: &[&str]) {
    let e = error(bytes, file);
    assert!(e.starts_with(file), "message does not name the file: {e}");
    for needle in needles {
        assert!(e.contains(needle), "'{needle}' not in: {e}");
    }
}

/// Triangles as vertex triples, each rotated to start at its smallest
/// corner so winding is compared but the starting corner is not.
pub(crate) fn triangle_set(mesh: &TriMesh) -> BTreeSet<[u64; 9]> {
    (0..mesh.triangle_count())
        .map(|t| {
            let c = mesh.triangle(t).map(|v| v.to_array().map(f64::to_bits));
            let first = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
            let mut key = [0u64; 9];
            for k in 0..3 {
                key[3 * k..3 * k + 3].copy_from_slice(&c[(first + k) % 3]);
            }
            key
        })
        .collect()
}

fn shape_set(shape: &Shape) -> BTreeSet<[u64; 9]> {
    let mesh = TriMesh {
        vertices: shape
            .vertices
            .iter()
            .map(|&v| DVec3::from_array(v))
            .collect(),
        triangles: shape.triangles(),
    };
    triangle_set(&mesh)
}

// ---------------------------------------------------------------- writers

/// OBJ with quads in every corner form, half of them by negative indices,
/// and the statements a scanner adds around them.
fn obj_bytes(shape: &Shape) -> Vec<u8> {
    let mut s = String::from("# scanner export\nmtllib scan.mtl\no scan\n");
    for v in &shape.vertices {
        s += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    s += "vt 0 0\nvn 0 0 1\ng surface\nusemtl grey\ns off\n";
    let n = shape.vertices.len() as i64;
    for (k, q) in shape.quads.iter().enumerate() {
        s += "f";
        for &i in q {
            let index = if k % 2 == 0 {
                i64::from(i) + 1
            } else {
                i64::from(i) - n
            };
            s += &match k % 4 {
                0 => format!(" {index}"),
                1 => format!(" {index}/1"),
                2 => format!(" {index}//1"),
                _ => format!(" {index}/1/1"),
            };
        }
        s += "\n";
    }
    s += "l 1 2\n";
    s.into_bytes()
}

fn ply_ascii(shape: &Shape) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment hand made\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        shape.vertices.len(),
        shape.quads.len()
    );
    for v in &shape.vertices {
        s += &format!("{} {} {} 200\n", v[0], v[1], v[2]);
    }
    for q in &shape.quads {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    s.into_bytes()
}

struct Bin {
    bytes: Vec<u8>,
    big_endian: bool,
}

impl Bin {
    fn put<const N: usize>(&mut self, mut le: [u8; N]) {
        if self.big_endian {
            le.reverse();
        }
        self.bytes.extend_from_slice(&le);
    }
}

/// Binary PLY with mixed coordinate types, extra properties on vertex and
/// face, and an extra element holding a list. `aliases` switches to the
/// int8..float64 type names and `vertex_index` with ushort indices.
fn ply_binary(shape: &Shape, big_endian: bool, aliases: bool) -> Vec<u8> {
    let order = if big_endian { "big" } else { "little" };
    let header = if aliases {
        format!(
            "ply\nformat binary_{order}_endian 1.0\nobj_info aliases\nelement vertex {}\n\
             property float64 x\nproperty uint8 quality\nproperty float32 y\n\
             property float32 z\nelement face {}\nproperty list int32 uint16 vertex_index\n\
             property int16 flags\nelement material 1\nproperty list uint8 float64 k\n\
             end_header\n",
            shape.vertices.len(),
            shape.quads.len()
        )
    } else {
        format!(
            "ply\nformat binary_{order}_endian 1.0\ncomment mixed\nelement vertex {}\n\
             property float x\nproperty uchar quality\nproperty double y\nproperty float z\n\
             property list uchar short extra\nelement face {}\nproperty uchar flags\n\
             property list uchar uint vertex_indices\nproperty float weight\n\
             element material 1\nproperty list ushort int ids\nproperty double shine\n\
             end_header\n",
            shape.vertices.len(),
            shape.quads.len()
        )
    };
    let mut b = Bin {
        bytes: header.into_bytes(),
        big_endian,
    };
    for v in &shape.vertices {
        if aliases {
            b.put(v[0].to_le_bytes());
            b.put([7u8]);
            b.put((v[1] as f32).to_le_bytes());
            b.put((v[2] as f32).to_le_bytes());
        } else {
            b.put((v[0] as f32).to_le_bytes());
            b.put([7u8]);
            b.put(v[1].to_le_bytes());
            b.put((v[2] as f32).to_le_bytes());
            b.put([2u8]);
            b.put(1i16.to_le_bytes());
            b.put((-1i16).to_le_bytes());
        }
    }
    for q in &shape.quads {
        if aliases {
            b.put(4i32.to_le_bytes());
            for &i in q {
                b.put((i as u16).to_le_bytes());
            }
            b.put(3i16.to_le_bytes());
        } else {
            b.put([1u8]);
            b.put([4u8]);
            for &i in q {
                b.put(i.to_le_bytes());
            }
            b.put(0.5f32.to_le_bytes());
        }
    }
    if aliases {
        b.put([2u8]);
        b.put(1.0f64.to_le_bytes());
        b.put(2.0f64.to_le_bytes());
    } else {
        b.put(3u16.to_le_bytes());
        for k in 0..3i32 {
            b.put(k.to_le_bytes());
        }
        b.put(0.25f64.to_le_bytes());
    }
    b.bytes
}

fn stl_ascii(shape: &Shape) -> Vec<u8> {
    let mut s = String::from("solid grid\n");
    for t in shape.triangles() {
        s += "  facet normal 0 0 1\n    outer loop\n";
        for i in t {
            let v = shape.vertices[i as usize];
            s += &format!("      vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid grid\n";
    s.into_bytes()
}

fn stl_binary(shape: &Shape, header: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..header.len()].copy_from_slice(header);
    let triangles = shape.triangles();
    b.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    let v = shape.f32_vertices();
    for t in triangles {
        b.extend_from_slice(&[0u8; 12]);
        for i in t {
            for c in v[i as usize] {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

/// Assembles glTF buffer views and accessors; `json` then wraps them with
/// the caller's meshes, nodes and scenes.
#[derive(Default)]
struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl GltfBuilder {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() & 3 != 0 {
            self.bin.push(0);
        }
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in p {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
            p.len()
        ));
        self.accessors.len() - 1
    }

    /// `bytes_per_index` 1, 2 or 4 (UNSIGNED_BYTE, _SHORT, _INT).
    fn indices(&mut self, idx: &[u32], bytes_per_index: usize) -> usize {
        let (bytes, ty): (Vec<u8>, u32) = match bytes_per_index {
            1 => (idx.iter().map(|&i| i as u8).collect(), 5121),
            2 => (
                idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
                5123,
            ),
            _ => (idx.iter().flat_map(|&i| i.to_le_bytes()).collect(), 5125),
        };
        let view = self.view(&bytes);
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":{ty},"count":{},"type":"SCALAR"}}"#,
            idx.len()
        ));
        self.accessors.len() - 1
    }

    fn json(&self, rest: &str, uri: Option<&str>) -> String {
        let uri = uri.map(|u| format!(r#","uri":"{u}""#)).unwrap_or_default();
        format!(
            r#"{{"asset":{{"version":"2.0","generator":"pcpp tests"}},{rest},
            "accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{}{uri}}}]}}"#,
            self.accessors.join(","),
            self.views.join(","),
            self.bin.len()
        )
    }

    fn gltf(&self, rest: &str) -> Vec<u8> {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        self.json(rest, Some(&uri)).into_bytes()
    }

    fn glb(&self, rest: &str) -> Vec<u8> {
        glb(self.json(rest, None).as_bytes(), &self.bin)
    }
}

const ONE_NODE: &str = r#""scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}]"#;

/// The grid as an indexed glTF primitive.
fn gltf_grid(shape: &Shape, bytes_per_index: usize) -> GltfBuilder {
    let mut g = GltfBuilder::default();
    g.positions(&shape.f32_vertices());
    let idx: Vec<u32> = shape.triangles().into_iter().flatten().collect();
    g.indices(&idx, bytes_per_index);
    g
}

fn grid_mesh_json() -> String {
    r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#.into()
}

/// The grid unindexed: three positions per triangle, as exporters write
/// meshes with per-face normals.
fn gltf_grid_unindexed(shape: &Shape) -> Vec<u8> {
    let v = shape.f32_vertices();
    let soup: Vec<[f32; 3]> = shape
        .triangles()
        .into_iter()
        .flatten()
        .map(|i| v[i as usize])
        .collect();
    let mut g = GltfBuilder::default();
    g.positions(&soup);
    g.gltf(&format!(
        r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":4}}]}}]"#
    ))
}

// ------------------------------------------------------------ same shape

#[test]
fn every_format_yields_the_same_triangles() {
    let shape = Shape::grid();
    let expected = shape_set(&shape);
    let rest = format!("{ONE_NODE},{}", grid_mesh_json());
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("grid.obj", obj_bytes(&shape)),
        ("grid.ply", ply_ascii(&shape)),
        ("grid_le.ply", ply_binary(&shape, false, false)),
        ("grid_be.ply", ply_binary(&shape, true, false)),
        ("grid_le_alias.ply", ply_binary(&shape, false, true)),
        ("grid_be_alias.ply", ply_binary(&shape, true, true)),
        ("grid_ascii.stl", stl_ascii(&shape)),
        ("grid_bin.stl", stl_binary(&shape, b"exported by a scanner")),
        ("grid_solid.stl", stl_binary(&shape, b"solid grid binary")),
        ("grid8.gltf", gltf_grid(&shape, 1).gltf(&rest)),
        ("grid16.gltf", gltf_grid(&shape, 2).gltf(&rest)),
        ("grid32.glb", gltf_grid(&shape, 4).glb(&rest)),
        ("grid_soup.gltf", gltf_grid_unindexed(&shape)),
    ];
    for (name, bytes) in &files {
        let m = import(bytes, name, &RAW);
        assert_eq!(triangle_set(&m.mesh), expected, "{name}");
        assert_eq!(m.mesh.triangle_count(), 18, "{name}");
        // Welding (STL, unindexed glTF) gives back the shared vertices.
        assert_eq!(m.mesh.vertices.len(), 16, "{name}");
        assert!(
            warnings_but_units(&m).is_empty(),
            "{name}: {:?}",
            m.warnings
        );
    }
}

#[test]
fn formats_are_sniffed_without_an_extension() {
    let shape = Shape::grid();
    let rest = format!("{ONE_NODE},{}", grid_mesh_json());
    let cases = [
        (obj_bytes(&shape), MeshFormat::Obj),
        (ply_ascii(&shape), MeshFormat::Ply),
        (ply_binary(&shape, true, false), MeshFormat::Ply),
        (stl_ascii(&shape), MeshFormat::Stl),
        (stl_binary(&shape, b"solid but binary"), MeshFormat::Stl),
        (stl_binary(&shape, b""), MeshFormat::Stl),
        (gltf_grid(&shape, 2).gltf(&rest), MeshFormat::Gltf),
        (gltf_grid(&shape, 2).glb(&rest), MeshFormat::Glb),
    ];
    let expected = shape_set(&shape);
    for (bytes, format) in cases {
        assert_eq!(detect_format(&bytes, "upload"), Some(format));
        let m = import(&bytes, "upload", &RAW);
        assert_eq!(m.format, format);
        assert_eq!(triangle_set(&m.mesh), expected, "{format:?}");
    }
}

/// QA round 2: an OFF mesh got only the list of formats, and MeshLab's
/// binary point set (.pts, a name text clouds use too) "open the scan's
/// own file": each is named, with how to convert it.
#[test]
fn formats_not_read_are_named_with_how_to_convert_them() {
    let off = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let e = import_mesh(off, "elephant.off", &RAW)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("elephant.off: not a scan this program reads")
            && e.contains(
                "; this is an OFF mesh (Geomview, MeshLab, CGAL): export it as PLY, OBJ or STL"
            ),
        "{e}"
    );
    let mut pts = b"[Expe/PointSet/Binary/0.1]\nproperty position 12\nnofpoints 1\ndata\n".to_vec();
    pts.extend([0u8; 12]);
    let e = import_mesh(&pts, "chameleon.pts", &RAW)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("chameleon.pts: a binary Expe point set (MeshLab's .pts), which this program does not read"),
        "{e}"
    );
}

// ------------------------------------------------------------------ units

#[test]
fn centimetres_are_ten_times_millimetres() {
    let shape = Shape::grid();
    let bytes = ply_binary(&shape, false, false);
    let mm = import(&bytes, "g.ply", &ImportOptions::DEFAULT);
    assert_eq!(mm.units, ScanUnits::Mm);
    assert_eq!(mm.up_axis, UpAxis::Z);
    let cm = import(
        &bytes,
        "g.ply",
        &ImportOptions {
            units: Some(ScanUnits::Cm),
            up_axis: None,
            max_edge_mm: None,
        },
    );
    assert_eq!(cm.units, ScanUnits::Cm);
    for (a, b) in mm.mesh.vertices.iter().zip(&cm.mesh.vertices) {
        assert_eq!(*a * 10.0, *b);
    }
    let inches = import(
        &bytes,
        "g.ply",
        &ImportOptions {
            units: Some(ScanUnits::In),
            up_axis: None,
            max_edge_mm: None,
        },
    );
    let (_, hi) = inches.mesh.bbox().unwrap();
    assert!((hi.x - 1.5 * 25.4).abs() < 1e-9, "{hi}");
}

#[test]
fn gltf_defaults_to_metres_and_y_up() {
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let bytes = g.gltf(&format!(
        r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}]"#
    ));
    let m = import(&bytes, "t.gltf", &ImportOptions::DEFAULT);
    assert_eq!((m.units, m.up_axis), (ScanUnits::M, UpAxis::Y));
    assert_eq!(m.format, MeshFormat::Gltf);
    // glTF +Y up becomes the printer's +Z, metres become millimetres.
    assert_eq!(
        m.mesh.vertices,
        vec![
            DVec3::ZERO,
            DVec3::new(1000.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 1000.0)
        ]
    );
    // A +90 deg turn keeps the triangle counter-clockwise seen from +Y: its
    // normal, +Z in the file, now points to -Y.
    let [a, b, c] = m.mesh.triangle(0);
    assert!((b - a).cross(c - a).y < 0.0);
    let glb = g.glb(&format!(
        r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}]"#
    ));
    let m = import(&glb, "t.glb", &ImportOptions::DEFAULT);
    assert_eq!((m.format, m.units), (MeshFormat::Glb, ScanUnits::M));
    assert_eq!(m.mesh.vertices[2], DVec3::new(0.0, 0.0, 1000.0));
}

// ------------------------------------------------------------ glTF scenes

fn unit_triangle() -> GltfBuilder {
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.indices(&[0, 1, 2], 2);
    g
}

const TRIANGLE_MESH: &str =
    r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}]"#;

fn contains_point(mesh: &TriMesh, p: DVec3) -> bool {
    mesh.vertices.iter().any(|v| v.distance(p) < 1e-5)
}

#[test]
fn nested_node_transforms_and_shared_meshes() {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // Node 0 (translate) > node 1 (rotate 90 deg about Z) > node 2 (scale 2
    // then translate, draws the mesh); node 3 draws the same mesh again through a matrix.
    let nodes = format!(
        r#""scene":0,"scenes":[{{"nodes":[0,3]}}],"nodes":[
        {{"translation":[10,0,0],"children":[1]}},
        {{"rotation":[0,0,{s},{s}],"children":[2]}},
        {{"translation":[0,0,1],"scale":[2,2,2],"mesh":0}},
        {{"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1],"mesh":0}}]"#
    );
    let bytes = unit_triangle().gltf(&format!("{nodes},{TRIANGLE_MESH}"));
    let m = import(&bytes, "nested.gltf", &RAW);
    assert_eq!(m.mesh.triangle_count(), 2);
    let expected = [
        // (1,0,0) scaled to (2,0,0), lifted to (2,0,1), turned to (0,2,1),
        // moved to (10,2,1)
        DVec3::new(10.0, 0.0, 1.0),
        DVec3::new(10.0, 2.0, 1.0),
        DVec3::new(8.0, 0.0, 1.0),
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::new(1.0, 0.0, 5.0),
        DVec3::new(0.0, 1.0, 5.0),
    ];
    for p in expected {
        assert!(
            contains_point(&m.mesh, p),
            "{p} missing: {:?}",
            m.mesh.vertices
        );
    }
    // Cross-check the first instance against glam's composition.
    let world = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0))
        * DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2))
        * DMat4::from_scale_rotation_translation(
            DVec3::splat(2.0),
            DQuat::IDENTITY,
            DVec3::new(0.0, 0.0, 1.0),
        );
    assert!(contains_point(
        &m.mesh,
        world.transform_point3(DVec3::new(0.0, 1.0, 0.0))
    ));
}

#[test]
fn scene_selection() {
    // Default scene 1 draws only node 1; scene 0 would draw node 0.
    let nodes = r#""scene":1,"scenes":[{"nodes":[0]},{"nodes":[1]}],"nodes":[
        {"mesh":0},{"mesh":0,"translation":[0,0,7]}]"#;
    let m = import(
        &unit_triangle().gltf(&format!("{nodes},{TRIANGLE_MESH}")),
        "s.gltf",
        &RAW,
    );
    assert_eq!(m.mesh.triangle_count(), 1);
    assert!(m.mesh.vertices.iter().all(|v| v.z == 7.0));
    // No default: scene 0.
    let nodes = r#""scenes":[{"nodes":[0]},{"nodes":[1]}],"nodes":[
        {"mesh":0},{"mesh":0,"translation":[0,0,7]}]"#;
    let m = import(
        &unit_triangle().gltf(&format!("{nodes},{TRIANGLE_MESH}")),
        "s.gltf",
        &RAW,
    );
    assert!(m.mesh.vertices.iter().all(|v| v.z == 0.0));
    // No scenes at all: every mesh once.
    let m = import(&unit_triangle().gltf(TRIANGLE_MESH), "s.gltf", &RAW);
    assert_eq!(m.mesh.triangle_count(), 1);
}

#[test]
fn strips_fans_and_skipped_lines() {
    let mut g = GltfBuilder::default();
    g.positions(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let meshes = r#""meshes":[{"primitives":[
        {"attributes":{"POSITION":0},"mode":5},
        {"attributes":{"POSITION":0},"mode":1}]}]"#;
    let m = import(&g.gltf(&format!("{ONE_NODE},{meshes}")), "strip.gltf", &RAW);
    assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [2, 1, 3]]);
    assert_eq!(warnings_but_units(&m).len(), 1);
    assert!(
        m.warnings[0].contains("points or lines"),
        "{:?}",
        m.warnings
    );
    let meshes = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":6}]}]"#;
    let m = import(&g.gltf(&format!("{ONE_NODE},{meshes}")), "fan.gltf", &RAW);
    assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

/// The warnings of a test's mesh of a few units, but the hint that a scan
/// so small may be in other units.
fn warnings_but_units(m: &ImportedMesh) -> Vec<&String> {
    m.warnings
        .iter()
        .filter(|w| !w.contains("check its units"))
        .collect()
}

#[test]
fn degenerate_triangles_are_kept_with_one_warning() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 4\n";
    let m = import(obj, "d.obj", &ImportOptions::DEFAULT);
    // Kept: the segments they are are surface the nozzle must clear.
    assert_eq!(m.mesh.triangle_count(), 3);
    assert_eq!(warnings_but_units(&m).len(), 1);
    assert!(
        m.warnings[0].contains("2 degenerate triangle(s)") && m.warnings[0].contains("kept"),
        "{:?}",
        m.warnings
    );
}

// ---------------------------------------------------------- hostile input

#[test]
fn empty_and_garbage_files() {
    for name in ["e.obj", "e.ply", "e.stl", "e.gltf", "e.glb", "e"] {
        assert_error(b"", name, &["empty"]);
        assert_error(b" \n\t\n", name, &["empty"]);
    }
    assert_error(
        b"\x01\x02garbage",
        "x.bin",
        &["not a scan this program reads"],
    );
    assert_error(b"# only a comment\n", "c.obj", &["no triangles"]);
    assert_error(b"solid x\nendsolid x\n", "c.stl", &["no triangles"]);
    assert_error(
        b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
          property float z\nend_header\n",
        "c.ply",
        &["no triangles"],
    );
    assert_error(b"not json", "g.gltf", &["not a valid glTF"]);
    assert_error(b"glTF\x02\0\0\0", "g.glb", &["not a valid GLB", "needs 12"]);
    assert_error(
        br#"{"asset":{"version":"2.0"}}"#,
        "g.gltf",
        &["the file draws no mesh"],
    );
}

#[test]
fn obj_hostile() {
    assert_error(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
        "h.obj",
        &[":4:", "vertex index 4"],
    );
    assert_error(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
        "h.obj",
        &[":4:", "-4"],
    );
    assert_error(
        b"v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n",
        "h.obj",
        &[":2:", "vertex 2", "non-finite"],
    );
    assert_error(b"v 0 0 NaN\n", "h.obj", &[":1:", "non-finite"]);
    // Truncated in the middle of a vertex line.
    assert_error(b"v 0 0 0\nv 1 0 0\nv 0 1", "h.obj", &[":3:", "needs x y z"]);
}

fn ply_header(format: &str, vertices: u64, faces: u64) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n\
         property list uchar int vertex_indices\nend_header\n"
    )
}

#[test]
fn ply_hostile() {
    let shape = Shape::grid();
    let good = ply_binary(&shape, false, false);
    // Truncated body.
    assert_error(&good[..good.len() - 30], "h.ply", &["truncated"]);
    // Huge declared counts are refused before allocating.
    let mut huge = ply_header("binary_little_endian", 4_000_000_000, 1).into_bytes();
    huge.extend_from_slice(&[0u8; 64]);
    assert_error(
        &huge,
        "h.ply",
        &["declares 4000000000 'vertex'", "only 64 bytes follow"],
    );
    let huge = ply_header("ascii", u64::MAX, 1) + "0 0 0\n";
    assert_error(
        huge.as_bytes(),
        "h.ply",
        &["declares 18446744073709551615 'vertex'"],
    );
    // Wrong (too small) count: the face list runs into the vertex data.
    let ascii = ply_header("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    assert_error(
        ascii.as_bytes(),
        "h.ply",
        &["face 0 refers to vertex index 7", "3 vertices"],
    );
    let ascii = ply_header("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n";
    assert_error(ascii.as_bytes(), "h.ply", &["vertex index -1"]);
    let ascii = ply_header("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 inf\n3 0 1 2\n";
    assert_error(
        ascii.as_bytes(),
        "h.ply",
        &["h.ply:12:", "vertex 2", "non-finite"],
    );
    // Declared counts larger than the data.
    let ascii = ply_header("ascii", 3, 2) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_error(
        ascii.as_bytes(),
        "h.ply",
        &["'face' element 1 of 2", "truncated"],
    );
    // A binary NaN names the vertex.
    let mut b = ply_header("binary_big_endian", 3, 1).into_bytes();
    for v in [[0.0f32, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            b.extend_from_slice(&c.to_be_bytes());
        }
    }
    b.extend_from_slice(&[3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2]);
    assert_error(&b, "h.ply", &["vertex 1", "non-finite"]);
    assert_error(b"ply\nformat ascii 1.0\n", "h.ply", &["end_header"]);
    assert_error(
        b"ply\nformat utf8 1.0\nend_header\n",
        "h.ply",
        &[":2:", "unknown PLY format"],
    );
}

#[test]
fn stl_hostile() {
    let shape = Shape::grid();
    let good = stl_binary(&shape, b"binary");
    assert_error(
        &good[..good.len() - 7],
        "h.stl",
        &["declares 18 triangles", "truncated"],
    );
    // A damaged binary file whose header says "solid".
    let solid = stl_binary(&shape, b"solid but binary");
    assert_error(
        &solid[..solid.len() - 1],
        "h.stl",
        &["declares 18 triangles"],
    );
    let mut huge = good[..84].to_vec();
    huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_error(
        &huge,
        "h.stl",
        &["declares 4294967295 triangles", "file has 84 bytes"],
    );
    assert_error(&good[..50], "h.stl", &["truncated", "50 bytes"]);
    let mut nan = good.clone();
    // Facet 1, vertex 2, y coordinate.
    let at = 84 + 50 + 12 + 2 * 12 + 4;
    nan[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
    assert_error(&nan, "h.stl", &["facet 1 vertex 2", "non-finite"]);
    let ascii = String::from_utf8(stl_ascii(&shape)).unwrap_or_default();
    assert_error(
        &ascii.as_bytes()[..ascii.len() / 2],
        "h.stl",
        &["truncated"],
    );
    let bad = ascii.replacen("vertex 5e-1", "vertex nan", 1);
    assert_error(bad.as_bytes(), "h.stl", &["h.stl:", "non-finite"]);
}

#[test]
fn gltf_hostile() {
    let shape = Shape::grid();
    let rest = format!("{ONE_NODE},{}", grid_mesh_json());
    // Index out of range.
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.indices(&[0, 1, 3], 2);
    assert_error(
        &g.gltf(&format!("{ONE_NODE},{TRIANGLE_MESH}")),
        "h.gltf",
        &[
            "mesh 0 primitive 0",
            "index 2 refers to vertex 3",
            "3 elements",
        ],
    );
    // NaN position.
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]]);
    assert_error(
        &g.glb(&format!(
            r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}]"#
        )),
        "h.glb",
        &["POSITION element 1", "non-finite"],
    );
    // Truncated GLB and a binary chunk shorter than the buffer.
    let good = gltf_grid(&shape, 2).glb(&rest);
    assert_error(&good[..good.len() - 10], "h.glb", &["h.glb:"]);
    let g = gltf_grid(&shape, 2);
    let short = glb(g.json(&rest, None).as_bytes(), &g.bin[..40]);
    assert_error(&short, "h.glb", &["declares byteLength"]);
    // Accessor count far beyond its buffer view.
    let json = g
        .json(&rest, None)
        .replace(r#""count":16,"#, r#""count":4000000000,"#);
    assert_error(
        &glb(json.as_bytes(), &g.bin),
        "h.glb",
        &["declares 4000000000 elements"],
    );
    // External buffers are named, never opened.
    assert_error(
        g.json(&rest, Some("scan.bin")).as_bytes(),
        "h.gltf",
        &["'scan.bin'", "external"],
    );
    // A node cycle.
    let cyclic = r#""scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"children":[1]},{"children":[0]}]"#;
    let e = import_mesh(
        unit_triangle()
            .gltf(&format!("{cyclic},{TRIANGLE_MESH}"))
            .as_slice(),
        "h.gltf",
        &RAW,
    );
    assert!(e.is_err(), "cycle accepted");
}

/// Found by the corruption sweep below: `gltf-json` indexed the accessor
/// list with a POSITION index before validating it.
#[test]
fn regression_gltf_position_accessor_out_of_range_panicked() {
    let meshes = r#""meshes":[{"primitives":[{"attributes":{"POSITION":9}}]}]"#;
    assert_error(
        &unit_triangle().glb(&format!("{ONE_NODE},{meshes}")),
        "h.glb",
        &["refers to accessor 9", "there are 2 accessors"],
    );
}

/// `gltf::Glb::from_slice` subtracts 12 from the declared length unchecked.
#[test]
fn regression_glb_length_below_header_size() {
    let mut b = unit_triangle().glb(ONE_NODE);
    b[8..12].copy_from_slice(&3u32.to_le_bytes());
    assert_error(&b, "h.glb", &["no JSON chunk"]);
    b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_error(&b, "h.glb", &["declares 4294967295 bytes"]);
}

/// Every prefix and a sweep of single-byte corruptions of a file of each
/// format must give `Ok` or `Err`, never a panic (usvg's "must not panic").
#[test]
fn truncations_and_corruptions_never_panic() {
    let shape = Shape::grid();
    let rest = format!("{ONE_NODE},{}", grid_mesh_json());
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("f.obj", obj_bytes(&shape)),
        ("f.ply", ply_ascii(&shape)),
        ("f.ply", ply_binary(&shape, false, false)),
        ("f.ply", ply_binary(&shape, true, true)),
        ("f.stl", stl_ascii(&shape)),
        ("f.stl", stl_binary(&shape, b"solid x")),
        ("f.gltf", gltf_grid(&shape, 2).gltf(&rest)),
        ("f.glb", gltf_grid(&shape, 4).glb(&rest)),
    ];
    for (name, bytes) in &files {
        for len in 0..bytes.len() {
            let r: Result<ImportedMesh, MeshError> =
                import_mesh(&bytes[..len], name, &ImportOptions::DEFAULT);
            if let Err(e) = r {
                assert!(e.to_string().starts_with(name), "{e}");
            }
        }
        for at in (0..bytes.len()).step_by(3) {
            for value in [0u8, 0xff, b'9', b'-'] {
                let mut b = bytes.clone();
                b[at] = value;
                let _ = import_mesh(&b, name, &ImportOptions::DEFAULT);
            }
        }
    }
}

/// Throughput check for the spec's 200 MB/s OBJ goal on a 2M-triangle
/// scan; run with `cargo test --release --test lib obj_throughput -- --ignored --nocapture`.
#[cfg(not(target_arch = "wasm32"))] // no clock on wasm32-unknown-unknown
#[test]
#[ignore]
fn obj_throughput() {
    let n = 1001usize;
    let mut s = String::with_capacity(100 << 20);
    for j in 0..n {
        for i in 0..n {
            let z = ((i * 7 + j * 13) % 100) as f64 * 0.001234;
            s += &format!("v {:.6} {:.6} {:.6}\n", i as f64 * 0.1, j as f64 * 0.1, z);
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            s += &format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + 1,
                a + 1 + n,
                a + 1 + n,
                a + n
            );
        }
    }
    let start = std::time::Instant::now();
    let m = import(s.as_bytes(), "big.obj", &ImportOptions::DEFAULT);
    let secs = start.elapsed().as_secs_f64();
    let mb = s.len() as f64 / 1e6;
    println!(
        "{} triangles, {mb:.1} MB in {secs:.3} s: {:.0} MB/s",
        m.mesh.triangle_count(),
        mb / secs
    );
    assert_eq!(m.mesh.triangle_count(), 2 * (n - 1) * (n - 1));
}

/// Every byte of a small file of each format set to every value (slow; run
/// with `--ignored` after changing a parser).
#[test]
#[ignore]
fn exhaustive_byte_corruption_never_panics() {
    let mut shape = Shape::grid();
    shape.vertices.truncate(8);
    shape.quads.truncate(2);
    let rest = format!("{ONE_NODE},{}", grid_mesh_json());
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("f.obj", obj_bytes(&shape)),
        ("f.ply", ply_ascii(&shape)),
        ("f.ply", ply_binary(&shape, false, false)),
        ("f.ply", ply_binary(&shape, true, true)),
        ("f.stl", stl_ascii(&shape)),
        ("f.stl", stl_binary(&shape, b"solid x")),
        ("f.gltf", gltf_grid(&shape, 2).gltf(&rest)),
        ("f.glb", gltf_grid(&shape, 4).glb(&rest)),
    ];
    for (name, bytes) in &files {
        for at in 0..bytes.len() {
            for value in 0..=255u8 {
                let mut b = bytes.clone();
                b[at] = value;
                let _ = import_mesh(&b, name, &ImportOptions::DEFAULT);
            }
        }
    }
}

/// 62 bytes of Draco that decode to 2,000,000 points: one face, and a
/// POSITION whose values are all the same, which entropy-codes to a run with
/// no payload (written by draco-core 2.3.3's own `MeshEncoder`: sequential,
/// 11-bit positions). 24 MB of floats from 62 bytes.
const DRACO_2M_POINTS_IN_62_BYTES: [u8; 62] = [
    0x44, 0x52, 0x41, 0x43, 0x4f, 0x02, 0x02, 0x01, 0x00, 0x00, 0x00, 0x01, //
    0x80, 0x89, 0x7a, 0x01, 0x00, 0x01, 0x02, 0x01, 0x01, 0x00, 0x09, 0x03, //
    0x00, 0x00, 0x02, 0x00, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x40, 0x01, //
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, //
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, //
    0x3f, 0x0b,
];

/// A Draco stream that decodes to far more than a stream its size can hold
/// of a real scan (a decompression bomb) is refused before it is decoded,
/// naming the file and the primitive: the decoder's ceilings follow the
/// stream's length (256 faces a byte and 65,536 besides, 3 points a face,
/// 64 bytes a point), not only the program's limits on a whole scan, which
/// a 62-byte stream of 2 M points (24 MB) passes.
#[test]
fn gltf_draco_stream_decoding_to_far_more_than_its_size_is_refused() {
    let mut g = GltfBuilder::default();
    let view = g.view(&DRACO_2M_POINTS_IN_62_BYTES);
    g.accessors.push(
        r#"{"componentType":5126,"count":2000000,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}"#
            .into(),
    );
    g.accessors
        .push(r#"{"componentType":5125,"count":3,"type":"SCALAR"}"#.into());
    let draco = r#""KHR_draco_mesh_compression""#;
    let bytes = g.glb(&format!(
        r#"{ONE_NODE},"extensionsUsed":[{draco}],"extensionsRequired":[{draco}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,
        "extensions":{{{draco}:{{"bufferView":{view},"attributes":{{"POSITION":0}}}}}}}}]}}]"#
    ));
    let e = import_mesh(&bytes, "bomb.glb", &ImportOptions::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(
            "bomb.glb: mesh 0 primitive 0: its Draco data (bufferView 0) could not be decoded"
        ) && e.contains("ceiling"),
        "{e}"
    );
}

/// What real glTF files require beyond the core: a file that requires
/// meshopt or Draco but holds a plain primitive is read as it is (both are
/// decoded: `realworld::gltf_meshopt_*`, `realworld::gltf_draco_*`), glTF
/// 1.0 written with a numeric version
/// is named, appearance-only required extensions do not stop the import,
/// and a POSITION accessor without min/max is read (its bounds come from
/// the data).
#[test]
fn gltf_extensions_versions_and_missing_bounds() {
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let tri = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]"#;
    let with = |required: &str| {
        g.gltf(&format!(
            r#"{ONE_NODE},{tri},"extensionsUsed":[{required}],"extensionsRequired":[{required}]"#
        ))
    };
    let m = import_mesh(
        &with(r#""EXT_meshopt_compression""#),
        "engine.gltf",
        &ImportOptions::DEFAULT,
    )
    .unwrap();
    assert_eq!(m.mesh.triangle_count(), 1);
    let m = import_mesh(
        &with(r#""KHR_draco_mesh_compression""#),
        "plain.gltf",
        &ImportOptions::DEFAULT,
    )
    .unwrap();
    assert_eq!(m.mesh.triangle_count(), 1);
    // GPU instancing is read (its nodes drawn once per instance), required
    // or not; an extension this program does not know is refused.
    let m = import_mesh(
        &with(r#""EXT_mesh_gpu_instancing""#),
        "i.gltf",
        &ImportOptions::DEFAULT,
    )
    .unwrap();
    assert_eq!(m.mesh.triangle_count(), 1);
    let e = import_mesh(
        &with(r#""ACME_displaced_geometry""#),
        "i.gltf",
        &ImportOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("requires the extension ACME_displaced_geometry"),
        "{e}"
    );
    let fine = with(
        r#""KHR_materials_pbrSpecularGlossiness","KHR_texture_transform","KHR_mesh_quantization""#,
    );
    let m = import_mesh(&fine, "shiny.gltf", &ImportOptions::DEFAULT).unwrap();
    assert_eq!(m.mesh.triangle_count(), 1);
    // glTF 1.0, its version a number.
    let v1 = br#"{"asset":{"version":1},"accessors":{"a":{"bufferView":"v","count":3}}}"#;
    let e = import_mesh(v1, "truck.gltf", &ImportOptions::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("glTF version 1") && e.contains("only glTF 2.0"),
        "{e}"
    );
    // Bounds left out.
    let bare = String::from_utf8(g.gltf(&format!("{ONE_NODE},{tri}"))).unwrap();
    let cut = bare.replace(r#","min":[0.0, 0.0, 0.0],"max":[1.0, 1.0, 0.0]"#, "");
    assert_ne!(cut, bare, "{bare}");
    let m = import_mesh(cut.as_bytes(), "nobounds.gltf", &ImportOptions::DEFAULT).unwrap();
    assert_eq!(m.mesh.triangle_count(), 1);
}

/// A textured scan optimised by glTF-Transform (`optimize`'s default
/// turns its textures into WebP: EXT_texture_webp, required) names each
/// texture's image only in the extension, as the spec allows, and was
/// refused "not a valid glTF 2.0 file: textures[0].source: Missing data"
/// (every 2025 cookie scan of github:curtgrimes/stephen-desserts, Polycam
/// scans). Appearance never changes the surface: materials, textures,
/// images and samplers are not read, whatever they hold or lack.
#[test]
fn regression_a_texture_named_only_by_an_extension_stopped_the_import() {
    let mut g = GltfBuilder::default();
    g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let webp = r#""EXT_texture_webp""#;
    let appearance = format!(
        r#"{ONE_NODE},"extensionsUsed":[{webp}],"extensionsRequired":[{webp}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},
          "normalTexture":{{"index":1}}}}],
        "textures":[{{"sampler":0,"extensions":{{{webp}:{{"source":0}}}}}},
          {{"extensions":{{{webp}:{{"source":1}}}}}}],
        "images":[{{"mimeType":"image/webp","uri":"baseColor_1.webp"}},
          {{"mimeType":"image/webp","uri":"normal_1.webp"}}],
        "samplers":[{{"magFilter":9729}}]"#
    );
    // A material pointing at a texture the file does not have changes no
    // surface either.
    let dangling = format!(
        r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":3}}}}}}]"#
    );
    // Nor does a primitive's material index past the file's materials.
    let missing = format!(
        r#"{ONE_NODE},"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":5}}]}}]"#
    );
    for json in [appearance, dangling, missing] {
        let m = import_mesh(&g.gltf(&json), "cookie.gltf", &ImportOptions::DEFAULT).unwrap();
        assert_eq!(m.mesh.triangle_count(), 1);
    }
}

/// A PNG renamed .obj (the page's file picker takes any name) read as
/// lines of nothing: "the mesh has no triangles". Now named as binary data,
/// with what it looks like (found by exploratory runs in the page).
#[test]
fn regression_an_image_named_obj_had_no_triangles() {
    let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
    png.extend_from_slice(&[0u8; 64]);
    assert_error(
        &png,
        "logo.obj",
        &["logo.obj", "not OBJ text", "a PNG image"],
    );
    let mut gz = vec![0x1f, 0x8b, 8, 0];
    gz.extend_from_slice(&[0u8; 32]);
    assert_error(&gz, "scan.xyz", &["not XYZ text", "gzip"]);
}

/// An OBJ of `v` lines only (Meshlab's and CloudCompare's point-cloud
/// export) said "the mesh has no triangles" while the same points as XYZ,
/// PLY or PCD were meshed as a cloud: now it is meshed as one too.
#[test]
fn regression_a_point_cloud_saved_as_obj_had_no_triangles() {
    let mut obj = String::from("# OBJ File Generated by Meshlab\n");
    for i in 0..20 {
        for j in 0..20 {
            let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
            obj.push_str(&format!("v {x} {y} {}\nvn 0 0 1\n", 0.1 * (x + y).sin()));
        }
    }
    let m = import(obj.as_bytes(), "cloud.obj", &ImportOptions::DEFAULT);
    let info = m.cloud.expect("meshed as a point cloud");
    assert_eq!(info.points, 400);
    assert!(m.mesh.triangle_count() > 600, "{}", m.mesh.triangle_count());
}

/// A scan whose name gives another format than its content: the error
/// says what the content is and the name to give it (a PLY named `.stl`
/// was "binary STL header declares 1886351984 triangles"); a file whose
/// content is no format at all keeps the error of its name's format.
#[test]
fn regression_a_misnamed_scan_was_diagnosed_as_its_names_format() {
    let ply = include_bytes!("data/realworld/mesh/cube_binary.ply");
    let glb = include_bytes!("data/realworld/mesh/bunny.glb");
    let stl = include_bytes!("data/realworld/mesh/Spider_binary.stl");
    for (bytes, name, says) in [
        (&ply[..], "cube.stl", "its content is a PLY file, not what its name says: rename it to .ply (read as .stl: binary STL header declares"),
        (&glb[..], "bunny.obj", "its content is a binary glTF file, not what its name says: rename it to .glb (read as .obj: not OBJ text"),
        (&stl[..], "spider.ply", "its content is an STL file, not what its name says: rename it to .stl (read as .ply:1: PLY header"),
    ] {
        let e = import_mesh(bytes, name, &ImportOptions::DEFAULT)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&format!("{name}: {says}")), "{e}");
    }
    let e = import_mesh(
        b"\x01\x02 not a scan \x03",
        "junk.stl",
        &ImportOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("junk.stl: ") && !e.contains("rename"), "{e}");
}

/// A ZIP archive of entries `names` (stored, empty), as a phone scanning
/// app exports an OBJ with its .mtl and texture.
fn zip_of(names: &[&str]) -> Vec<u8> {
    let (mut b, mut central) = (Vec::new(), Vec::new());
    for n in names {
        let offset = b.len() as u32;
        b.extend(b"PK\x03\x04");
        b.extend([0u8; 22]);
        b.extend((n.len() as u16).to_le_bytes());
        b.extend([0u8; 2]);
        b.extend(n.as_bytes());
        central.extend(b"PK\x01\x02");
        central.extend([0u8; 24]);
        central.extend((n.len() as u16).to_le_bytes());
        central.extend([0u8; 12]);
        central.extend(offset.to_le_bytes());
        central.extend(n.as_bytes());
    }
    let at = b.len() as u32;
    let size = central.len() as u32;
    b.extend(central);
    b.extend(b"PK\x05\x06");
    b.extend([0u8; 4]);
    b.extend((names.len() as u16).to_le_bytes());
    b.extend((names.len() as u16).to_le_bytes());
    b.extend(size.to_le_bytes());
    b.extend(at.to_le_bytes());
    b.extend([0u8; 2]);
    b
}

/// QA round 16 F7: a phone scan's ZIP (fuze.obj, its .mtl and texture,
/// trimesh's fuze.zip) was "not a scan this program reads". It is named
/// as an archive, with the scan inside to open.
#[test]
fn a_zip_archive_is_told_to_be_unpacked_naming_the_scan_inside() {
    let e = import_mesh(
        &zip_of(&["fuze.obj", "fuze.obj.mtl", "fuze_uv.jpg"]),
        "fuze.zip",
        &ImportOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with(
            "fuze.zip: the file is a ZIP archive holding fuze.obj, fuze.obj.mtl, fuze_uv.jpg, \
             not a scan: unpack it and open the scan inside it, fuze.obj"
        ),
        "{e}"
    );
    let e = import_mesh(
        &zip_of(&["scan/", "scan/a.ply", "scan/b.glb", "notes.md"]),
        "scans.obj",
        &ImportOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("open the scan inside it (one of scan/a.ply, scan/b.glb)"),
        "{e}"
    );
    // Cut short (no directory): still an archive, its entries unnamed.
    let cut = zip_of(&["fuze.obj"]);
    let e = import_mesh(&cut[..40], "fuze.zip", &ImportOptions::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "the file is a ZIP archive, not a scan: unpack it and open the scan inside it (an OBJ"
        ),
        "{e}"
    );
}

/// A web page saved under a scan's name (GitHub's page for a .glb, saved
/// from the browser) read "not a valid glTF 2.0 file: expected value at
/// line 7 column 1" (a QA run); as .obj it would have been "no triangles".
/// It is named as what it is, whatever the extension.
#[test]
fn regression_a_web_page_saved_as_a_scan_was_read_as_one() {
    let page = b"\xEF\xBB\xBF\n  <!DOCTYPE html>\n<html lang=\"en\"><head><title>DamagedHelmet.glb</title></head></html>\n";
    for name in [
        "DamagedHelmet.glb",
        "bunny.obj",
        "part.stl",
        "scan.ply",
        "noext",
    ] {
        let e = import_mesh(page, name, &ImportOptions::DEFAULT)
            .err()
            .unwrap_or_else(|| panic!("{name} read"))
            .to_string();
        assert!(
            e.starts_with(&format!(
                "{name}: the file is a web page (HTML), not a scan"
            )),
            "{name}: {e}"
        );
    }
    let e = import_mesh(
        b"<HTML><body>404</body></HTML>",
        "x.glb",
        &ImportOptions::DEFAULT,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("web page (HTML)"), "{e}");
}

/// QA round 21 F5: KiCad's VRML model and LibreCAD's DXF given as the
/// scan got the list of formats alone, where an OFF got its format and
/// a way out. Other 3-D formats are named by their first bytes, however
/// the file is named, or by their extension, each with how to export
/// it; a DXF is the drawing, to export as SVG.
#[test]
fn other_3d_formats_and_a_dxf_are_named_with_a_way_out() {
    let refused = |bytes: &[u8], name: &str| {
        import_mesh(bytes, name, &ImportOptions::DEFAULT)
            .unwrap_err()
            .to_string()
    };
    let tds = vec![0x4D, 0x4D, 16, 0, 0, 0, 2, 0, 10, 0, 0, 0, 3, 0, 0, 0];
    let mut iges = format!("{:<72}S{:>7}\n", "IGES written by a CAD program", 1);
    iges += &format!("{:<72}G{:>7}\n", "1H,,1H;", 1);
    for (bytes, what, way) in [
        (
            b"#VRML V2.0 utf8\n#Exported from Wings 3D\nDEF cube Transform {\n}\n".to_vec(),
            "; this is a VRML model (KiCad's and many CAD tools' 3-D models): open it in \
             MeshLab",
            "export it as PLY, OBJ or STL",
        ),
        (
            b"<?xml version=\"1.0\"?>\n<X3D profile=\"Immersive\">".to_vec(),
            "; this is an X3D model",
            "MeshLab",
        ),
        (
            b"<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"x\" version=\"1.4.1\">".to_vec(),
            "; this is a COLLADA scene (.dae)",
            "MeshLab",
        ),
        (
            b"Kaydara FBX Binary  \x00\x1a\x00".to_vec(),
            "; this is an FBX scene",
            "Blender",
        ),
        (
            b"ISO-10303-21;\nHEADER;\n".to_vec(),
            "; this is a CAD model (STEP or IGES), not a mesh",
            "export it as STL from its CAD program",
        ),
        (
            iges.into_bytes(),
            "; this is a CAD model (STEP or IGES)",
            "STL",
        ),
        (tds, "; this is a 3DS scene", "MeshLab"),
        (
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
            "; this is an OFF mesh (Geomview, MeshLab, CGAL): export it as PLY, OBJ or STL",
            "Export Mesh As",
        ),
        (
            zip_of(&["[Content_Types].xml", "3D/3dmodel.model"]),
            "; this is a 3MF model",
            "export it as STL or OBJ",
        ),
        // An iPhone scanning app's USDZ (its USD layer first, binary or
        // text), and a bare USD layer: QA found the USDZ called a ZIP
        // archive to unpack, which holds no scan this program reads.
        (
            zip_of(&["Model.usdc", "0/texture.png"]),
            "; this is a USD scene (Universal Scene Description; a .usdz",
            "export the scan as glTF/GLB, OBJ, PLY or STL",
        ),
        (
            b"PXR-USDC\x00\x08\x00\x00\x00\x00\x00\x00".to_vec(),
            "; this is a USD scene",
            "Blender",
        ),
        (
            b"#usda 1.0\n(\n    defaultPrim = \"root\"\n)\n".to_vec(),
            "; this is a USD scene",
            "Blender",
        ),
    ] {
        let e = refused(&bytes, "upload");
        assert!(
            e.starts_with("upload: not a scan this program reads")
                && e.contains(what)
                && e.contains(way),
            "{what}: {e}"
        );
    }
    // By extension alone.
    for (name, what) in [
        ("Jack.wrl", "a VRML model"),
        ("part.x3d", "an X3D model"),
        ("part.3mf", "a 3MF model"),
        ("part.igs", "a CAD model"),
        ("part.blend", "a Blender file"),
        ("Cookie.usdz", "a USD scene"),
        ("scan.usda", "a USD scene"),
    ] {
        let e = refused(b"\x01\x02junk", name);
        assert!(e.contains(&format!("; this is {what}")), "{name}: {e}");
    }
    // Nothing said of what is none of them.
    let e = refused(b"\x01\x02junk", "x.bin");
    assert!(!e.contains("this is"), "{e}");
    // LibreCAD's DXF (its first lines), by content or by name.
    let dxf = b"  0\nSECTION\n  2\nHEADER\n  9\n$LIMMIN\n 10\n0.000000\n";
    for (bytes, name) in [
        (&dxf[..], "hexagon_b.dxf"),
        (&dxf[..], "upload"),
        (
            b"999\r\ndxfrw 0.6.3\r\n  0\r\nSECTION\r\n".as_slice(),
            "upload",
        ),
        (b"AutoCAD Binary DXF\r\n\x1a\x00".as_slice(), "upload"),
        (b"\x01\x02junk".as_slice(), "plate.DXF"),
    ] {
        let e = refused(bytes, name);
        assert!(
            e.starts_with(&format!(
                "{name}: the file is a 2-D CAD drawing (DXF), not a scan; a DXF drawing is \
                 the path: export it as SVG"
            )),
            "{e}"
        );
    }
    // Review: a 3MF saved under a mesh's extension is named as a 3MF
    // (it was read as that mesh), and an SVG named .dxf, or a DXF after
    // a byte-order mark, as what it is.
    let three_mf = zip_of(&["[Content_Types].xml", "3D/3dmodel.model"]);
    for name in ["part.stl", "part.obj", "part.ply"] {
        let e = refused(&three_mf, name);
        assert!(e.contains("; this is a 3MF model"), "{name}: {e}");
    }
    let e = refused(b"<svg xmlns=\"http://www.w3.org/2000/svg\"/>", "logo.dxf");
    assert!(!e.contains("(DXF)"), "{e}");
    let e = refused(b"\xEF\xBB\xBF  0\r\nSECTION\r\n", "upload");
    assert!(e.contains("(DXF)"), "{e}");
}
