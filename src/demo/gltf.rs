//! A mesh written as glTF 2.0, as exporters write it: for the tests of a
//! `.gltf` with its buffer in a separate `.bin` (Blender's "glTF Separate",
//! Sketchfab's downloads) against the same scan as one `.glb`.

use crate::mesh::TriMesh;

/// The JSON of a glTF holding `mesh` (mm, +Z up) in metres and +Y up, as
/// the format defines them (a root node's matrix turns and scales it), f32
/// positions and u32 indices in buffer 0 of `length` bytes at `uri`, or in
/// the GLB's binary chunk without one.
fn json(mesh: &TriMesh, length: usize, uri: Option<&str>) -> String {
    let n = mesh.vertices.len();
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for v in &mesh.vertices {
        for (k, c) in [v.x, v.y, v.z].into_iter().enumerate() {
            lo[k] = lo[k].min(c as f32);
            hi[k] = hi[k].max(c as f32);
        }
    }
    let uri = uri.map(|u| format!(r#","uri":"{u}""#)).unwrap_or_default();
    format!(
        r#"{{"asset":{{"version":"2.0","generator":"pcpp demo"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"matrix":[0.001,0,0,0,0,0,-0.001,0,0,0.001,0,0,0,0,0,1],"children":[1]}},{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":{lo:?},"max":{hi:?}}},
{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{}}},{{"buffer":0,"byteOffset":{},"byteLength":{}}}],
"buffers":[{{"byteLength":{length}{uri}}}]}}
"#,
        3 * mesh.triangles.len(),
        12 * n,
        12 * n,
        12 * mesh.triangles.len(),
    )
}

/// The buffer: f32 positions, then u32 indices.
fn buffer(mesh: &TriMesh) -> Vec<u8> {
    let mut bin = Vec::with_capacity(12 * (mesh.vertices.len() + mesh.triangles.len()));
    for v in &mesh.vertices {
        for c in [v.x, v.y, v.z] {
            bin.extend_from_slice(&(c as f32).to_le_bytes());
        }
    }
    for k in mesh.triangles.iter().flatten() {
        bin.extend_from_slice(&k.to_le_bytes());
    }
    bin
}

/// `mesh` (mm, +Z up) as a `.gltf` whose buffer is the separate file
/// `bin_uri` (written into the JSON as given, so percent-encoded where it
/// needs to be): (the `.gltf`'s bytes, the `.bin`'s bytes).
pub fn to_gltf_separate(mesh: &TriMesh, bin_uri: &str) -> (Vec<u8>, Vec<u8>) {
    let bin = buffer(mesh);
    (json(mesh, bin.len(), Some(bin_uri)).into_bytes(), bin)
}

/// The same glTF as [`to_gltf_separate`] as one `.glb`.
pub fn to_glb(mesh: &TriMesh) -> Vec<u8> {
    let bin = buffer(mesh);
    glb_container(json(mesh, bin.len(), None).as_bytes(), &bin)
}

/// A `.glb` holding the glTF JSON `json` and the binary chunk `bin`, each
/// chunk padded to 4 bytes as the format asks (JSON with spaces, BIN with
/// zeros).
pub fn glb_container(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let json_chunk = json.len().next_multiple_of(4);
    let bin_chunk = bin.len().next_multiple_of(4);
    let total = 12 + 8 + json_chunk + 8 + bin_chunk;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_chunk as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(out.len() + json_chunk - json.len(), b' ');
    out.extend_from_slice(&(bin_chunk as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out.resize(total, 0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{import_mesh, import_mesh_with, ExternalFiles, ImportOptions, MeshFormat};

    #[test]
    fn separate_and_binary_read_the_same_mesh_in_mm() {
        let m = TriMesh::height_field(&[0.0, 10.0, 20.0], &[0.0, 5.0], |x, y| x * 0.1 + y);
        let (gltf, bin) = to_gltf_separate(&m, "part%201.bin");
        let files = ExternalFiles::new().with("part 1.bin", bin);
        let a = import_mesh_with(&gltf, "part.gltf", &ImportOptions::DEFAULT, &files).unwrap();
        let b = import_mesh(&to_glb(&m), "part.glb", &ImportOptions::DEFAULT).unwrap();
        assert_eq!((a.format, b.format), (MeshFormat::Gltf, MeshFormat::Glb));
        assert_eq!(a.mesh, b.mesh);
        assert_eq!(a.external_files, ["part 1.bin"]);
        assert!(b.external_files.is_empty());
        assert_eq!(a.mesh.triangles, m.triangles);
        // To f32's precision (the node's 0.001 is an f32 too).
        for (got, want) in a.mesh.vertices.iter().zip(&m.vertices) {
            assert!(
                (*got - *want).length() < 1e-6 * want.length().max(1.0),
                "{got} {want}"
            );
        }
    }
}
