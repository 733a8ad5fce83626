//! meshopt-compressed glTF buffer views (`EXT_meshopt_compression`, what
//! gltfpack and glTF-Transform's `meshopt` write): a compressed view's
//! bytes lie in a buffer of their own and decode to the view's data, while
//! the buffer the view names is a *fallback*, usually without data.
//!
//! The decoders and filters are `meshopt-rs`'s (a pure-Rust port of
//! meshoptimizer's); this module reads the extension's JSON, checks each
//! view against the extension's rules before a byte is decoded, bounds what
//! a stream may decode to by its length (a decompression bomb is refused,
//! not decoded), and turns every decoder failure into an error naming the
//! view.

use std::collections::{HashMap, HashSet};

use super::{MeshError, MAX_SCAN_BYTES};

/// The extension's name.
pub(super) const EXT: &str = "EXT_meshopt_compression";

/// How a view's stream is coded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Vertex attributes: `count` elements of `stride` bytes.
    Attributes,
    /// Triangle-list indices (2 or 4 bytes each).
    Triangles,
    /// Indices of any other kind.
    Indices,
}

/// The transform applied to decoded attributes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
}

/// One compressed bufferView, as its extension object describes it.
#[derive(Debug, Clone, Copy)]
pub(super) struct View {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

/// Decoded bytes a stream may give per byte of it. meshoptimizer's codecs
/// give at most 64 (a run of equal vertex bytes, 2 bits for 16), 12 (a
/// triangle of 4-byte indices in its one code byte) and 4 (an index in one
/// byte); past twice the first, the stream is a bomb.
const BYTES_PER_BYTE: usize = 128;

/// Decoded bytes any stream may give, however short.
const BYTES_ANYWAY: usize = 1 << 16;

/// The file's meshopt-compressed bufferViews by index, and the buffers it
/// marks as fallbacks (read by no compressed view's decoder; they may have
/// no data). Empty when the file does not use the extension. The extension
/// objects are read from the JSON text (the `gltf` crate keeps no unknown
/// extensions); each view is checked against the extension's rules here.
pub(super) fn views(
    json: &[u8],
    used: bool,
    file: &str,
) -> Result<(HashMap<usize, View>, HashSet<usize>), MeshError> {
    #[derive(serde::Deserialize)]
    struct Doc {
        #[serde(default, rename = "bufferViews")]
        buffer_views: Vec<Extended>,
        #[serde(default)]
        buffers: Vec<Extended>,
    }
    #[derive(serde::Deserialize)]
    struct Extended {
        #[serde(default)]
        extensions: Option<serde_json::Map<String, serde_json::Value>>,
    }
    let mut views = HashMap::new();
    let mut fallbacks = HashSet::new();
    if !used {
        return Ok((views, fallbacks));
    }
    let doc: Doc = serde_json::from_slice(json)
        .map_err(|e| MeshError::invalid(file, format!("not a valid glTF 2.0 file: {e}")))?;
    let ext = |e: &Option<serde_json::Map<String, serde_json::Value>>| {
        e.as_ref().and_then(|e| e.get(EXT)).cloned()
    };
    for (i, b) in doc.buffers.iter().enumerate() {
        if ext(&b.extensions)
            .and_then(|e| e.get("fallback").and_then(serde_json::Value::as_bool))
            .unwrap_or(false)
        {
            fallbacks.insert(i);
        }
    }
    for (i, v) in doc.buffer_views.iter().enumerate() {
        if let Some(e) = ext(&v.extensions) {
            views.insert(i, view(i, &e, doc.buffers.len(), file)?);
        }
    }
    Ok((views, fallbacks))
}

/// View `i`'s extension object `e`, checked: the fields the extension
/// requires, a mode and filter it defines, and the strides and counts it
/// allows for them.
fn view(i: usize, e: &serde_json::Value, buffers: usize, file: &str) -> Result<View, MeshError> {
    let bad = |what: String| MeshError::invalid(file, format!("bufferView {i}: its {EXT} {what}"));
    let number = |key: &str, default: Option<usize>| -> Result<usize, MeshError> {
        match e.get(key) {
            None => default.ok_or_else(|| bad(format!("has no {key}"))),
            Some(v) => v
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| bad(format!("has {key} {v}, not a count of bytes or elements"))),
        }
    };
    let text = |key: &str| e.get(key).and_then(serde_json::Value::as_str);
    let buffer = number("buffer", None)?;
    if buffer >= buffers {
        return Err(bad(format!(
            "refers to buffer {buffer}, but there are {buffers}"
        )));
    }
    let mode = match text("mode") {
        Some("ATTRIBUTES") => Mode::Attributes,
        Some("TRIANGLES") => Mode::Triangles,
        Some("INDICES") => Mode::Indices,
        other => {
            return Err(bad(format!(
                "has mode {}, not ATTRIBUTES, TRIANGLES or INDICES",
                other.unwrap_or("(none)")
            )))
        }
    };
    let filter = match text("filter") {
        None | Some("NONE") => Filter::None,
        Some("OCTAHEDRAL") => Filter::Octahedral,
        Some("QUATERNION") => Filter::Quaternion,
        Some("EXPONENTIAL") => Filter::Exponential,
        Some(other) => {
            return Err(bad(format!(
                "has filter {other}, not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL"
            )))
        }
    };
    let v = View {
        buffer,
        offset: number("byteOffset", Some(0))?,
        length: number("byteLength", None)?,
        stride: number("byteStride", None)?,
        count: number("count", None)?,
        mode,
        filter,
    };
    let fits = match (v.mode, v.filter) {
        (Mode::Attributes, Filter::None | Filter::Exponential) => {
            v.stride.is_multiple_of(4) && (4..=256).contains(&v.stride)
        }
        (Mode::Attributes, Filter::Octahedral) => v.stride == 4 || v.stride == 8,
        (Mode::Attributes, Filter::Quaternion) => v.stride == 8,
        (Mode::Triangles | Mode::Indices, Filter::None) => v.stride == 2 || v.stride == 4,
        (Mode::Triangles | Mode::Indices, _) => {
            return Err(bad(format!(
                "filters indices ({:?}), which the extension allows for attributes only",
                v.filter
            )))
        }
    };
    if !fits {
        return Err(bad(format!(
            "has byteStride {} for mode {:?} with filter {:?}, which the extension does not \
             allow (attributes: a multiple of 4 up to 256, 4 or 8 octahedral, 8 quaternion; \
             indices: 2 or 4)",
            v.stride, v.mode, v.filter
        )));
    }
    if v.mode == Mode::Triangles && !v.count.is_multiple_of(3) {
        return Err(bad(format!(
            "holds {} triangle indices, not a multiple of 3",
            v.count
        )));
    }
    Ok(v)
}

/// Decodes compressed view `index` from the file's buffers: its
/// `count * byteStride` bytes, as the view's data.
pub(super) fn decode(
    index: usize,
    v: &View,
    buffers: &[std::borrow::Cow<'_, [u8]>],
    file: &str,
) -> Result<Vec<u8>, MeshError> {
    let err = |what: String| MeshError::invalid(file, format!("bufferView {index}: {what}"));
    let stream = buffers
        .get(v.buffer)
        .and_then(|b| {
            v.offset
                .checked_add(v.length)
                .and_then(|end| b.get(v.offset..end))
        })
        .ok_or_else(|| {
            err(format!(
                "its meshopt data (offset {}, length {}) lies outside buffer {}",
                v.offset, v.length, v.buffer
            ))
        })?;
    let size = v
        .count
        .checked_mul(v.stride)
        .filter(|&n| n <= MAX_SCAN_BYTES)
        .filter(|&n| n <= BYTES_PER_BYTE.saturating_mul(stream.len()) + BYTES_ANYWAY)
        .ok_or_else(|| {
            err(format!(
                "its {} bytes of meshopt data claim {} elements of {} bytes, more than such a \
                 stream decodes to (a damaged or hostile file)",
                stream.len(),
                v.count,
                v.stride
            ))
        })?;
    let failed = |e: &dyn std::fmt::Debug| {
        err(format!(
            "its meshopt data (mode {:?}, {} elements of {} bytes) could not be decoded: {e:?}",
            v.mode, v.count, v.stride
        ))
    };
    // Only what POSITION and indices hold is decoded: octahedral unit
    // vectors and quaternions are neither.
    if matches!(v.filter, Filter::Octahedral | Filter::Quaternion) {
        return Err(err(format!(
            "its meshopt data is filtered as {:?} (unit vectors or rotations), which no \
             position is",
            v.filter
        )));
    }
    let mut bytes = match v.mode {
        Mode::Attributes => attributes(stream, v.count, v.stride).map_err(|e| failed(&e))?,
        Mode::Triangles => {
            let mut ids = vec![0u32; v.count];
            meshopt_rs::index::buffer::decode_index_buffer(&mut ids, stream)
                .map_err(|e| failed(&e))?;
            // 2-byte indices keep their low half, as meshoptimizer's own
            // decoder writes them.
            match v.stride {
                2 => ids.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
                _ => ids.iter().flat_map(|&i| i.to_le_bytes()).collect(),
            }
        }
        // Exporters code the indices of points and lines so, which are not
        // read (only triangles describe a surface).
        Mode::Indices => {
            return Err(err(
                "its meshopt data is an index sequence (mode INDICES), which is not decoded: \
                 triangles' indices are coded as TRIANGLES"
                    .into(),
            ))
        }
    };
    debug_assert_eq!(bytes.len(), size);
    unfilter(&mut bytes, v);
    Ok(bytes)
}

/// The vertex codec's `count` elements of `stride` bytes (a multiple of 4
/// up to 256, checked by [`view`]): the decoder takes the element size as
/// its element type's.
fn attributes(
    stream: &[u8],
    count: usize,
    stride: usize,
) -> Result<Vec<u8>, meshopt_rs::vertex::DecodeError> {
    fn of<const N: usize>(
        stream: &[u8],
        count: usize,
    ) -> Result<Vec<u8>, meshopt_rs::vertex::DecodeError> {
        let mut out = vec![[0u8; N]; count];
        meshopt_rs::vertex::buffer::decode_vertex_buffer(&mut out, stream)?;
        Ok(out.into_flattened())
    }
    macro_rules! by_stride {
        ($($n:literal)*) => {
            match stride {
                $($n => of::<$n>(stream, count),)*
                _ => unreachable!("byteStride {stride} was checked to be a multiple of 4 up to 256"),
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108
        112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196
        200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

/// Undoes the view's filter on its decoded bytes (little-endian words).
fn unfilter(bytes: &mut [u8], v: &View) {
    use meshopt_rs::vertex::filter;
    match v.filter {
        Filter::None => {}
        Filter::Exponential => {
            let mut words: Vec<u32> = bytes
                .chunks_exact(4)
                .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
                .collect();
            filter::decode_filter_exp(&mut words);
            for (w, b) in words.iter().zip(bytes.chunks_exact_mut(4)) {
                b.copy_from_slice(&w.to_le_bytes());
            }
        }
        // Unit vectors and rotations: [`decode`] refuses them before.
        Filter::Octahedral | Filter::Quaternion => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(ext: &str) -> Result<View, String> {
        let e: serde_json::Value = serde_json::from_str(ext).unwrap();
        view(3, &e, 2, "s.glb").map_err(|e| e.to_string())
    }

    /// What the extension defines is read, with byteOffset and filter
    /// defaulted; what it does not allow is named with the view.
    #[test]
    fn views_are_checked_against_the_extension_s_rules() {
        let v =
            check(r#"{"buffer":1,"byteLength":40,"byteStride":8,"mode":"ATTRIBUTES","count":5}"#)
                .unwrap();
        assert_eq!(
            (v.buffer, v.offset, v.length, v.stride, v.count),
            (1, 0, 40, 8, 5)
        );
        assert_eq!((v.mode, v.filter), (Mode::Attributes, Filter::None));
        for (ext, says) in [
            (
                r#"{"buffer":2,"byteLength":4,"byteStride":8,"mode":"ATTRIBUTES","count":5}"#,
                "refers to buffer 2, but there are 2",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":8,"mode":"POINTS","count":5}"#,
                "has mode POINTS, not ATTRIBUTES, TRIANGLES or INDICES",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":6,"mode":"ATTRIBUTES","count":5}"#,
                "has byteStride 6 for mode Attributes with filter None",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":260,"mode":"ATTRIBUTES","count":5}"#,
                "has byteStride 260",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":8,"mode":"TRIANGLES","count":6}"#,
                "has byteStride 8 for mode Triangles",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":2,"mode":"TRIANGLES","count":7}"#,
                "holds 7 triangle indices, not a multiple of 3",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":4,"mode":"TRIANGLES","count":6,
                   "filter":"EXPONENTIAL"}"#,
                "filters indices (Exponential)",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":4,"mode":"ATTRIBUTES","count":6,
                   "filter":"QUATERNION"}"#,
                "has byteStride 4 for mode Attributes with filter Quaternion",
            ),
            (
                r#"{"buffer":0,"byteLength":4,"byteStride":4,"mode":"ATTRIBUTES","count":6,
                   "filter":"COLOR"}"#,
                "has filter COLOR",
            ),
            (
                r#"{"buffer":0,"byteStride":4,"mode":"ATTRIBUTES","count":6}"#,
                "has no byteLength",
            ),
            (
                r#"{"buffer":0,"byteLength":-4,"byteStride":4,"mode":"ATTRIBUTES","count":6}"#,
                "has byteLength -4, not a count",
            ),
        ] {
            let e = check(ext).unwrap_err();
            assert!(
                e.starts_with("s.glb: bufferView 3: its EXT_meshopt_compression ")
                    && e.contains(says),
                "{e}\nwanted: {says}"
            );
        }
    }

    /// Views whose data no position or triangle holds are refused when
    /// they would be decoded: index sequences, and unit vectors.
    #[test]
    fn sequences_and_unit_vectors_are_not_decoded() {
        let buffers = [std::borrow::Cow::Owned(vec![0u8; 64])];
        for (ext, says) in [
            (
                r#"{"buffer":0,"byteLength":64,"byteStride":4,"mode":"INDICES","count":6}"#,
                "index sequence (mode INDICES)",
            ),
            (
                r#"{"buffer":0,"byteLength":64,"byteStride":8,"mode":"ATTRIBUTES","count":6,
                   "filter":"OCTAHEDRAL"}"#,
                "filtered as Octahedral",
            ),
        ] {
            let e: serde_json::Value = serde_json::from_str(ext).unwrap();
            let v = view(0, &e, 1, "s.glb").unwrap();
            let e = decode(0, &v, &buffers, "s.glb").unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }
}
