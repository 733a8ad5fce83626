//! The page's scan bindings: [`ScanBuffer`] (a file's bytes, and the
//! files it names, written into wasm memory by the worker) and
//! [`ScanImport`] (the staged import and registration, whose last step
//! makes the [`Session`] that plans). Part of [`crate::wasm`]: they only
//! convert types; every decision is made by [`crate::job`] and the core.

use serde::Serialize;
use sha2::{Digest, Sha256};
use wasm_bindgen::prelude::*;

use super::session::Session;
use super::{check_scan_size, core_err, demo_part_named, from_js, kind_err, to_js, MIB};
use crate::demo::{self, parts::DemoPart};
use crate::fiducials::{find_fiducials_in, Fiducial};
use crate::job::{self, InputFile, PreparedScan, RegistrationSettings};
use crate::mesh::{ExternalFiles, ImportOptions, ImportedMesh, Topology};
use crate::pipeline;
use crate::registration::{Registration, RegistrationMethod};

/// A scan file's bytes, written into wasm memory chunk by chunk as the
/// worker reads the file (`Blob.slice().arrayBuffer()`), so a large scan is
/// never held whole by JS nor passed through a string. The first of the
/// staged steps that [`job::prepare_scan`] runs in one call; the page shows
/// progress between them: [`ScanBuffer::import_scan`], [`ScanImport::register`],
/// [`ScanImport::index`].
///
/// A `.gltf` whose buffers are separate files ([`ScanBuffer::external_files`]
/// lists them) gets each as a ScanBuffer of its own, written the same way
/// and handed over with [`ScanBuffer::add_external_file`] before the import.
#[wasm_bindgen]
pub struct ScanBuffer {
    name: String,
    size: usize,
    bytes: Vec<u8>,
    /// The report's sha256, chunk by chunk as the bytes arrive: V8 runs a
    /// long single call in its baseline tier (no on-stack replacement for
    /// wasm), where hashing a large file at once took 16 times longer.
    /// `None` when it is found elsewhere (the page's second worker,
    /// [`Sha256Stream`]) and given to the session ([`Session::set_scan_sha256`]).
    sha256: Option<Sha256>,
    /// The files given with the scan, by name, and their SHA-256s.
    external: ExternalFiles,
    external_sha256: Vec<[u8; 32]>,
}

/// A file's SHA-256 found chunk by chunk, for the page's second worker: it
/// reads the scan's file beside the worker that imports it, so the hash is
/// off the import's path (as the CLI hashes on a second thread).
#[wasm_bindgen]
pub struct Sha256Stream {
    hasher: Sha256,
}

#[wasm_bindgen]
impl Sha256Stream {
    #[wasm_bindgen(constructor)]
    #[allow(clippy::new_without_default)]
    pub fn new() -> Sha256Stream {
        Sha256Stream {
            hasher: Sha256::new(),
        }
    }

    /// Hashes the next chunk of the file.
    pub fn update(&mut self, chunk: &[u8]) {
        job::hash_in_pieces(&mut self.hasher, chunk);
    }

    /// The digest (32 bytes).
    pub fn finish(self) -> Vec<u8> {
        self.hasher.finalize().to_vec()
    }
}

/// A file a `.gltf` needs besides itself, as the page is told of it.
#[derive(Serialize)]
struct ExternalView<'a> {
    buffer: usize,
    uri: &'a str,
    /// Decoded, relative to the `.gltf`.
    path: &'a str,
    /// Its last component: the name of the file to select.
    file_name: &'a str,
}

#[wasm_bindgen]
impl ScanBuffer {
    /// Room for a file of `size` bytes; refuses sizes past the page's limit
    /// ([`check_scan_size`]) and, without aborting, sizes the tab's memory
    /// cannot hold. With `hashed` false the file's SHA-256 is not found
    /// here: the page finds it beside the import, in another worker
    /// ([`Sha256Stream`]), as the CLI does on a second thread, and gives it
    /// to the session before it plans ([`Session::set_scan_sha256`]).
    #[wasm_bindgen(constructor)]
    pub fn new(name: &str, size: f64, hashed: Option<bool>) -> Result<ScanBuffer, JsValue> {
        check_scan_size(name, size)?;
        let size = size as usize;
        let mut bytes = Vec::new();
        bytes.try_reserve_exact(size).map_err(|_| {
            kind_err(
                "limit",
                &format!(
                    "{name}: this tab has no room for the file's {:.1} MiB; close other tabs \
                     or reload the page (its memory only grows), decimate the scan, or plan it \
                     with the command line",
                    size as f64 / MIB
                ),
            )
        })?;
        Ok(ScanBuffer {
            name: name.to_string(),
            size,
            bytes,
            sha256: hashed.unwrap_or(true).then(Sha256::new),
            external: ExternalFiles::new(),
            external_sha256: Vec::new(),
        })
    }

    /// The demo scan (the paper's test part as binary PLY), already full.
    pub fn demo() -> ScanBuffer {
        ScanBuffer::full(DemoPart::TestPart)
    }

    /// A generated demo part's scan ([`demo_part_scan`]), already full.
    #[wasm_bindgen(js_name = demoPart)]
    pub fn demo_part(name: &str) -> Result<ScanBuffer, JsError> {
        Ok(ScanBuffer::full(demo_part_named(name)?))
    }

    /// Appends the next chunk of the file.
    pub fn write(&mut self, chunk: &[u8]) -> Result<(), JsError> {
        if self.bytes.len() + chunk.len() > self.size {
            return Err(JsError::new(&format!(
                "{}: the file grew while it was read (more than its {} bytes); open it again",
                self.name, self.size
            )));
        }
        self.bytes.extend_from_slice(chunk);
        if let Some(h) = &mut self.sha256 {
            job::hash_in_pieces(h, chunk);
        }
        Ok(())
    }

    /// Bytes written so far.
    pub fn received(&self) -> usize {
        self.bytes.len()
    }

    /// The files the scan needs besides itself, once it is written whole
    /// (a `.gltf`'s buffers in separate files,
    /// [`crate::mesh::external_files_needed`]): `[{buffer, uri, path,
    /// file_name}]`, none for other formats; a remote or absolute buffer
    /// URI is an error (kind `mesh`) naming the buffer and the URI.
    #[wasm_bindgen(js_name = externalFiles)]
    pub fn external_files(&self) -> Result<JsValue, JsValue> {
        self.check_whole()?;
        let refs = crate::mesh::external_files_needed(&self.bytes, &self.name)
            .map_err(|e| core_err(e.into()))?;
        let views: Vec<ExternalView> = refs
            .iter()
            .map(|r| ExternalView {
                buffer: r.buffer,
                uri: &r.uri,
                path: &r.path,
                file_name: r.file_name(),
            })
            .collect();
        Ok(to_js(&views)?)
    }

    /// Hands over `file`, a file the scan names (written whole into its own
    /// ScanBuffer, named as the browser names it), for the import. Refused
    /// (kind `limit`) when the scan and its files together pass the page's
    /// limit.
    #[wasm_bindgen(js_name = addExternalFile)]
    pub fn add_external_file(&mut self, file: ScanBuffer) -> Result<(), JsValue> {
        file.check_whole()?;
        let total = self.size + self.external.iter().map(|(_, b)| b.len()).sum::<usize>();
        check_scan_size(
            &format!("{} with {}", self.name, file.name),
            (total + file.size) as f64,
        )?;
        let digest = match file.sha256 {
            Some(h) => h.finalize().into(),
            None => job::sha256(&file.bytes),
        };
        self.external_sha256.push(digest);
        self.external.add(file.name, file.bytes);
        Ok(())
    }

    /// Imports the bytes ([`pipeline::load_scan`]) with `scan`
    /// (ImportOptions); the bytes are freed once read, before the next step
    /// allocates the search structure.
    #[wasm_bindgen(js_name = importScan)]
    pub fn import_scan(self, scan: JsValue) -> Result<ScanImport, JsValue> {
        self.check_whole()?;
        let options: ImportOptions = from_js("scan settings", scan)?;
        let imported = pipeline::load_scan_with(&self.bytes, &self.name, &options, &self.external)
            .map_err(core_err)?;
        let external = InputFile::external_of(&imported, &self.external, &self.external_sha256);
        // (An empty hash until the page gives it: `Session::set_scan_sha256`.)
        let digest = self
            .sha256
            .map(|h| h.finalize().to_vec())
            .unwrap_or_default();
        let file = InputFile::from_digest(&self.name, self.bytes.len(), &digest)
            .with_external_files(external);
        Ok(ScanImport {
            file,
            imported,
            topology: None,
            registered: None,
        })
    }
}

impl ScanBuffer {
    /// Ok once every byte of the file was written.
    fn check_whole(&self) -> Result<(), JsValue> {
        if self.bytes.len() != self.size {
            return Err(JsError::new(&format!(
                "{}: only {} of {} bytes were read; open the file again",
                self.name,
                self.bytes.len(),
                self.size
            ))
            .into());
        }
        Ok(())
    }

    /// A demo part's scan as the binary PLY `pcpp demo --part` writes.
    fn full(part: DemoPart) -> ScanBuffer {
        let bytes = demo::to_binary_ply(&part.mesh());
        let mut sha256 = Sha256::new();
        job::hash_in_pieces(&mut sha256, &bytes);
        ScanBuffer {
            name: part.scan_name(),
            size: bytes.len(),
            bytes,
            sha256: Some(sha256),
            external: ExternalFiles::new(),
            external_sha256: Vec::new(),
        }
    }
}

/// A scan imported (scanner frame), not yet registered or indexed.
#[wasm_bindgen]
pub struct ScanImport {
    file: InputFile,
    imported: ImportedMesh,
    /// Its boundary edges and owners (one pass over the edges for the
    /// holes and the index), found by the first [`ScanImport::register`]
    /// and kept for every registration after it.
    topology: Option<Topology>,
    /// The fiducial holes (scanner frame) and the registration found with
    /// them, once [`ScanImport::register`] succeeded.
    registered: Option<(Vec<Fiducial>, Registration, RegistrationMethod)>,
}

#[wasm_bindgen]
impl ScanImport {
    pub fn triangles(&self) -> usize {
        self.imported.mesh.triangle_count()
    }

    /// Finds the fiducial holes (in the scanner frame, ranked for the
    /// settings' dot diameter) and registers with `registration`
    /// (RegistrationSettings), as [`job::prepare_scan`] does. A failure
    /// (kind `registration`) leaves the import usable.
    pub fn register(&mut self, registration: JsValue) -> Result<(), JsValue> {
        let settings: RegistrationSettings = from_js("registration settings", registration)?;
        let mesh = &self.imported.mesh;
        let topology = self.topology.get_or_insert_with(|| Topology::of(mesh));
        let holes = find_fiducials_in(mesh, topology, settings.dot_diameter_mm);
        // Placement on the bed included, as job::prepare_scan does.
        let reg =
            job::registration_for_scan(&self.imported, &holes, &settings).map_err(core_err)?;
        self.registered = Some((holes, reg, settings.method));
        Ok(())
    }

    /// Builds the registered surface and its spatial index: the [`Session`]
    /// that plans. Call [`ScanImport::register`] first.
    pub fn index(self) -> Result<Session, JsValue> {
        let (Some((fiducials, registration, method)), Some(topology)) =
            (self.registered, self.topology)
        else {
            return Err(JsError::new("the scan must be registered before it is indexed").into());
        };
        let scan_bbox = self.imported.mesh.bbox();
        let prepared = PreparedScan::assemble(
            self.file,
            self.imported,
            topology,
            fiducials,
            registration,
            method,
        )
        .map_err(core_err)?;
        Ok(Session::from_prepared(prepared, scan_bbox))
    }
}
