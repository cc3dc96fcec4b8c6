//! glTF 2.0 reader (`.glb` and `.gltf` with embedded or caller-supplied buffers), from bytes.
//!
//! The `gltf` crate parses and validates the JSON; accessors are decoded here, with every offset
//! and count checked against the buffers, because the crate's own reader panics on some valid
//! files (quantized positions, gltf-rs/gltf#400). Required extensions are checked first so a
//! Draco- or meshopt-compressed file gets a clear message instead of a validation error.

use std::collections::BTreeMap;

use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use crate::error::{Error, Result};
use crate::geometry::{Point3, TriangleMesh};

const GLB: &str = "GLB";
const GLTF: &str = "glTF";

/// Extensions that may be required without changing the geometry we read.
const HARMLESS_REQUIRED: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_unlit",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_variants",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "KHR_lights_punctual",
];

/// A mesh read from glTF plus notes on what was ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfMesh {
    /// All triangles of the default scene, in the glTF world frame.
    pub mesh: TriangleMesh,
    /// Things skipped on the way (point/line primitives, ...), for the report's warnings.
    pub warnings: Vec<String>,
    /// Number of mesh instances (node × mesh) read.
    pub instances: usize,
}

/// True when the bytes start with the GLB magic.
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>)> {
    let u32_at = |o: usize| -> Option<u32> {
        let b = bytes.get(o..o + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let version = u32_at(4).ok_or_else(|| Error::truncated(GLB, "header shorter than 12 bytes"))?;
    if version != 2 {
        return Err(Error::unsupported(
            GLB,
            format!("container version {version}; only glTF 2.0 is supported"),
        ));
    }
    let total =
        u32_at(8).ok_or_else(|| Error::truncated(GLB, "header shorter than 12 bytes"))? as usize;
    if total > bytes.len() {
        return Err(Error::truncated(
            GLB,
            format!("header says {total} bytes, file has {}", bytes.len()),
        ));
    }
    let mut pos = 12;
    let mut json = None;
    let mut bin = None;
    while pos + 8 <= total {
        let len = u32_at(pos).ok_or_else(|| Error::truncated(GLB, "chunk header"))? as usize;
        let kind = u32_at(pos + 4).ok_or_else(|| Error::truncated(GLB, "chunk header"))?;
        let start = pos + 8;
        let end = start
            .checked_add(len)
            .filter(|&e| e <= total)
            .ok_or_else(|| {
                Error::truncated(
                    GLB,
                    format!("chunk of {len} bytes at offset {pos} runs past the end"),
                )
            })?;
        match kind {
            0x4E4F_534A if json.is_none() => json = Some(&bytes[start..end]),
            0x004E_4942 if bin.is_none() => bin = Some(&bytes[start..end]),
            _ => {}
        }
        pos = end + (4 - len % 4) % 4;
    }
    let json = json.ok_or_else(|| Error::malformed(GLB, "no JSON chunk"))?;
    Ok((json, bin))
}

/// Reads every triangle of the default scene (else scene 0, else every root node), with node
/// transforms applied. `external` maps relative URIs of external buffers to their bytes.
pub fn read_gltf(bytes: &[u8], external: &BTreeMap<String, Vec<u8>>) -> Result<GltfMesh> {
    let (format, json_bytes, blob) = if is_glb(bytes) {
        let (j, b) = split_glb(bytes)?;
        (GLB, j, b)
    } else {
        (GLTF, bytes, None)
    };
    let mut value: serde_json::Value = serde_json::from_slice(json_bytes)
        .map_err(|e| Error::malformed(format, format!("JSON: {e}")))?;
    let obj = value
        .as_object_mut()
        .ok_or_else(|| Error::malformed(format, "JSON root is not an object"))?;
    if let Some(req) = obj.get("extensionsRequired").and_then(|v| v.as_array()) {
        for ext in req.iter().filter_map(|e| e.as_str()) {
            if !HARMLESS_REQUIRED.contains(&ext) {
                let hint = match ext {
                    "KHR_draco_mesh_compression" => {
                        "Draco-compressed glTF cannot be read: re-export without mesh compression"
                    }
                    "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
                        "meshopt-compressed glTF cannot be read: re-export without compression"
                    }
                    "EXT_mesh_gpu_instancing" => {
                        "GPU-instanced meshes are not supported: re-export with instancing off"
                    }
                    _ => "this required extension is not supported",
                };
                return Err(Error::unsupported(
                    format,
                    format!("requires extension '{ext}': {hint}"),
                ));
            }
        }
    }
    // The geometry does not depend on the extensions left; the crate would refuse them.
    obj.remove("extensionsRequired");
    obj.remove("extensionsUsed");
    let cleaned =
        serde_json::to_vec(&value).map_err(|e| Error::malformed(format, e.to_string()))?;
    let doc = gltf::Gltf::from_slice(&cleaned)
        .map_err(|e| Error::malformed(format, format!("invalid glTF: {e}")))?
        .document;

    let buffers = resolve_buffers(&doc, format, blob, external)?;
    let mut reader = Walker {
        format,
        buffers,
        mesh: TriangleMesh::default(),
        warnings: Vec::new(),
        instances: 0,
    };
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    if let Some(f) = is_child.get_mut(c.index()) {
                        *f = true;
                    }
                }
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    for node in roots {
        reader.walk(&node, &IDENTITY, 0)?;
    }
    if reader.mesh.triangles.is_empty() {
        return Err(Error::Empty {
            what: format!("{format} scene (no triangles)"),
        });
    }
    reader.mesh.validate(format)?;
    Ok(GltfMesh {
        mesh: reader.mesh,
        warnings: reader.warnings,
        instances: reader.instances,
    })
}

fn resolve_buffers(
    doc: &gltf::Document,
    format: &'static str,
    blob: Option<&[u8]>,
    external: &BTreeMap<String, Vec<u8>>,
) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    Error::malformed(
                        format,
                        "buffer refers to the GLB BIN chunk but there is none",
                    )
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, payload) = rest.split_once(";base64,").ok_or_else(|| {
                        Error::unsupported(format, "data URI without base64 encoding")
                    })?;
                    base64::engine::general_purpose::STANDARD
                        .decode(payload)
                        .map_err(|e| Error::malformed(format, format!("buffer data URI: {e}")))?
                } else {
                    let key = percent_decode(uri);
                    let base = key.rsplit('/').next().unwrap_or(&key).to_string();
                    external
                        .get(&key)
                        .or_else(|| external.get(&base))
                        .cloned()
                        .ok_or_else(|| {
                            Error::unsupported(format, format!("external buffer '{key}' was not supplied (drop or pass it with the .gltf)"))
                        })?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(Error::truncated(
                format,
                format!(
                    "buffer {} declares {} bytes but holds {}",
                    buffer.index(),
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

type Mat4 = [[f64; 4]; 4]; // row-major

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn apply(m: &Mat4, p: Point3) -> Point3 {
    let r = |i: usize| m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3];
    [r(0), r(1), r(2)]
}

fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

struct Walker {
    format: &'static str,
    buffers: Vec<Vec<u8>>,
    mesh: TriangleMesh,
    warnings: Vec<String>,
    instances: usize,
}

const MAX_DEPTH: usize = 256;

impl Walker {
    fn walk(&mut self, node: &gltf::Node, parent: &Mat4, depth: usize) -> Result<()> {
        if depth > MAX_DEPTH {
            return Err(Error::malformed(
                self.format,
                "node hierarchy deeper than 256 levels (a cycle?)",
            ));
        }
        // glTF matrices are column-major: m[c][r].
        let cm = node.transform().matrix();
        let mut local = [[0.0; 4]; 4];
        for (r, row) in local.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = f64::from(cm[c][r]);
            }
        }
        let world = mul(parent, &local);
        if let Some(mesh) = node.mesh() {
            self.instances += 1;
            for prim in mesh.primitives() {
                self.primitive(&prim, &world, mesh.index())?;
            }
        }
        for child in node.children() {
            self.walk(&child, &world, depth + 1)?;
        }
        Ok(())
    }

    fn primitive(&mut self, prim: &gltf::Primitive, world: &Mat4, mesh_index: usize) -> Result<()> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warnings.push(format!(
                "mesh {mesh_index}: skipped a {mode:?} primitive (not a surface)"
            ));
            return Ok(());
        }
        let pos = prim.get(&gltf::Semantic::Positions).ok_or_else(|| {
            Error::malformed(
                self.format,
                format!("mesh {mesh_index}: primitive without POSITION"),
            )
        })?;
        if pos.dimensions() != Dimensions::Vec3 {
            return Err(Error::malformed(
                self.format,
                format!("mesh {mesh_index}: POSITION is not VEC3"),
            ));
        }
        let local = decode_accessor(self.format, &self.buffers, &pos)?;
        let n = local.len() / 3;
        let base = self.mesh.vertices.len();
        if base + n > u32::MAX as usize {
            return Err(Error::unsupported(
                self.format,
                "more than 4 billion vertices",
            ));
        }
        self.mesh.vertices.extend(
            local
                .chunks_exact(3)
                .map(|c| apply(world, [c[0], c[1], c[2]])),
        );
        let indices: Vec<u32> = match prim.indices() {
            Some(acc) => {
                if acc.dimensions() != Dimensions::Scalar
                    || !matches!(
                        acc.data_type(),
                        DataType::U8 | DataType::U16 | DataType::U32
                    )
                {
                    return Err(Error::malformed(
                        self.format,
                        format!("mesh {mesh_index}: indices are not unsigned integer scalars"),
                    ));
                }
                let raw = decode_accessor(self.format, &self.buffers, &acc)?;
                let mut out = Vec::with_capacity(raw.len());
                for v in raw {
                    if v >= n as f64 {
                        return Err(Error::malformed(
                            self.format,
                            format!("mesh {mesh_index}: index {v} ≥ vertex count {n}"),
                        ));
                    }
                    out.push(v as u32);
                }
                out
            }
            None => (0..n as u32).collect(),
        };
        let flip = det3(world) < 0.0;
        let b = base as u32;
        let mut push = |a: u32, c1: u32, c2: u32| {
            let t = if flip {
                [a + b, c2 + b, c1 + b]
            } else {
                [a + b, c1 + b, c2 + b]
            };
            self.mesh.triangles.push(t);
        };
        match mode {
            Mode::Triangles => {
                for t in indices.chunks_exact(3) {
                    push(t[0], t[1], t[2]);
                }
            }
            Mode::TriangleStrip => {
                for i in 0..indices.len().saturating_sub(2) {
                    if i % 2 == 0 {
                        push(indices[i], indices[i + 1], indices[i + 2]);
                    } else {
                        push(indices[i + 1], indices[i], indices[i + 2]);
                    }
                }
            }
            Mode::TriangleFan => {
                for i in 1..indices.len().saturating_sub(1) {
                    push(indices[i], indices[i + 1], indices[0]);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

fn component(dt: DataType, b: &[u8], normalized: bool) -> f64 {
    let v = match dt {
        DataType::I8 => f64::from(b[0] as i8),
        DataType::U8 => f64::from(b[0]),
        DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
        DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    };
    if !normalized {
        return v;
    }
    match dt {
        DataType::I8 => (v / 127.0).max(-1.0),
        DataType::U8 => v / 255.0,
        DataType::I16 => (v / 32767.0).max(-1.0),
        DataType::U16 => v / 65535.0,
        DataType::U32 => v / 4294967295.0,
        DataType::F32 => v,
    }
}

/// Decodes an accessor into a flat list of f64 components, checking every range.
fn decode_accessor(
    format: &'static str,
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
) -> Result<Vec<f64>> {
    let dims = acc.dimensions().multiplicity();
    let dt = acc.data_type();
    let csize = dt.size();
    let count = acc.count();
    let elem = csize * dims;
    let normalized = acc.normalized();
    let err = |what: &str| Error::malformed(format, format!("accessor {}: {what}", acc.index()));
    let mut out = Vec::new();
    match acc.view() {
        Some(view) => {
            let buf = buffers
                .get(view.buffer().index())
                .ok_or_else(|| err("buffer missing"))?;
            let stride = view.stride().unwrap_or(elem).max(elem);
            let view_start = view.offset();
            let view_end = view_start
                .checked_add(view.length())
                .filter(|&e| e <= buf.len())
                .ok_or_else(|| err("buffer view runs past its buffer"))?;
            let view_bytes = &buf[view_start..view_end];
            if count > 0 {
                let last_end = acc
                    .offset()
                    .checked_add(
                        (count - 1)
                            .checked_mul(stride)
                            .ok_or_else(|| err("count overflows"))?,
                    )
                    .and_then(|s| s.checked_add(elem))
                    .ok_or_else(|| err("count overflows"))?;
                if last_end > view_bytes.len() {
                    return Err(Error::CountMismatch {
                        format,
                        what: "accessor elements",
                        declared: count as u64,
                        available: (view_bytes.len().saturating_sub(acc.offset()) / stride.max(1))
                            as u64,
                    });
                }
            }
            out.reserve(count * dims);
            for i in 0..count {
                let at = acc.offset() + i * stride;
                for k in 0..dims {
                    out.push(component(dt, &view_bytes[at + k * csize..], normalized));
                }
            }
        }
        None => {
            if count > 100_000_000 {
                return Err(err("sparse/zero accessor with an implausible count"));
            }
            out.resize(count * dims, 0.0);
        }
    }
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let iv = sparse.indices();
        let ibuf = buffers
            .get(iv.view().buffer().index())
            .ok_or_else(|| err("sparse buffer missing"))?;
        let isize = match iv.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let istart = iv.view().offset() + iv.offset();
        let ibytes = ibuf
            .get(istart..istart.saturating_add(n.saturating_mul(isize)))
            .ok_or_else(|| err("sparse indices run past their buffer"))?;
        let vv = sparse.values();
        let vbuf = buffers
            .get(vv.view().buffer().index())
            .ok_or_else(|| err("sparse buffer missing"))?;
        let vstart = vv.view().offset() + vv.offset();
        let vbytes = vbuf
            .get(vstart..vstart.saturating_add(n.saturating_mul(elem)))
            .ok_or_else(|| err("sparse values run past their buffer"))?;
        for j in 0..n {
            let b = &ibytes[j * isize..];
            let idx = match isize {
                1 => usize::from(b[0]),
                2 => usize::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            if idx >= count {
                return Err(err("sparse index out of range"));
            }
            for k in 0..dims {
                out[idx * dims + k] = component(dt, &vbytes[j * elem + k * csize..], normalized);
            }
        }
    }
    if out.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            format,
            what: "accessor value",
            count: out.iter().filter(|v| !v.is_finite()).count(),
            first_index: out.iter().position(|v| !v.is_finite()).unwrap_or(0) / dims.max(1),
        });
    }
    Ok(out)
}
