//! Integration tests: real-world files nobody on the team wrote, taken from
//! public packages (tests/data/realworld/SOURCES.md names each one's package,
//! version, path and licence). They pin what the importers and the pipeline
//! make of CAD exports, Blender/LightWave/trueSpace exports, glTF sample
//! models and icon sets, and the exact error a genuinely broken file gets.
//!
//! Tests marked `#[ignore = "bug: ..."]` state the behaviour we want and
//! currently fail; each is named after the bug it pins.

use std::collections::BTreeSet;

use pcpp::fiducials::{boundary_loops, find_fiducials};
use pcpp::gcode::MachineProfile;
use pcpp::job::{prepare_scan, run_on, FiducialSource, RegistrationSettings};
use pcpp::mesh::{
    external_files_needed, import_mesh_with, ExternalFiles, ExternalRef, ImportOptions,
    ImportedMesh, MeshFormat, ScanUnits, TriMesh,
};
use pcpp::pipeline::{load_path, DrawnPath, PlanSettings};
use pcpp::svg::Placement;
use pcpp::{DVec2, DVec3};

/// The bytes of a checked-in file; `include_bytes!` so the same tests run
/// wherever the crate is built (no file paths at run time).
macro_rules! data {
    ($name:literal) => {
        include_bytes!(concat!("data/realworld/", $name)).as_slice()
    };
}

use crate::importers::{assert_error as assert_import_error, error as import_error, triangle_set};

fn import(bytes: &[u8], file: &str) -> ImportedMesh {
    crate::importers::import(bytes, file, &ImportOptions::DEFAULT)
}

fn assert_close(a: DVec3, b: DVec3, tol: f64, what: &str) {
    assert!(
        (a - b).abs().max_element() <= tol,
        "{what}: {a} vs expected {b}"
    );
}

fn assert_bbox(mesh: &TriMesh, lo: [f64; 3], hi: [f64; 3], tol: f64) {
    let (l, h) = mesh.bbox().expect("empty mesh");
    assert_close(l, DVec3::from_array(lo), tol, "bbox min");
    assert_close(h, DVec3::from_array(hi), tol, "bbox max");
}

fn degenerate_warning(m: &ImportedMesh) -> Option<&str> {
    m.warnings
        .iter()
        .find(|w| w.contains("degenerate"))
        .map(String::as_str)
}

// ------------------------------------------------------------------ STL

/// trueSpace wrote the binary file, another exporter the ascii one, of the
/// same spider: both read to the same welded mesh.
#[test]
fn spider_binary_and_ascii_stl_read_to_the_same_mesh() {
    let bin = import(data!("mesh/Spider_binary.stl"), "Spider_binary.stl");
    let ascii = import(data!("mesh/Spider_ascii.stl"), "Spider_ascii.stl");
    for m in [&bin, &ascii] {
        assert_eq!(m.format, MeshFormat::Stl);
        assert_eq!(m.units, ScanUnits::Mm);
        // 1368 facets, 56 of them zero-area slivers the exporter left in
        // (kept: segments the nozzle must clear).
        assert_eq!(m.mesh.triangle_count(), 1368);
        assert_eq!(m.mesh.vertices.len(), 722, "welded vertex count");
        let w = degenerate_warning(m).expect("degenerate facets not reported");
        assert!(w.contains("56 degenerate triangle(s)"), "{w}");
        assert_bbox(&m.mesh, [-3.115, -4.0, -1.649], [3.115, 4.0, 1.649], 1e-3);
    }
    // The ascii file prints 6 digits, the binary one stores f32: the same
    // points to within the ascii rounding.
    let (bl, bh) = bin.mesh.bbox().unwrap();
    let (al, ah) = ascii.mesh.bbox().unwrap();
    assert_close(bl, al, 1e-5, "binary vs ascii bbox min");
    assert_close(bh, ah, 1e-5, "binary vs ascii bbox max");
    // Closed apart from the spider's six hole-like openings, seen the same
    // way in both files.
    assert_eq!(find_fiducials(&bin.mesh).len(), 6);
    assert_eq!(find_fiducials(&ascii.mesh).len(), 6);
}

/// 3ds Max's binary STL ("STLEXP" header, 2000 facets), already clean.
#[test]
fn cad_binary_stl_from_3ds_max() {
    let m = import(data!("mesh/3DSMaxExport.STL"), "3DSMaxExport.STL");
    assert_eq!(m.format, MeshFormat::Stl);
    assert_eq!(m.mesh.triangle_count(), 2000);
    assert_eq!(m.mesh.vertices.len(), 1042);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    assert_bbox(
        &m.mesh,
        [-27.370, -2.428, 9.699],
        [29.664, 45.913, 62.343],
        1e-3,
    );
    // A closed, welded solid: no boundary at all.
    assert!(boundary_loops(&m.mesh).is_empty());
}

/// A sphere of diameter 3 with three facets missing: each missing facet is
/// one three-edge boundary loop, and each is a fiducial candidate.
#[test]
fn sphere_with_missing_facets_shows_each_hole() {
    let m = import(data!("mesh/sphereWithHole.stl"), "sphereWithHole.stl");
    assert_eq!(m.mesh.triangle_count(), 285);
    assert_bbox(&m.mesh, [0.0; 3], [3.0; 3], 1e-9);
    let loops = boundary_loops(&m.mesh);
    assert_eq!(loops.len(), 3);
    assert!(loops.iter().all(|l| l.vertices.len() == 3));
    let holes = find_fiducials(&m.mesh);
    assert_eq!(holes.len(), 3);
    for h in &holes {
        // On the sphere's bottom, near the pole at (1.5, 1.5, 0).
        assert!(h.centroid.z < 0.2, "{:?}", h.centroid);
        assert!(h.diameter_mm > 0.3 && h.diameter_mm < 0.35, "{h:?}");
    }
}

// ------------------------------------------------------------------ OBJ

/// LightWave-style OBJ with `f v/vt/vn` corners (302 vt, 747 vn).
#[test]
fn obj_with_texture_and_normal_indices() {
    let m = import(data!("mesh/spider.obj"), "spider.obj");
    assert_eq!(m.format, MeshFormat::Obj);
    // 1368 faces, the same 56 slivers as the STL spider (kept).
    assert_eq!(m.mesh.triangle_count(), 1368);
    // 762 vertex records, 722 distinct positions once welded.
    assert_eq!(m.mesh.vertices.len(), 722);
    let w = degenerate_warning(&m).expect("degenerate faces not reported");
    assert!(w.contains("56 degenerate triangle(s)"), "{w}");
    assert_bbox(
        &m.mesh,
        [-92.655, -42.234, -106.691],
        [57.936, 37.504, 86.691],
        1e-3,
    );
}

/// `v 1e+2 2.e+1 3.1+e2`: the file really has a malformed number on line 11.
#[test]
fn obj_malformed_exponent_is_reported_with_its_line() {
    assert_import_error(
        data!("mesh/number_formats.obj"),
        "number_formats.obj",
        &["number_formats.obj:11:", "'3.1+e2' is not a number"],
    );
}

/// A UTF-16 (big-endian, BOM) OBJ cannot be read; it must at least fail.
#[test]
fn obj_in_utf16_is_refused() {
    let e = import_error(data!("mesh/box_UTF16BE.obj"), "box_UTF16BE.obj");
    assert!(e.starts_with("box_UTF16BE.obj"), "{e}");
}

#[test]

fn obj_in_utf16_error_names_the_encoding() {
    let e = import_error(data!("mesh/box_UTF16BE.obj"), "box_UTF16BE.obj");
    assert!(e.contains("UTF-16"), "{e}");
}

/// One concave 66-corner face (LightWave export). A fan from the first
/// corner covers 13x the polygon's area with 29 of 64 triangles flipped;
/// the triangulation must cover exactly the polygon, one orientation.
#[test]

fn obj_concave_polygon_is_triangulated_inside_its_outline() {
    let m = import(data!("mesh/concave_polygon.obj"), "concave_polygon.obj");
    assert_eq!(m.mesh.triangle_count(), 64);
    // The face lies in the plane x = -1.146; its shoelace area in (y, z).
    let polygon_area = 0.245_496_687_2;
    let mut area = 0.0;
    let mut normals = BTreeSet::new();
    for t in 0..m.mesh.triangle_count() {
        let [a, b, c] = m.mesh.triangle(t);
        let n = (b - a).cross(c - a);
        area += n.length() / 2.0;
        normals.insert(n.x > 0.0);
    }
    assert!(
        (area - polygon_area).abs() < 1e-6,
        "triangles cover {area} mm^2, polygon is {polygon_area} mm^2"
    );
    assert_eq!(normals.len(), 1, "triangles of one face face both ways");
}

// ------------------------------------------------------------------ PLY

#[test]
fn ply_binary_cube() {
    let m = import(data!("mesh/cube_binary.ply"), "cube_binary.ply");
    assert_eq!(m.format, MeshFormat::Ply);
    assert_eq!(m.mesh.triangle_count(), 12);
    assert_eq!(m.mesh.vertices.len(), 8);
    assert_bbox(&m.mesh, [0.0; 3], [1.0; 3], 0.0);
    assert!(boundary_loops(&m.mesh).is_empty());
}

/// Blender's ascii PLY repeats each corner per face (24 vertices for a cube,
/// 8 distinct positions). Read, it is a cube; but unwelded, each face is its
/// own patch with a boundary, which the fiducial search takes for holes.
#[test]
fn ply_with_split_vertices_reads_the_cube() {
    let m = import(data!("mesh/cube_uv.ply"), "cube_uv.ply");
    assert_eq!(m.mesh.triangle_count(), 12);
    assert_bbox(&m.mesh, [-1.0; 3], [1.0; 3], 2e-6);
}

#[test]

fn ply_with_split_vertices_is_welded() {
    let m = import(data!("mesh/cube_uv.ply"), "cube_uv.ply");
    assert_eq!(m.mesh.vertices.len(), 8);
    assert!(boundary_loops(&m.mesh).is_empty());
}

/// Blender 2.77 wrote `property list ... vertex_indices` inside the vertex
/// element and no face element: genuinely broken. The list length is read
/// from the next line's first coordinate.
#[test]
fn ply_with_face_list_in_vertex_element_is_refused() {
    assert_import_error(
        data!("mesh/issue623.ply"),
        "issue623.ply",
        &[
            "issue623.ply:14:",
            "'vertex' element 0",
            "'vertex_indices'",
            "'7.941797'",
        ],
    );
}

// ----------------------------------------------------------------- glTF

/// The glTF sample BoxTextured: a root node with a rotation matrix over a
/// child node holding the mesh. Binary and embedded-JSON forms agree.
#[test]
fn gltf_box_binary_and_embedded_agree() {
    let glb = import(data!("mesh/BoxTextured.glb"), "BoxTextured.glb");
    let gltf = import(
        data!("mesh/BoxTextured-Embedded.gltf"),
        "BoxTextured-Embedded.gltf",
    );
    assert_eq!(glb.format, MeshFormat::Glb);
    assert_eq!(gltf.format, MeshFormat::Gltf);
    for m in [&glb, &gltf] {
        assert_eq!(m.units, ScanUnits::M);
        assert_eq!(m.mesh.triangle_count(), 12);
        assert_eq!(m.mesh.vertices.len(), 8, "seams welded");
        // A 1 m cube in metres, centred: 1000 mm across.
        assert_bbox(&m.mesh, [-500.0; 3], [500.0; 3], 1e-9);
        assert!(boundary_loops(&m.mesh).is_empty());
    }
    assert_eq!(triangle_set(&glb.mesh), triangle_set(&gltf.mesh));
}

/// Five sibling nodes, each with its own mesh, buffers as data URIs
/// (assimp issue 3269). Y up: the file's thin axis (z, 0.0526 m) becomes
/// the printer's y after the +90 deg turn about X.
#[test]
fn gltf_five_nodes_with_data_uri_buffers() {
    let m = import(data!("mesh/texcoord_crash.gltf"), "texcoord_crash.gltf");
    assert_eq!(m.mesh.triangle_count(), 10);
    assert_bbox(
        &m.mesh,
        [-1200.0, -0.000_525, -1200.0],
        [1200.0, 52.591, 1200.0],
        1e-3,
    );
}

// ------------------------------------------------------------ glTF Draco
//
// Draco bitstreams written by Google's own encoder (draco3dgltf, through
// glTF-Transform's `draco` command, SOURCES.md): EdgeBreaker standard,
// EdgeBreaker valence and sequential connectivity, positions quantized to
// 14 bits as that command does by default.

/// Each vertex of `decoded` snapped to the nearest vertex of `original`
/// (brute force), no farther than `tol`: the triangles must be the
/// original's, as sets of its vertices.
fn assert_same_surface(decoded: &TriMesh, original: &TriMesh, tol: f64, what: &str) {
    let nearest: Vec<u32> = decoded
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let (k, d) = original
                .vertices
                .iter()
                .enumerate()
                .map(|(k, o)| (k, o.distance(*v)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .expect("vertices");
            assert!(
                d <= tol,
                "{what}: vertex {i} at {v} is {d} mm from the nearest"
            );
            k as u32
        })
        .collect();
    let key = |t: [u32; 3]| {
        let mut t = t;
        t.sort_unstable();
        t
    };
    let want: BTreeSet<[u32; 3]> = original.triangles.iter().map(|&t| key(t)).collect();
    let got: BTreeSet<[u32; 3]> = decoded
        .triangles
        .iter()
        .map(|t| key(t.map(|v| nearest[v as usize])))
        .collect();
    assert_eq!(
        decoded.triangle_count(),
        original.triangle_count(),
        "{what}"
    );
    assert_eq!(got, want, "{what}: the triangles differ");
}

/// The compressed GLB `bytes` (`name`) imports as the Stanford bunny
/// (3,674 triangles, `bunny.glb`): its vertices, each within a quantization
/// step of its own (the largest extent over 2^14 - 1: the bunny is about 15
/// units across, read as metres), and its triangles.
fn assert_is_the_bunny(bytes: &[u8], name: &str) {
    let original = import(data!("mesh/bunny.glb"), "bunny.glb");
    assert_eq!(original.mesh.triangle_count(), 3674);
    let (lo, hi) = original.mesh.bbox().unwrap();
    let step = (hi - lo).max_element() / 16383.0;
    let m = import(bytes, name);
    assert_eq!(m.format, MeshFormat::Glb);
    assert_eq!(m.units, ScanUnits::M);
    assert_eq!(
        m.mesh.vertices.len(),
        original.mesh.vertices.len(),
        "{name}"
    );
    assert_same_surface(&m.mesh, &original.mesh, step, name);
}

/// The Stanford bunny (3,674 triangles) as glTF, then Draco-compressed
/// with EdgeBreaker's standard and valence traversals: the same surface,
/// each vertex within a quantization step of its own (the file's largest
/// extent over 2^14 - 1: the bunny is about 15 units across, read as
/// metres).
#[test]
fn gltf_draco_bunny_edgebreaker_standard_and_valence_are_the_bunny() {
    for (bytes, name) in [
        (data!("mesh/bunny-draco.glb"), "bunny-draco.glb"),
        (
            data!("mesh/bunny-draco-valence.glb"),
            "bunny-draco-valence.glb",
        ),
    ] {
        assert_is_the_bunny(bytes, name);
    }
}

/// The Stanford bunny as glTF, meshopt-compressed by gltfpack (SOURCES.md):
/// 16-bit positions placed by the node's scale and offset
/// (KHR_mesh_quantization) in 8-byte elements, and float positions through
/// the exponential filter in 12-byte elements, indices as TRIANGLES; and by
/// glTF-Transform (its own quantization, the same codecs). The same
/// surface, each vertex within a quantization step of its own (14 bits
/// over the largest extent).
#[test]
fn gltf_meshopt_bunny_quantized_and_exponential_is_the_bunny() {
    for (bytes, name) in [
        (data!("mesh/bunny-meshopt.glb"), "bunny-meshopt.glb"),
        (data!("mesh/bunny-meshopt-vpf.glb"), "bunny-meshopt-vpf.glb"),
        (
            data!("mesh/bunny-meshopt-gltf-transform.glb"),
            "bunny-meshopt-gltf-transform.glb",
        ),
    ] {
        assert_is_the_bunny(bytes, name);
    }
}

/// QA round 13 F4: a Draco-compressed scan was planned on without a word,
/// its positions rounded by over half of tol. Every compressed file says
/// its geometry is rounded, naming the compression; the plain files do
/// not.
#[test]
fn gltf_compressed_geometry_is_said_to_be_rounded() {
    let said = |m: &ImportedMesh| {
        m.warnings
            .iter()
            .find(|w| w.contains("its geometry is compressed"))
            .cloned()
    };
    for (bytes, name, ext) in [
        (
            data!("mesh/bunny-draco.glb"),
            "bunny-draco.glb",
            "KHR_draco_mesh_compression",
        ),
        (
            data!("mesh/bunny-meshopt.glb"),
            "bunny-meshopt.glb",
            "EXT_meshopt_compression",
        ),
        (
            data!("mesh/BoxTextured-draco-sequential.glb"),
            "BoxTextured-draco-sequential.glb",
            "KHR_draco_mesh_compression",
        ),
    ] {
        let w = said(&import(bytes, name)).unwrap_or_else(|| panic!("{name}: not said"));
        assert!(
            w.starts_with(&format!("{name}: its geometry is compressed (")) && w.contains(ext),
            "{w}"
        );
        assert!(
            w.contains("plan on the scan as it was before compression"),
            "{w}"
        );
    }
    for (bytes, name) in [
        (data!("mesh/bunny.glb"), "bunny.glb"),
        (data!("mesh/BoxTextured.glb"), "BoxTextured.glb"),
    ] {
        assert_eq!(said(&import(bytes, name)), None, "{name}");
    }
}

/// QA round 14 (F4 of round 13 left): the warning gave no step, only
/// "commonly the part's size over 2^11 to 2^14". It now states the grid,
/// in mm, where every primitive's is known: Draco's (the smallest gap
/// between coordinates) and quantized positions' (an integer step times
/// the node's scale). Every vertex lies within half that grid, along each
/// axis, of its uncompressed self; the grid of the dense bunny is a fine
/// one (under a thousandth of its size). Floats through meshopt's
/// exponential filter have no one step: the warning says none.
/// The number `text` writes between `before` and `after`.
fn number_between(text: &str, before: &str, after: &str) -> f64 {
    text.split_once(before)
        .and_then(|(_, rest)| rest.split_once(after))
        .unwrap_or_else(|| panic!("{text}"))
        .0
        .parse()
        .unwrap_or_else(|e| panic!("{text}: {e}"))
}

#[test]
fn gltf_compressed_geometry_states_its_grid() {
    let original = import(data!("mesh/bunny.glb"), "bunny.glb");
    let (lo, hi) = original.mesh.bbox().unwrap();
    let size = (hi - lo).max_element();
    for (bytes, name) in [
        (data!("mesh/bunny-draco.glb"), "bunny-draco.glb"),
        (data!("mesh/bunny-meshopt.glb"), "bunny-meshopt.glb"),
    ] {
        let m = import(bytes, name);
        let w = m
            .warnings
            .iter()
            .find(|w| w.contains("its geometry is compressed"))
            .unwrap_or_else(|| panic!("{name}: not said"));
        let grid = number_between(
            w,
            "to a grid no coarser than ",
            " mm (each moved by up to half of it)",
        );
        assert!(
            grid > 0.0 && grid < size / 1000.0,
            "{name}: {grid} mm of {size}"
        );
        // The margin to add to tol (QA round 18 F11): half the grid's
        // diagonal, rounded up, and no surface point moved more.
        let raise = number_between(w, "or raise tol by ", " mm (--tol");
        assert!(
            raise >= grid * 3f64.sqrt() / 2.0 * 0.95 && raise <= grid * 3f64.sqrt() / 2.0 * 1.2,
            "{name}: raise {raise} for a grid of {grid} mm"
        );
        assert_same_surface(&m.mesh, &original.mesh, raise, name);
        // Half the grid along each axis, two digits of it stated.
        assert_same_surface(
            &m.mesh,
            &original.mesh,
            1.05 * grid * 3f64.sqrt() / 2.0,
            name,
        );
    }
    let m = import(data!("mesh/bunny-meshopt-vpf.glb"), "bunny-meshopt-vpf.glb");
    let w = m
        .warnings
        .iter()
        .find(|w| w.contains("its geometry is compressed"))
        .expect("said");
    assert!(
        w.contains("(commonly to the part's size over 2^11 to 2^14)"),
        "{w}"
    );
}

/// glTF-Transform's meshopt box (SOURCES.md): its normals are unit vectors
/// through the OCTAHEDRAL filter, which is not decoded, as nothing reads
/// them; the box is the uncompressed one.
#[test]
fn gltf_meshopt_box_with_octahedral_normals_is_the_box() {
    let m = import(
        data!("mesh/BoxTextured-meshopt.glb"),
        "BoxTextured-meshopt.glb",
    );
    let original = import(data!("mesh/BoxTextured.glb"), "BoxTextured.glb");
    assert_eq!(m.mesh.vertices.len(), 8, "seams welded");
    assert_bbox(&m.mesh, [-500.0; 3], [500.0; 3], 0.04);
    assert_same_surface(&m.mesh, &original.mesh, 0.04, "box");
}

/// The paths of the files the `.gltf` `gltf` names and needs.
fn needed_files(gltf: &[u8], name: &str) -> Vec<String> {
    external_files_needed(gltf, name)
        .unwrap()
        .into_iter()
        .map(|r| r.path)
        .collect()
}

/// gltfpack's `.gltf` with a fallback: the compressed data in one `.bin`
/// and the uncompressed data, for readers without meshopt, in a second,
/// which is neither asked for nor read (it is not in this folder).
#[test]
fn gltf_meshopt_fallback_file_is_not_needed() {
    let gltf = data!("mesh/bunny-meshopt-cf.gltf");
    let needed = needed_files(gltf, "bunny-meshopt-cf.gltf");
    assert_eq!(needed, ["bunny-meshopt-cf.bin"]);
    let files =
        ExternalFiles::new().with("bunny-meshopt-cf.bin", data!("mesh/bunny-meshopt-cf.bin"));
    let m = import_mesh_with(
        gltf,
        "bunny-meshopt-cf.gltf",
        &ImportOptions::DEFAULT,
        &files,
    )
    .unwrap();
    assert_eq!(m.external_files, needed);
    let glb = import(data!("mesh/bunny-meshopt.glb"), "bunny-meshopt.glb");
    assert_eq!(m.mesh, glb.mesh);
}

/// meshopt data damaged anywhere is read or refused with the file named,
/// never a panic; a stream whose header is not meshopt's is named with its
/// bufferView; a view that claims far more elements than its stream can
/// hold is refused before it is decoded.
#[test]
fn gltf_meshopt_damaged_data_is_an_error_not_a_panic() {
    let bytes = data!("mesh/bunny-meshopt.glb");
    let json = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    // The BIN chunk's data: the vertex stream (bufferView 0), then the
    // index stream.
    let bin = 20 + json + 8;
    assert_eq!(bytes[bin], 0xa0, "meshopt's vertex header, version 0");
    assert!(damaged_somewhere(bytes, bin, "bunny-meshopt.glb") > 0);
    let mut b = bytes.to_vec();
    b[bin] = 0x42;
    assert_import_error(
        &b,
        "bunny-meshopt.glb",
        &[
            "bunny-meshopt.glb: bufferView 0",
            "meshopt data (mode Attributes, 1839 elements of 8 bytes) could not be decoded",
        ],
    );
    // The vertex view's count raised from 1,839 to 9,999,999 (80 MB from
    // 8,482 bytes), the JSON chunk keeping its length (its padding spaces
    // take the three digits more).
    let text = std::str::from_utf8(&bytes[20..20 + json]).unwrap();
    let claim = r#""mode":"ATTRIBUTES","count":1839}"#;
    assert!(text.ends_with("   ") && text.contains(claim), "{text}");
    let bomb = text.replacen(claim, r#""mode":"ATTRIBUTES","count":9999999}"#, 1);
    let bomb = &bomb[..json];
    let mut b = bytes.to_vec();
    b[20..20 + json].copy_from_slice(bomb.as_bytes());
    assert_import_error(
        &b,
        "bunny-meshopt.glb",
        &[
            "bufferView 0",
            "claim 9999999 elements of 8 bytes, more than such a stream decodes to",
        ],
    );
}

/// The glTF sample box (a rotated root node over the mesh's node) with
/// sequential connectivity and POSITION as Draco attribute 1, beside the
/// normals and texture coordinates: the uncompressed box, its 24 points
/// welded to 8 again.
#[test]
fn gltf_draco_sequential_box_with_a_node_hierarchy_is_the_box() {
    let m = import(
        data!("mesh/BoxTextured-draco-sequential.glb"),
        "BoxTextured-draco-sequential.glb",
    );
    let original = import(data!("mesh/BoxTextured.glb"), "BoxTextured.glb");
    assert_eq!(m.mesh.vertices.len(), 8, "seams welded");
    assert_bbox(&m.mesh, [-500.0; 3], [500.0; 3], 0.04);
    assert_same_surface(&m.mesh, &original.mesh, 0.04, "box");
}

/// One Draco mesh drawn by two nodes (decoded once, placed twice): the
/// second box is the first moved by the second node's translation (2 m
/// along x, 2,000 mm in the printer frame, the root's quarter turn about x
/// leaving x as it is).
#[test]
fn gltf_draco_mesh_drawn_by_two_nodes_is_two_boxes() {
    let file = data!("mesh/BoxTextured-draco-sequential.glb");
    let json_len = u32::from_le_bytes(file[12..16].try_into().unwrap()) as usize;
    let json = std::str::from_utf8(&file[20..20 + json_len]).unwrap();
    let bin = &file[20 + json_len + 8..];
    let one = r#""children":[1]},{"mesh":0}]"#;
    assert!(json.contains(one), "{json}");
    let two = json.replace(
        one,
        r#""children":[1,2]},{"mesh":0},{"mesh":0,"translation":[2,0,0]}]"#,
    );
    let bytes = pcpp::demo::glb_container(two.trim_end().as_bytes(), bin);
    let m = import(&bytes, "two-boxes.glb");
    let single = import(file, "BoxTextured-draco-sequential.glb");
    assert_eq!(m.mesh.vertices.len(), 16);
    assert_eq!(m.mesh.triangle_count(), 2 * single.mesh.triangle_count());
    // Whichever box comes first: each vertex is one of the single box's,
    // as it is or moved, and each of those is there once.
    let moved = DVec3::new(2000.0, 0.0, 0.0);
    let key = |v: DVec3| (v * 1e6).round().to_array().map(|c| c as i64);
    let got: BTreeSet<[i64; 3]> = m.mesh.vertices.iter().map(|&v| key(v)).collect();
    let want: BTreeSet<[i64; 3]> = single
        .mesh
        .vertices
        .iter()
        .flat_map(|&v| [key(v), key(v + moved)])
        .collect();
    assert_eq!(got, want);
    assert_bbox(&m.mesh, [-500.0; 3], [2500.0, 500.0, 500.0], 0.04);
}

/// The demo test part (247,490 triangles, a root node scaling mm to
/// metres and turning +Z up to +Y) Draco-compressed: it plans as the
/// uncompressed part does. Quantization (80 mm / 2^14) collapses 292 of
/// the thinnest triangles, and moves the surface by less than a hundredth
/// of a mm (at 3,600 points off its walls).
#[test]
fn gltf_draco_test_part_plans_as_the_uncompressed_part() {
    use pcpp::surface::Surface;
    let m = import(data!("mesh/test-part-draco.glb"), "test-part-draco.glb");
    let part = pcpp::demo::test_part::test_part();
    // Quantization collapses the thinnest triangles: Draco's encoder drops
    // those whose points merge, the import skips those left with zero area
    // and says so.
    let lost = part.triangle_count() - m.mesh.triangle_count();
    assert!(lost * 500 < part.triangle_count(), "{lost} triangles lost");
    assert!(degenerate_warning(&m).is_some(), "{:?}", m.warnings);
    let (decoded, original) = (
        Surface::new(m.mesh.clone()).unwrap(),
        Surface::new(part.clone()).unwrap(),
    );
    let (lo, hi) = part.bbox().unwrap();
    let (mut close, mut asked) = (0, 0);
    for i in 0..60 {
        for j in 0..60 {
            // (Off the part's whole and half mm, where its walls stand: a
            // wall moved by quantization moves the height found there.)
            let xy = DVec2::new(
                lo.x + (hi.x - lo.x) * (i as f64 + 0.1) / 60.0,
                lo.y + (hi.y - lo.y) * (j as f64 + 0.1) / 60.0,
            );
            if let (Some(a), Some(b)) = (decoded.highest_hit(xy), original.highest_hit(xy)) {
                asked += 1;
                close += usize::from((a - b).abs() <= 0.01);
            }
        }
    }
    assert!(asked > 3000 && close == asked, "{close} of {asked}");
    // The whole job, as a user runs it: the demo drawing planned with
    // `even` on the Draco file's bytes, every written move checked against
    // the decoded scan (no risk accepted), as on the uncompressed part.
    let drawing = pcpp::demo::test_part::test_part_svg();
    let settings = PlanSettings {
        placement: pcpp::demo::test_part::placement(),
        ..PlanSettings::default()
    };
    let profile = MachineProfile::builtin("marlin").expect("marlin profile");
    let ply = pcpp::demo::to_binary_ply(&part);
    let plans: Vec<_> = [
        (data!("mesh/test-part-draco.glb"), "test-part-draco.glb"),
        (ply.as_slice(), "test-part.ply"),
    ]
    .into_iter()
    .map(|(bytes, name)| {
        let scan = prepare_scan(
            bytes,
            name,
            &ImportOptions::DEFAULT,
            &RegistrationSettings::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        run_on(
            &scan,
            drawing.as_bytes(),
            "lines.svg",
            &settings,
            &profile,
            false,
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"))
    })
    .collect();
    let points = |o: &pcpp::job::JobOutput| {
        o.plan
            .pieces
            .iter()
            .map(|p| p.toolpath.len())
            .sum::<usize>()
    };
    assert_eq!(points(&plans[0]), points(&plans[1]));
    assert!(plans[0].gcode.contains("test-part-draco.glb"));
}

/// Every third byte of the GLB `bytes` from `bin` on, set to 0, to 255
/// and flipped, one at a time: each import reads or is refused naming
/// `name`, never a panic. How many were refused.
fn damaged_somewhere(bytes: &[u8], bin: usize, name: &str) -> usize {
    let mut refused = 0;
    for at in (bin..bytes.len()).step_by(3) {
        for value in [0x00, 0xff, bytes[at] ^ 0x55] {
            let mut b = bytes.to_vec();
            b[at] = value;
            if let Err(e) =
                import_mesh_with(&b, name, &ImportOptions::DEFAULT, &ExternalFiles::new())
            {
                refused += 1;
                assert!(e.to_string().contains(name), "{e}");
            }
        }
    }
    refused
}

/// Draco data damaged anywhere is read or refused with the file named,
/// never a panic; a stream that is not Draco at all is named as such, with
/// its primitive and bufferView.
#[test]
fn gltf_draco_damaged_data_is_an_error_not_a_panic() {
    let bytes = data!("mesh/bunny-draco.glb");
    let json = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    // The BIN chunk's data, which is the Draco stream (bufferView 0).
    let bin = 20 + json + 8;
    assert_eq!(&bytes[bin..bin + 5], b"DRACO");
    assert!(damaged_somewhere(bytes, bin, "bunny-draco.glb") > 0);
    let mut b = bytes.to_vec();
    b[bin..bin + 5].copy_from_slice(b"DRACX");
    assert_import_error(
        &b,
        "bunny-draco.glb",
        &[
            "bunny-draco.glb",
            "mesh 0 primitive 0",
            "Draco data (bufferView 0) could not be decoded",
        ],
    );
}

#[test]
fn gltf_1_glb_is_refused_by_version() {
    assert_import_error(
        data!("mesh/BoxTextured-glTF1.glb"),
        "BoxTextured-glTF1.glb",
        &["version 1", "only glTF 2.0"],
    );
}

/// A glTF 1.0 JSON file fails; today with a serde message.
#[test]
fn gltf_1_json_is_refused() {
    assert_import_error(
        data!("mesh/TwoBoxes-glTF1.gltf"),
        "TwoBoxes-glTF1.gltf",
        &["glTF 2.0"],
    );
}

#[test]

fn gltf_1_json_error_names_the_version() {
    assert_import_error(
        data!("mesh/TwoBoxes-glTF1.gltf"),
        "TwoBoxes-glTF1.gltf",
        &["1.0"],
    );
}

#[test]
fn gltf_node_cycle_is_refused() {
    assert_import_error(
        data!("mesh/RecursiveNodes.gltf"),
        "RecursiveNodes.gltf",
        &["node 0 is reached twice", "tree"],
    );
}

#[test]
fn gltf_with_infinite_positions_is_refused() {
    assert_import_error(
        data!("mesh/BoxWithInfinites.glb"),
        "BoxWithInfinites.glb",
        // Refused for its values, naming the element, not for its
        // accessor's missing bounds.
        &["POSITION element 0 has a non-finite coordinate"],
    );
}

/// A .gltf whose buffer is a separate .bin: only bytes of one file are read,
/// and the message says what to export instead.
#[test]
fn gltf_with_external_buffer_says_how_to_fix_it() {
    assert_import_error(
        data!("mesh/Mesh_PrimitiveMode_00.gltf"),
        "Mesh_PrimitiveMode_00.gltf",
        &["external file 'Mesh_PrimitiveMode_00.bin'", ".glb"],
    );
}

/// The same sample box as a `.gltf` whose buffer is `BoxTextured0.bin`
/// (and a texture, `CesiumLogoFlat.png`, not needed for the surface): the
/// importer lists only the `.bin`, and with it reads what the `.glb` holds.
/// Without it, the error names it (assimp's `MissingBin` model is this
/// `.gltf` alone).
#[test]
fn gltf_with_its_bin_reads_as_the_glb() {
    let gltf = data!("mesh/BoxTextured.gltf");
    let needed = external_files_needed(gltf, "BoxTextured.gltf").unwrap();
    assert_eq!(
        needed,
        [ExternalRef {
            buffer: 0,
            uri: "BoxTextured0.bin".into(),
            path: "BoxTextured0.bin".into()
        }]
    );
    let files = ExternalFiles::new().with("BoxTextured0.bin", data!("mesh/BoxTextured0.bin"));
    let m = import_mesh_with(gltf, "BoxTextured.gltf", &ImportOptions::DEFAULT, &files).unwrap();
    assert_eq!(m.external_files, ["BoxTextured0.bin"]);
    let glb = import(data!("mesh/BoxTextured.glb"), "BoxTextured.glb");
    assert_eq!(m.mesh, glb.mesh);
    assert_import_error(
        gltf,
        "BoxTextured.gltf",
        &[
            "buffer 0",
            "external file 'BoxTextured0.bin'",
            "select both files",
        ],
    );
}

/// trimesh writes each buffer to a `.bin` of its own (the indices, then
/// the positions): the `.gltf` with both reads as trimesh's `.glb`.
#[test]
fn trimesh_gltf_with_two_bins_reads_as_its_glb() {
    let gltf = data!("mesh/trimesh/trimesh-icosphere.gltf");
    let needed = needed_files(gltf, "trimesh-icosphere.gltf");
    assert_eq!(needed, ["gltf_buffer_0.bin", "gltf_buffer_1.bin"]);
    let files = ExternalFiles::new()
        .with("gltf_buffer_1.bin", data!("mesh/trimesh/gltf_buffer_1.bin"))
        .with("gltf_buffer_0.bin", data!("mesh/trimesh/gltf_buffer_0.bin"));
    let opts = ImportOptions::DEFAULT;
    let m = import_mesh_with(gltf, "trimesh-icosphere.gltf", &opts, &files).unwrap();
    assert_eq!(m.external_files, needed);
    let glb = import(
        data!("mesh/trimesh/trimesh-icosphere.glb"),
        "trimesh-icosphere.glb",
    );
    assert_eq!(m.mesh, glb.mesh);
    assert_eq!(m.mesh.triangle_count(), 80);
    // A 10 m sphere in metres.
    assert_bbox(&m.mesh, [-10_000.0; 3], [10_000.0; 3], 1e-3);
    // Without the positions' file, it is the one named.
    let one =
        ExternalFiles::new().with("gltf_buffer_0.bin", data!("mesh/trimesh/gltf_buffer_0.bin"));
    let e = import_mesh_with(gltf, "trimesh-icosphere.gltf", &opts, &one)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("buffer 1 ") && e.contains("'gltf_buffer_1.bin'"),
        "{e}"
    );
}

/// assimp's IndexOutOfRange model: a COLLADA2GLTF box whose first index
/// is 255 of 24 vertices. With its `.bin` it is read, and refused naming
/// the index and the vertex count.
#[test]
fn gltf_index_out_of_range_in_its_bin_is_named() {
    let files = ExternalFiles::new().with("IndexOutOfRange.bin", data!("mesh/IndexOutOfRange.bin"));
    let e = import_mesh_with(
        data!("mesh/IndexOutOfRange.gltf"),
        "IndexOutOfRange.gltf",
        &ImportOptions::DEFAULT,
        &files,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "IndexOutOfRange.gltf: mesh 0 primitive 0: index 0 refers to vertex 255, but POSITION \
         has 24 elements"
    );
}

// ------------------------------------------------------------------ SVG

fn svg(bytes: &[u8], file: &str) -> DrawnPath {
    load_path(bytes, file).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn svg_error(bytes: &[u8], file: &str) -> String {
    match load_path(bytes, file) {
        Ok(d) => panic!("{file}: read {} subpaths", d.subpaths.len()),
        Err(e) => e.to_string(),
    }
}

fn svg_bbox(d: &DrawnPath) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in d.subpaths.iter().flat_map(|s| &s.points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// 24 px = 6.35 mm at 96 px/in; the y axis flips to point up.
const PX: f64 = 25.4 / 96.0;

/// Tabler's outline star: one stroked polyline of 10 segments; the icon's
/// invisible 24x24 bounding rectangle (stroke and fill none) is dropped.
#[test]
fn tabler_star_icon() {
    let d = svg(data!("svg/tabler-star.svg"), "tabler-star.svg");
    assert_eq!(d.subpaths.len(), 1);
    let s = &d.subpaths[0];
    // Not closed by Z: it ends 0.008 px from its start.
    assert!(!s.closed);
    assert_eq!(s.points.len(), 11);
    assert_eq!(s.points[0], DVec2::new(12.0 * PX, -17.75 * PX));
    assert!(d.notes.iter().any(|n| n.contains("no stroke and no fill")));
    let (lo, hi) = svg_bbox(&d);
    assert!(lo.x > 0.0 && hi.x < 24.0 * PX && lo.y > -24.0 * PX && hi.y < 0.0);
}

/// Tabler's circle is two arcs (`a9 9 0 1 0 18 0`): every flattened point
/// lies on the 9 px circle about (12, 12) px.
#[test]
fn tabler_circle_arcs_flatten_onto_the_circle() {
    let d = svg(data!("svg/tabler-circle.svg"), "tabler-circle.svg");
    assert_eq!(d.subpaths.len(), 1);
    let s = &d.subpaths[0];
    assert!(s.points.len() > 100);
    let centre = DVec2::new(12.0 * PX, -12.0 * PX);
    for p in &s.points {
        let r = p.distance(centre);
        assert!((r - 9.0 * PX).abs() < 0.01, "point {p} at radius {r} mm");
    }
    let circumference = 2.0 * std::f64::consts::PI * 9.0 * PX;
    assert!((s.length_mm() - circumference).abs() < 0.01 * circumference);
}

/// Bootstrap's logo: 16 px square, five filled outlines (rounded square
/// corners are arcs), all closed.
#[test]
fn bootstrap_logo_icon() {
    let d = svg(
        data!("svg/bootstrap-bootstrap.svg"),
        "bootstrap-bootstrap.svg",
    );
    assert_eq!(d.subpaths.len(), 5);
    assert!(d.subpaths.iter().all(|s| s.closed));
    let (lo, hi) = svg_bbox(&d);
    assert!(lo.abs_diff_eq(DVec2::new(0.0, -16.0 * PX), 1e-6), "{lo}");
    assert!(hi.abs_diff_eq(DVec2::new(16.0 * PX, 0.0), 1e-6), "{hi}");
}

/// An Inkscape drawing on an A4 page in mm, with group transforms: 9 closed
/// outlines, inside the 210 x 297 mm page. Inkscape 0.39 drew it in px at
/// 90 per inch (no viewBox maps them to the page): read so, it spans the
/// page with margins of 3.3 and 4.4 mm (at CSS's 96, 3.1 and 17.3 mm).
#[test]
fn openclipart_a4_drawing_in_mm() {
    let d = svg(
        data!("svg/openclipart-scale_01.svg"),
        "openclipart-scale_01.svg",
    );
    assert_eq!(d.subpaths.len(), 9);
    assert!(d.subpaths.iter().all(|s| s.closed));
    let (lo, hi) = svg_bbox(&d);
    assert!(lo.x >= 0.0 && hi.x <= 210.0 && lo.y >= -297.0 && hi.y <= 0.0);
    assert!(hi.x - lo.x > 180.0, "width {} mm", hi.x - lo.x);
    let length: f64 = d.subpaths.iter().map(|s| s.length_mm()).sum();
    assert!((length - 1223.54).abs() < 1.0, "{length} mm");
    assert!(lo.x > 3.0 && hi.x > 205.0, "{lo} {hi}");
}

/// A Tango icon (Inkscape, gradients, nested transforms): 17 outlines.
#[test]
fn tango_icon_with_gradients_and_transforms() {
    let d = svg(data!("svg/tango-go-home.svg"), "tango-go-home.svg");
    assert_eq!(d.subpaths.len(), 17);
    assert!(d.subpaths.iter().all(|s| s.closed));
    let (lo, hi) = svg_bbox(&d);
    // A 48 px icon of Inkscape 0.46, which drew at 90 px per inch: 13.5 mm.
    let px = 25.4 / 90.0;
    assert!(lo.x >= 0.0 && hi.x <= 48.0 * px && lo.y >= -48.0 * px && hi.y <= 0.0);
    assert!(hi.x > 40.0 * px, "{hi}");
}

/// A swatch file with only gradient definitions: genuinely nothing to print.
#[test]
fn openclipart_gradient_swatch_has_nothing_printable() {
    let e = svg_error(
        data!("svg/openclipart-gradient-americana.svg"),
        "openclipart-gradient-americana.svg",
    );
    assert!(e.starts_with("openclipart-gradient-americana.svg"), "{e}");
    assert!(e.contains("nothing printable"), "{e}");
    assert!(e.contains("contains no shapes"), "{e}");
}

/// Text only (no fonts are loaded): the error says to convert to paths.
#[test]
fn openclipart_text_only_drawing_says_convert_text_to_paths() {
    let e = svg_error(
        data!("svg/openclipart-large_braces_amos_01.svg"),
        "openclipart-large_braces_amos_01.svg",
    );
    assert!(e.contains("nothing printable"), "{e}");
    assert!(e.contains("text element(s) skipped"), "{e}");
    assert!(e.contains("convert text to paths"), "{e}");
}

// ------------------------------------------------------------------ plan

/// Every X/Y/Z word of every G0/G1 move.
fn moves(gcode: &str) -> Vec<DVec3> {
    let mut at = DVec3::ZERO;
    let mut out = Vec::new();
    for line in gcode.lines() {
        let code = line.split(';').next().unwrap_or("");
        let mut words = code.split_whitespace();
        if !matches!(words.next(), Some("G0" | "G1")) {
            continue;
        }
        for w in words {
            let (axis, value) = w.split_at(1);
            let v: f64 = match axis {
                "X" | "Y" | "Z" => value.parse().unwrap_or(f64::NAN),
                _ => continue,
            };
            match axis {
                "X" => at.x = v,
                "Y" => at.y = v,
                _ => at.z = v,
            }
        }
        out.push(at);
    }
    out
}

/// The 3ds Max export, registered into the printer's build volume by three
/// picked points, with the Tabler star placed over its bbox centre: a plan
/// with finite G-code inside the build volume that follows the surface.
#[test]
fn plan_over_a_cad_export_writes_finite_gcode() {
    let scan = data!("mesh/3DSMaxExport.STL");
    let raw = import(scan, "3DSMaxExport.STL");
    let (lo, hi) = raw.mesh.bbox().unwrap();
    let shift = DVec3::new(20.0, 20.0, 5.0) - lo;
    let picked = vec![
        lo,
        DVec3::new(hi.x, lo.y, lo.z),
        DVec3::new(lo.x, hi.y, lo.z),
    ];
    let registration = RegistrationSettings {
        fiducials: FiducialSource::Points(picked.clone()),
        printer_points: picked.iter().map(|p| *p + shift).collect(),
        ..Default::default()
    };
    let prepared = prepare_scan(
        scan,
        "3DSMaxExport.STL",
        &ImportOptions::DEFAULT,
        &registration,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(prepared.registration.rms_mm < 1e-9);
    let (slo, shi) = prepared.surface.bbox();
    assert_close(slo, lo + shift, 1e-9, "registered bbox min");

    let star = data!("svg/tabler-star.svg");
    let (dlo, dhi) = svg_bbox(&svg(star, "tabler-star.svg"));
    let extent = (shi - slo).truncate();
    let scale = (0.5 * extent.x / (dhi.x - dlo.x)).min(0.5 * extent.y / (dhi.y - dlo.y));
    let centre = ((slo + shi) * 0.5).truncate();
    let settings = PlanSettings {
        placement: Placement {
            offset_mm: centre - (dlo + dhi) * 0.5 * scale,
            rotation_deg: 0.0,
            scale,
        },
        ..PlanSettings::default()
    };
    let profile = MachineProfile::builtin("marlin").expect("marlin profile");
    // Seen from above the model is mostly gaps: 12 % of the star lies over
    // its surface, which is refused unless the risk is accepted (QA F10: a
    // script saw exit 0 for 5 % of a drawing printed).
    let e = run_on(
        &prepared,
        star,
        "tabler-star.svg",
        &settings,
        &profile,
        false,
    )
    .err()
    .expect("most of the star is off the model");
    assert!(
        matches!(e, pcpp::Error::MostlyOffScan { percent, .. } if percent < 50.0),
        "{e}"
    );
    let out = run_on(
        &prepared,
        star,
        "tabler-star.svg",
        &settings,
        &profile,
        true,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        out.gcode
            .contains("written only because the risk was accepted: only ")
            && out.gcode.contains("lie over the scan and are printed"),
        "{}",
        &out.gcode[..out.gcode.len().min(3000)]
    );

    assert!(out.plan.uncleared.is_empty());
    assert!(!out.plan.pieces.is_empty());
    // The star crosses gaps in this open-bottomed model; those are reported.
    assert!(
        out.report
            .warnings
            .iter()
            .any(|w| w.contains("path 'path #2'")),
        "{:?}",
        out.report.warnings
    );
    let printed: usize = out.plan.pieces.iter().map(|p| p.toolpath.len()).sum();
    assert!(printed >= 20, "{printed} toolpath points");
    for p in out.plan.pieces.iter().flat_map(|p| &p.toolpath) {
        assert!(p.is_finite());
        // On the star's footprint, and on or above the surface's range.
        assert!(
            p.x > slo.x && p.x < shi.x && p.y > slo.y && p.y < shi.y,
            "{p}"
        );
        assert!(p.z >= slo.z && p.z <= shi.z + 5.0, "{p}");
    }
    let moves = moves(&out.gcode);
    assert!(moves.len() > printed, "{} moves", moves.len());
    for m in &moves {
        assert!(m.is_finite(), "non-finite move in G-code");
        assert!(
            profile.build_volume.contains(*m),
            "{m} outside the build volume"
        );
    }
    let code: String = out
        .gcode
        .lines()
        .map(|l| l.split(';').next().unwrap_or(""))
        .collect();
    assert!(!code.contains("NaN") && !code.contains("inf"));
    // Safe along every move, by the independent oracle, on the registered
    // scan.
    let oracle = crate::bruteforce::check_gcode(
        &out.gcode,
        prepared.surface.mesh(),
        settings.nozzle.outer_diameter_mm,
        settings.process.tolerance_mm,
    );
    assert_eq!(oracle.too_close, 0, "{oracle:?}");
    assert!(oracle.min_distance_mm >= settings.process.tolerance_mm);
}

/// Promise 2 on a real scan with real drawings nobody here wrote: the
/// Stanford bunny (in cm, +Y up: 100 mm tall) under seven Simple Icons
/// logos at 24 mm, centred on it. On each, `even` prints with no more
/// predicted defects (section 7) than any of the paper's planners whose
/// moves keep tol, and its print moves keep tol by the independent oracle.
/// With only the least-squares fit of the tip's progress (before the fits
/// were tried per stretch) `even` had 2-6 times `slope`'s defects on these
/// drawings: at every sharp valley or turn of the drawing it pooled a
/// dozen points onto one place, and they floated.
#[test]
fn even_prints_real_logos_on_the_bunny_no_worse_than_a_safe_paper_planner() {
    use pcpp::mesh::{ImportOptions, ScanUnits, UpAxis};
    use pcpp::pipeline;
    use pcpp::surface::Surface;

    let options = ImportOptions {
        units: Some(ScanUnits::Cm),
        up_axis: Some(UpAxis::Y),
        ..ImportOptions::DEFAULT
    };
    let scan = pipeline::load_scan(
        data!("mesh/stanford-bunny.ply"),
        "stanford-bunny.ply",
        &options,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mesh = scan.mesh.clone();
    let surface = Surface::new(scan.mesh).unwrap();
    let logos: [(&str, &[u8]); 7] = [
        ("abusedotch", data!("svg/simple-icons-abusedotch.svg")),
        ("actix", data!("svg/simple-icons-actix.svg")),
        ("discover", data!("svg/simple-icons-discover.svg")),
        ("eyeem", data!("svg/simple-icons-eyeem.svg")),
        ("postmates", data!("svg/simple-icons-postmates.svg")),
        ("rancher", data!("svg/simple-icons-rancher.svg")),
        ("vulkan", data!("svg/simple-icons-vulkan.svg")),
    ];
    for (name, bytes) in logos {
        let drawn = load_path(bytes, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (settings, plans) = compare_centred(&surface, &drawn, name);
        let even = even_no_worse_than_the_safe_paper_planners(&plans, name);
        assert_eq!(even.quality.contact_pct, 0.0, "{name}");
        assert_eq!(even.motion.touching_moves, 0, "{name}");
        assert!(even.uncleared.is_empty(), "{name}");
        oracle_clears_every_move(even, &mesh, &settings, name);
    }
}

/// `drawn` centred on `surface` at its own size and turn, compared with
/// every planner at the default settings: (those settings, the plans).
fn compare_centred(
    surface: &pcpp::surface::Surface,
    drawn: &pcpp::pipeline::DrawnPath,
    case: &str,
) -> (PlanSettings, Vec<pcpp::pipeline::Plan>) {
    let (lo, hi) = surface.bbox();
    let (placement, _) = pcpp::placement::centre_drawing(
        &drawn.subpaths,
        (lo.truncate(), hi.truncate()),
        &Placement::IDENTITY,
        false,
    )
    .unwrap();
    let settings = PlanSettings {
        placement,
        ..PlanSettings::default()
    };
    let plans = pcpp::pipeline::compare(surface, &drawn.subpaths, &settings)
        .unwrap_or_else(|e| panic!("{case}: {e}"));
    (settings, plans)
}

/// Promise 2: `even`'s plan of `plans`, which predicts no more defects
/// (section 7, a share of the points) than any of the paper's planners
/// whose moves keep tol and whose nozzle meets nothing.
fn even_no_worse_than_the_safe_paper_planners<'p>(
    plans: &'p [pcpp::pipeline::Plan],
    case: &str,
) -> &'p pcpp::pipeline::Plan {
    use pcpp::planners::PlannerKind;
    let by = |k: PlannerKind| plans.iter().find(|p| p.planner == k).unwrap();
    let even = by(PlannerKind::Even);
    let safe_paper = [
        PlannerKind::Constant,
        PlannerKind::Slope,
        PlannerKind::Pcpp,
        PlannerKind::PcppGuarded,
    ]
    .into_iter()
    .map(by)
    .filter(|p| p.motion.touching_moves == 0 && p.quality.contact_pct == 0.0);
    for p in safe_paper {
        assert!(
            even.quality.defect_pct() <= p.quality.defect_pct(),
            "{case}: even {:.2}% defects, {} {:.2}%",
            even.quality.defect_pct(),
            p.planner.name(),
            p.quality.defect_pct()
        );
    }
    even
}

/// Every print move of `plan` (waypoints included), piece by piece,
/// followed by the oracle that shares no code with the planner: none
/// comes closer than tol to `mesh`.
fn oracle_clears_every_move(
    plan: &pcpp::pipeline::Plan,
    mesh: &pcpp::mesh::TriMesh,
    settings: &PlanSettings,
    case: &str,
) {
    for piece in &plan.pieces {
        let gcode: String = piece
            .moves
            .iter()
            .map(|m| format!("G1 X{:.6} Y{:.6} Z{:.6}\n", m.x, m.y, m.z))
            .collect();
        let oracle = crate::bruteforce::check_gcode(
            &gcode,
            mesh,
            settings.nozzle.outer_diameter_mm,
            settings.process.tolerance_mm,
        );
        assert_eq!(oracle.too_close, 0, "{case}: {oracle:?}");
    }
}

/// Promise 2 with the paper's large nozzle (QA round 17 F9: with d 0.8,
/// do 1.2 and tol 0.3, `even` had one or two more defects than
/// `pcpp-guarded` on 2 of 750 real scan and drawing pairs, drawings with
/// detail near the nozzle's size). The same real bunny and logos, read in
/// cm and in inches, at scales 1 and 2: `even` has no more defects than
/// any of the paper's planners whose moves keep tol, a piece of it taken
/// from `pcpp-guarded` where that predicts fewer (and the plan says so),
/// and its print moves keep tol by the independent oracle.
#[test]
fn even_is_no_worse_than_a_safe_paper_planner_with_the_large_nozzle() {
    use pcpp::mesh::{ImportOptions, ScanUnits, UpAxis};
    use pcpp::params::{Nozzle, Process};
    use pcpp::pipeline;
    use pcpp::placement::centre_drawing;
    use pcpp::planners::PlannerKind;
    use pcpp::surface::Surface;

    let logos: [(&str, &[u8]); 4] = [
        ("discover", data!("svg/simple-icons-discover.svg")),
        ("postmates", data!("svg/simple-icons-postmates.svg")),
        ("rancher", data!("svg/simple-icons-rancher.svg")),
        ("vulkan", data!("svg/simple-icons-vulkan.svg")),
    ];
    let mut fell_back = 0;
    for units in [ScanUnits::Cm, ScanUnits::In] {
        let options = ImportOptions {
            units: Some(units),
            up_axis: Some(UpAxis::Y),
            ..ImportOptions::DEFAULT
        };
        let scan = pipeline::load_scan(
            data!("mesh/stanford-bunny.ply"),
            "stanford-bunny.ply",
            &options,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mesh = scan.mesh.clone();
        let surface = Surface::new(scan.mesh).unwrap();
        let (lo, hi) = surface.bbox();
        for (name, bytes) in logos {
            let drawn = load_path(bytes, name).unwrap_or_else(|e| panic!("{name}: {e}"));
            for scale in [1.0, 2.0] {
                let case = format!("{name} on the bunny in {units}, x{scale}");
                let current = Placement {
                    scale,
                    ..Placement::IDENTITY
                };
                let (placement, _) = centre_drawing(
                    &drawn.subpaths,
                    (lo.truncate(), hi.truncate()),
                    &current,
                    false,
                )
                .unwrap();
                let settings = PlanSettings {
                    placement,
                    nozzle: Nozzle {
                        inner_diameter_mm: 0.8,
                        outer_diameter_mm: 1.2,
                    },
                    process: Process {
                        tolerance_mm: 0.3,
                        ..Process::DEFAULT
                    },
                    ..PlanSettings::default()
                };
                let plans = pipeline::compare(&surface, &drawn.subpaths, &settings)
                    .unwrap_or_else(|e| panic!("{case}: {e}"));
                let by = |k: PlannerKind| plans.iter().find(|p| p.planner == k).unwrap();
                let even = by(PlannerKind::Even);
                assert_eq!(even.motion.touching_moves, 0, "{case}");
                assert!(even.uncleared.is_empty(), "{case}");
                let defects = |p: &pipeline::Plan| {
                    p.pieces
                        .iter()
                        .flat_map(|piece| &piece.quality)
                        .filter(|q| q.defect != pcpp::quality::Defect::Good)
                        .count()
                };
                for p in PlannerKind::ALL.map(by) {
                    if p.motion.touching_moves == 0 && p.quality.contact_pct == 0.0 {
                        assert!(
                            defects(even) <= defects(p),
                            "{case}: even {} defects, {} {}",
                            defects(even),
                            p.planner.name(),
                            defects(p)
                        );
                    }
                }
                fell_back += usize::from(
                    even.warnings
                        .iter()
                        .any(|w| w.contains("(pcpp-guarded) predicts fewer defects")),
                );
                oracle_clears_every_move(even, &mesh, &settings, &case);
            }
        }
    }
    assert!(
        fell_back > 0,
        "no piece of even's was taken from pcpp-guarded"
    );
}

/// A phone scan as the web serves it: a Polycam scan of a cookie, optimised
/// by glTF-Transform (its textures turned into WebP, EXT_texture_webp
/// required, each texture's image named only in that extension; the
/// geometry in a separate `.optimized.bin`). It was refused "not a valid
/// glTF 2.0 file: textures[0].source: Missing data". It is read (the .bin
/// the only file it needs: the .webp images are never asked for), and
/// planned on: a real logo centred on its crust, `even` no worse than any
/// of the paper's planners whose moves keep tol, and every print move
/// clear by the independent oracle.
#[test]
fn a_gltf_transform_phone_scan_with_webp_textures_is_read_and_planned_on() {
    use pcpp::surface::Surface;

    let gltf = data!("mesh/phone-scan/molasses-cookies.gltf");
    let needed = needed_files(gltf, "molasses-cookies.gltf");
    assert_eq!(needed, ["molasses-cookies.optimized.bin"]);
    let files = ExternalFiles::new().with(
        "molasses-cookies.optimized.bin",
        data!("mesh/phone-scan/molasses-cookies.optimized.bin"),
    );
    let m = import_mesh_with(
        gltf,
        "molasses-cookies.gltf",
        &ImportOptions::DEFAULT,
        &files,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // 6454 triangles; glTF's metres and +Y up, the node's translation
    // applied: 346 x 341 mm, standing 0..46 mm (the site scaled its scans).
    assert_eq!(m.mesh.triangles.len(), 6454);
    assert_bbox(
        &m.mesh,
        [-173.2145, -170.6982, 0.0],
        [173.2145, 170.6982, 46.0129],
        0.001,
    );
    let mesh = m.mesh.clone();
    let surface = Surface::new(m.mesh).unwrap();
    let drawn = load_path(data!("svg/simple-icons-vulkan.svg"), "vulkan.svg").unwrap();
    let (settings, plans) = compare_centred(&surface, &drawn, "cookie");
    let even = even_no_worse_than_the_safe_paper_planners(&plans, "cookie");
    assert!(even.uncleared.is_empty());
    assert_eq!(even.motion.touching_moves, 0);
    // The logo's 14 outlines, each printed.
    let points: usize = even.pieces.iter().map(|p| p.toolpath.len()).sum();
    assert!(
        even.pieces.len() == 14 && points > 150,
        "{} pieces, {points} points",
        even.pieces.len()
    );
    oracle_clears_every_move(even, &mesh, &settings, "cookie");
}
