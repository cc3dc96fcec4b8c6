//! glTF 2.0 reader (`.glb` and `.gltf` with embedded or caller-supplied buffers), from bytes.
//!
//! The `gltf` crate parses and validates the JSON; accessors are decoded here, with every offset
//! and count checked against the buffers, because the crate's own reader panics on some valid
//! files (quantized positions, gltf-rs/gltf#400). Required extensions are checked first so a
//! Draco- or meshopt-compressed file gets a clear message instead of a validation error.
//!
//! Hostile node graphs: the nodes must form a tree (a node listed as a child twice, by two
//! parents, as its own ancestor, or a scene root that is also a child, is an error naming the
//! node), and the triangles and vertices the scene expands to are counted from the accessor
//! counts before anything is decoded, against [`ReadLimits`]. Accessors are decoded straight
//! into the mesh (no intermediate copy), so the memory used is that of the mesh returned.

use std::collections::BTreeMap;

use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::ReadLimits;
use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, Point3, TriangleMesh, show};
use crate::note::{Code, Note};

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
    pub notes: Vec<Note>,
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
/// transforms applied. `external` maps relative URIs of external buffers to their bytes. Uses the
/// default [`ReadLimits`].
pub fn read_gltf(bytes: &[u8], external: &BTreeMap<String, Vec<u8>>) -> Result<GltfMesh> {
    read_gltf_with_limits(bytes, external, &ReadLimits::default())
}

/// [`read_gltf`] with explicit limits: the node graph is checked to be a tree and the expanded
/// triangle and vertex counts are checked against `limits` before any accessor is decoded.
pub(crate) fn read_gltf_with_limits(
    bytes: &[u8],
    external: &BTreeMap<String, Vec<u8>>,
    limits: &ReadLimits,
) -> Result<GltfMesh> {
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
    prepare_for_validation(format, obj)?;
    let cleaned =
        serde_json::to_vec(&value).map_err(|e| Error::malformed(format, e.to_string()))?;
    drop(value);
    let doc = gltf::Gltf::from_slice(&cleaned)
        .map_err(|e| Error::malformed(format, format!("invalid glTF: {e}")))?
        .document;

    let parents = node_parents(&doc, format)?;
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => {
            let mut listed = vec![false; parents.len()];
            let mut roots = Vec::new();
            for n in scene.nodes() {
                let i = n.index();
                if listed.get(i).copied().unwrap_or(false) {
                    return Err(Error::malformed(
                        format,
                        format!("scene {} lists node {i} more than once", scene.index()),
                    ));
                }
                if let Some(f) = listed.get_mut(i) {
                    *f = true;
                }
                if let Some(Some(p)) = parents.get(i) {
                    return Err(Error::malformed(
                        format,
                        format!(
                            "scene {} lists node {i} as a root, but it is a child of node {p}",
                            scene.index()
                        ),
                    ));
                }
                roots.push(n);
            }
            roots
        }
        None => doc
            .nodes()
            .filter(|n| parents.get(n.index()).is_some_and(Option::is_none))
            .collect(),
    };
    let (triangles, vertices) = expanded_size(format, &roots)?;
    limits.check(format, triangles, vertices)?;

    let buffers = resolve_buffers(&doc, format, blob, external)?;
    let mut reader = Walker {
        format,
        buffers,
        mesh: TriangleMesh::default(),
        notes: Vec::new(),
        instances: 0,
    };
    // The counts are exact upper bounds of what the walk pushes.
    reader
        .mesh
        .vertices
        .reserve(usize::try_from(vertices).unwrap_or(0));
    reader
        .mesh
        .triangles
        .reserve(usize::try_from(triangles).unwrap_or(0));
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
        notes: reader.notes,
        instances: reader.instances,
    })
}

/// The parent of every node, checking that the nodes form a forest: no node is listed as a
/// child twice (by one parent or two) and no node is its own ancestor.
fn node_parents(doc: &gltf::Document, format: &'static str) -> Result<Vec<Option<usize>>> {
    let n = doc.nodes().len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for node in doc.nodes() {
        for child in node.children() {
            let c = child.index();
            let slot = parent
                .get_mut(c)
                .ok_or_else(|| Error::malformed(format, format!("node {c} does not exist")))?;
            if let Some(p) = *slot {
                let how = if p == node.index() {
                    format!("lists node {c} twice among its children")
                } else {
                    format!("lists node {c} as a child, but node {p} already does")
                };
                return Err(Error::malformed(
                    format,
                    format!(
                        "node {} {how}: glTF nodes must form a tree (a node with two parents would be expanded once per path)",
                        node.index()
                    ),
                ));
            }
            *slot = Some(node.index());
        }
    }
    // Cycles: follow each node's parents; 1 = on the current path, 2 = known to reach a root.
    let mut state = vec![0u8; n];
    let mut path = Vec::new();
    for start in 0..n {
        let mut i = start;
        path.clear();
        loop {
            match state.get(i).copied() {
                Some(2) | None => break,
                Some(1) => {
                    return Err(Error::malformed(
                        format,
                        format!(
                            "node {i} is its own ancestor (a cycle in the node hierarchy): glTF nodes must form a tree"
                        ),
                    ));
                }
                _ => {}
            }
            if let Some(s) = state.get_mut(i) {
                *s = 1;
            }
            path.push(i);
            match parent.get(i).copied().flatten() {
                Some(p) => i = p,
                None => break,
            }
        }
        for &k in &path {
            if let Some(s) = state.get_mut(k) {
                *s = 2;
            }
        }
    }
    Ok(parent)
}

/// Triangles and vertices the scene expands to (every node instance of every mesh), from the
/// accessor counts alone; saturating, so an absurd count cannot wrap. The nodes form a tree
/// ([`node_parents`]), so this visits each node once.
fn expanded_size(format: &'static str, roots: &[gltf::Node]) -> Result<(u64, u64)> {
    let (mut triangles, mut vertices) = (0u64, 0u64);
    let mut stack: Vec<(gltf::Node, usize)> = roots.iter().map(|n| (n.clone(), 0)).collect();
    while let Some((node, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err(deep(format, node.index()));
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let Some(pos) = prim.get(&gltf::Semantic::Positions) else {
                    continue;
                };
                let count = match prim.indices() {
                    Some(acc) => acc.count() as u64,
                    None => pos.count() as u64,
                };
                let t = match prim.mode() {
                    Mode::Triangles => count / 3,
                    Mode::TriangleStrip | Mode::TriangleFan => count.saturating_sub(2),
                    _ => continue,
                };
                triangles = triangles.saturating_add(t);
                vertices = vertices.saturating_add(pos.count() as u64);
            }
        }
        stack.extend(node.children().map(|c| (c, depth + 1)));
    }
    Ok((triangles, vertices))
}

fn deep(format: &'static str, node: usize) -> Error {
    Error::malformed(
        format,
        format!("node {node} is deeper than {MAX_DEPTH} levels in the node hierarchy"),
    )
}

/// Prepares the JSON for the crate's validation, which itself panics on some bad indices:
/// checks that every accessor index a primitive uses exists, and fills the `min`/`max` that the
/// spec requires on POSITION accessors (some exporters omit them; we never use them).
fn prepare_for_validation(
    format: &'static str,
    root: &mut serde_json::Map<String, serde_json::Value>,
) -> Result<()> {
    let n_accessors = root
        .get("accessors")
        .and_then(|a| a.as_array())
        .map_or(0, |a| a.len());
    let mut position_accessors = Vec::new();
    let bad = |what: String| Error::malformed(format, what);
    for (mi, mesh) in root
        .get("meshes")
        .and_then(|m| m.as_array())
        .into_iter()
        .flatten()
        .enumerate()
    {
        for (pi, prim) in mesh
            .get("primitives")
            .and_then(|p| p.as_array())
            .into_iter()
            .flatten()
            .enumerate()
        {
            let mut refs: Vec<&serde_json::Value> = Vec::new();
            if let Some(attrs) = prim.get("attributes").and_then(|a| a.as_object()) {
                refs.extend(attrs.values());
                if let Some(i) = attrs.get("POSITION").and_then(|i| i.as_u64()) {
                    position_accessors.push(i as usize);
                }
            }
            refs.extend(prim.get("indices"));
            for t in prim
                .get("targets")
                .and_then(|t| t.as_array())
                .into_iter()
                .flatten()
            {
                refs.extend(t.as_object().into_iter().flat_map(|o| o.values()));
            }
            for r in refs {
                match r.as_u64() {
                    Some(i) if (i as usize) < n_accessors => {}
                    _ => {
                        return Err(bad(format!(
                            "mesh {mi} primitive {pi} refers to accessor {r}, but there are {n_accessors}"
                        )));
                    }
                }
            }
        }
    }
    if let Some(accessors) = root.get_mut("accessors").and_then(|a| a.as_array_mut()) {
        for i in position_accessors {
            if let Some(acc) = accessors.get_mut(i).and_then(|a| a.as_object_mut()) {
                for key in ["min", "max"] {
                    if !acc.contains_key(key) {
                        acc.insert(key.into(), serde_json::json!([0.0, 0.0, 0.0]));
                    }
                }
            }
        }
    }
    Ok(())
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
        let escaped = (b[i] == b'%' && i + 2 < b.len())
            .then(|| hex(b[i + 1]).zip(hex(b[i + 2])))
            .flatten();
        if let Some((h, l)) = escaped {
            out.push((h * 16 + l) as u8);
            i += 3;
            continue;
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
    notes: Vec<Note>,
    instances: usize,
}

const MAX_DEPTH: usize = 256;

impl Walker {
    fn walk(&mut self, node: &gltf::Node, parent: &Mat4, depth: usize) -> Result<()> {
        if depth > MAX_DEPTH {
            return Err(deep(self.format, node.index()));
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
        if let Some(bad) = world
            .iter()
            .flatten()
            .find(|v| !(v.abs() <= MAX_COORDINATE))
        {
            return Err(Error::out_of_range(
                self.format,
                format!("node {}", node.index()),
                "transform",
                format!(
                    "(its own composed with its ancestors') has an entry of {}, beyond ±{} (a scale or translation out of range, or a value past f32)",
                    show(*bad),
                    show(MAX_COORDINATE)
                ),
            ));
        }
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
            self.notes.push(
                Note::new(
                    Code::NonSurfacePrimitiveSkipped,
                    format!("mesh {mesh_index}: skipped a {mode:?} primitive (not a surface)"),
                )
                .with("mesh", mesh_index)
                .with("mode", format!("{mode:?}")),
            );
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
        let n = pos.count();
        let base = self.mesh.vertices.len();
        if base.saturating_add(n) > u32::MAX as usize {
            return Err(Error::unsupported(
                self.format,
                "more than 4 billion vertices",
            ));
        }
        let vertices = &mut self.mesh.vertices;
        decode_accessor(self.format, &self.buffers, &pos, |c| {
            vertices.push(apply(world, [c[0], c[1], c[2]]));
        })?;
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
                let mut out = Vec::with_capacity(acc.count());
                let mut bad: Option<f64> = None;
                decode_accessor(self.format, &self.buffers, &acc, |v| {
                    if v[0] < n as f64 {
                        out.push(v[0] as u32);
                    } else if bad.is_none() {
                        bad = Some(v[0]);
                    }
                })?;
                if let Some(v) = bad {
                    return Err(Error::malformed(
                        self.format,
                        format!("mesh {mesh_index}: index {v} ≥ vertex count {n}"),
                    ));
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

/// Most components of an accessor element (MAT4).
const MAX_DIMS: usize = 16;

/// Decodes an accessor element by element (sparse substitutions applied), checking every
/// range first, and hands each element's components to `sink` in order; fails on a
/// non-finite component. Nothing is allocated besides the sparse substitutions, which are
/// bounded by their bytes.
fn decode_accessor(
    format: &'static str,
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    mut sink: impl FnMut(&[f64]),
) -> Result<()> {
    let dims = acc.dimensions().multiplicity();
    if dims == 0 || dims > MAX_DIMS {
        return Err(Error::malformed(
            format,
            format!("accessor {}: {dims} components", acc.index()),
        ));
    }
    let dt = acc.data_type();
    let csize = dt.size();
    let count = acc.count();
    let elem = csize * dims;
    let normalized = acc.normalized();
    let err = |what: &str| Error::malformed(format, format!("accessor {}: {what}", acc.index()));
    // The dense data: a view's bytes and stride, or zeros.
    let dense: Option<(&[u8], usize)> = match acc.view() {
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
            Some((view_bytes, stride))
        }
        None => {
            if count > 100_000_000 {
                return Err(err("sparse/zero accessor with an implausible count"));
            }
            None
        }
    };
    // Sparse substitutions, sorted by element index (the last one wins for repeated indices).
    let mut sparse_idx: Vec<(usize, usize)> = Vec::new();
    let mut sparse_bytes: &[u8] = &[];
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
        let istart = iv.view().offset().saturating_add(iv.offset());
        let ibytes = ibuf
            .get(istart..istart.saturating_add(n.saturating_mul(isize)))
            .ok_or_else(|| err("sparse indices run past their buffer"))?;
        let vv = sparse.values();
        let vbuf = buffers
            .get(vv.view().buffer().index())
            .ok_or_else(|| err("sparse buffer missing"))?;
        let vstart = vv.view().offset().saturating_add(vv.offset());
        sparse_bytes = vbuf
            .get(vstart..vstart.saturating_add(n.saturating_mul(elem)))
            .ok_or_else(|| err("sparse values run past their buffer"))?;
        sparse_idx.reserve(n);
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
            sparse_idx.push((idx, j));
        }
        sparse_idx.sort_by_key(|&(idx, j)| (idx, std::cmp::Reverse(j)));
        sparse_idx.dedup_by_key(|e| e.0);
    }
    let mut next_sparse = sparse_idx.iter().peekable();
    let mut values = [0.0f64; MAX_DIMS];
    let (mut bad, mut first_bad) = (0usize, 0usize);
    for i in 0..count {
        let src: Option<&[u8]> = match next_sparse.peek() {
            Some(&&(idx, j)) if idx == i => {
                next_sparse.next();
                sparse_bytes.get(j * elem..)
            }
            _ => dense.and_then(|(bytes, stride)| bytes.get(acc.offset() + i * stride..)),
        };
        let el = &mut values[..dims];
        match src {
            Some(b) => {
                for (k, v) in el.iter_mut().enumerate() {
                    *v = component(dt, &b[k * csize..], normalized);
                }
            }
            None => el.fill(0.0),
        }
        if el.iter().any(|v| !v.is_finite()) {
            if bad == 0 {
                first_bad = i;
            }
            bad += 1;
        }
        sink(el);
    }
    if bad > 0 {
        return Err(Error::NonFinite {
            format,
            what: "accessor value",
            count: bad,
            first_index: first_bad,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Builds a glTF JSON with one data-URI buffer holding `positions` (f32) then `indices`.
    fn gltf_json(
        positions: &[[f32; 3]],
        indices: Option<(&[u32], u32)>,
        mode: u32,
        nodes: &str,
        extra: &str,
    ) -> Vec<u8> {
        let mut buf: Vec<u8> = positions
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let pos_len = buf.len();
        let mut accessors = format!(
            r#"{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3"}}"#,
            positions.len()
        );
        let mut views = format!(r#"{{"buffer":0,"byteOffset":0,"byteLength":{pos_len}}}"#);
        let mut prim = format!(r#"{{"attributes":{{"POSITION":0}},"mode":{mode}"#);
        if let Some((idx, ctype)) = indices {
            let start = buf.len();
            for &i in idx {
                match ctype {
                    5121 => buf.push(i as u8),
                    5123 => buf.extend((i as u16).to_le_bytes()),
                    _ => buf.extend(i.to_le_bytes()),
                }
            }
            let len = buf.len() - start;
            while !buf.len().is_multiple_of(4) {
                buf.push(0);
            }
            accessors.push_str(&format!(
                r#",{{"bufferView":1,"componentType":{ctype},"count":{},"type":"SCALAR"}}"#,
                idx.len()
            ));
            views.push_str(&format!(
                r#",{{"buffer":0,"byteOffset":{start},"byteLength":{len}}}"#
            ));
            prim.push_str(r#","indices":1"#);
        }
        prim.push('}');
        let b64 = base64::engine::general_purpose::STANDARD.encode(&buf);
        format!(
            r#"{{"asset":{{"version":"2.0"}},{extra}"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":{nodes},"meshes":[{{"primitives":[{prim}]}}],"accessors":[{accessors}],"bufferViews":[{views}],"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#,
            buf.len()
        )
        .into_bytes()
    }

    const QUAD: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    const PLAIN: &str = r#"[{"mesh":0}]"#;

    fn read(bytes: &[u8]) -> Result<GltfMesh> {
        read_gltf(bytes, &BTreeMap::new())
    }

    #[test]
    fn index_types_and_non_indexed() {
        for ctype in [5121, 5123, 5125] {
            let g = read(&gltf_json(
                &QUAD,
                Some((&[0, 1, 2, 0, 2, 3], ctype)),
                4,
                PLAIN,
                "",
            ))
            .unwrap();
            assert_eq!(
                g.mesh.triangles,
                vec![[0, 1, 2], [0, 2, 3]],
                "component type {ctype}"
            );
        }
        let g = read(&gltf_json(&QUAD[..3], None, 4, PLAIN, "")).unwrap();
        assert_eq!(g.mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn strips_and_fans_keep_winding() {
        let strip = read(&gltf_json(&QUAD, Some((&[0, 1, 3, 2], 5125)), 5, PLAIN, "")).unwrap();
        assert_eq!(strip.mesh.triangles, vec![[0, 1, 3], [3, 1, 2]]);
        let fan = read(&gltf_json(&QUAD, Some((&[0, 1, 2, 3], 5125)), 6, PLAIN, "")).unwrap();
        assert_eq!(fan.mesh.triangles, vec![[1, 2, 0], [2, 3, 0]]);
        // Both windings face +z like the triangle list.
        for m in [&strip.mesh, &fan.mesh] {
            for t in &m.triangles {
                let c = m.corners(t);
                let n = crate::geometry::cross(
                    crate::geometry::sub(c[1], c[0]),
                    crate::geometry::sub(c[2], c[0]),
                );
                assert!(n[2] > 0.0);
            }
        }
    }

    #[test]
    fn node_hierarchy_trs_and_matrix() {
        // Parent: translation (10,0,0), uniform scale 2. Child: rotation 90° about z (quaternion
        // x y z w), then a matrix node translating by (0,0,5) (column-major).
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let nodes = format!(
            r#"[{{"children":[1],"translation":[10,0,0],"scale":[2,2,2]}},{{"children":[2],"rotation":[0,0,{s},{s}]}},{{"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}}]"#
        );
        let g = read(&gltf_json(&QUAD[..3], None, 4, &nodes, "")).unwrap();
        // (1,0,0) → +z5 → (1,0,5) → rot z 90 → (0,1,5) → scale 2 → (0,2,10) → +10x → (10,2,10)
        let v = g.mesh.vertices[1];
        assert!(
            (v[0] - 10.0).abs() < 1e-6 && (v[1] - 2.0).abs() < 1e-6 && (v[2] - 10.0).abs() < 1e-6,
            "{v:?}"
        );
        assert_eq!(g.instances, 1);
    }

    #[test]
    fn mirroring_flips_winding() {
        let nodes = r#"[{"mesh":0,"scale":[-1,1,1]}]"#;
        let g = read(&gltf_json(&QUAD[..3], None, 4, nodes, "")).unwrap();
        assert_eq!(g.mesh.triangles, vec![[0, 2, 1]]);
    }

    #[test]
    fn glb_container_round_trip() {
        let json = gltf_json(&QUAD, Some((&[0, 1, 2, 0, 2, 3], 5123)), 4, PLAIN, "");
        let mut padded = json.clone();
        while !padded.len().is_multiple_of(4) {
            padded.push(b' ');
        }
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(((12 + 8 + padded.len()) as u32).to_le_bytes());
        glb.extend((padded.len() as u32).to_le_bytes());
        glb.extend(0x4E4F_534Au32.to_le_bytes());
        glb.extend(&padded);
        let g = read(&glb).unwrap();
        assert_eq!(g.mesh.triangles.len(), 2);
        assert!(matches!(
            read(&glb[..glb.len() - 10]),
            Err(Error::Truncated { .. })
        ));
    }

    #[test]
    fn points_and_lines_are_skipped_with_a_warning() {
        let g = read(&gltf_json(&QUAD, None, 0, PLAIN, ""));
        assert!(matches!(g, Err(Error::Empty { .. })));
    }

    #[test]
    fn unsupported_extensions_and_bad_indices() {
        let draco = gltf_json(
            &QUAD,
            None,
            4,
            PLAIN,
            r#""extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"#,
        );
        let e = read(&draco).unwrap_err();
        assert!(matches!(e, Error::Unsupported { .. }));
        assert!(e.to_string().contains("Draco"));
        let quant = gltf_json(
            &QUAD[..3],
            None,
            4,
            PLAIN,
            r#""extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],"#,
        );
        assert!(read(&quant).is_ok());
        let bad = gltf_json(&QUAD, Some((&[0, 1, 9], 5125)), 4, PLAIN, "");
        assert!(matches!(read(&bad), Err(Error::Malformed { .. })));
        assert!(matches!(read(b"{not json"), Err(Error::Malformed { .. })));
        let external = String::from_utf8(gltf_json(&QUAD[..3], None, 4, PLAIN, "")).unwrap();
        let cut = external.find("data:").unwrap();
        let end = external[cut..].find('"').unwrap() + cut;
        let ext = format!("{}mesh.bin{}", &external[..cut], &external[end..]);
        let e = read(ext.as_bytes()).unwrap_err();
        assert!(e.to_string().contains("mesh.bin"), "{e}");
        let buf: Vec<u8> = QUAD[..3]
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut files = BTreeMap::new();
        files.insert("mesh.bin".to_string(), buf);
        assert_eq!(
            read_gltf(ext.as_bytes(), &files)
                .unwrap()
                .mesh
                .triangles
                .len(),
            1
        );
    }

    /// Nodes `[{"children":[1,1]}, ..., {"mesh":0}]`: each level lists its child twice.
    fn dag(levels: usize) -> String {
        let mut nodes: Vec<String> = (0..levels)
            .map(|i| format!(r#"{{"children":[{},{}]}}"#, i + 1, i + 1))
            .collect();
        nodes.push(r#"{"mesh":0}"#.into());
        format!("[{}]", nodes.join(","))
    }

    #[test]
    fn node_graphs_must_be_trees() {
        let err = |nodes: &str, extra: &str| {
            read(&gltf_json(&QUAD[..3], None, 4, nodes, extra))
                .unwrap_err()
                .to_string()
        };
        // A DAG 40 levels deep (2^40 paths): refused at once, naming the node.
        let t = std::time::Instant::now();
        let e = err(&dag(40), "");
        assert!(e.contains("node 0 lists node 1 twice"), "{e}");
        assert!(t.elapsed().as_secs_f64() < 1.0);
        // Two parents.
        let e = err(r#"[{"children":[2]},{"children":[2]},{"mesh":0}]"#, "");
        assert!(
            e.contains("node 1 lists node 2 as a child, but node 0 already does"),
            "{e}"
        );
        // A cycle (not reachable from the scene root, which is fine otherwise).
        let e = err(r#"[{"mesh":0},{"children":[2]},{"children":[1]}]"#, "");
        assert!(e.contains("is its own ancestor"), "{e}");
        let e = err(r#"[{"mesh":0,"children":[0]}]"#, "");
        assert!(e.contains("node 0"), "{e}");
        // A scene repeating its root, and a root that is a child.
        let repeat = String::from_utf8(gltf_json(&QUAD[..3], None, 4, PLAIN, ""))
            .unwrap()
            .replace(
                r#""scenes":[{"nodes":[0]}]"#,
                r#""scenes":[{"nodes":[0,0,0]}]"#,
            );
        let e = read(repeat.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("scene 0 lists node 0 more than once"), "{e}");
        let child_root = String::from_utf8(gltf_json(
            &QUAD[..3],
            None,
            4,
            r#"[{"children":[1]},{"mesh":0}]"#,
            "",
        ))
        .unwrap()
        .replace(
            r#""scenes":[{"nodes":[0]}]"#,
            r#""scenes":[{"nodes":[0,1]}]"#,
        );
        let e = read(child_root.as_bytes()).unwrap_err().to_string();
        assert!(
            e.contains("node 1 as a root, but it is a child of node 0"),
            "{e}"
        );
        // A deep but valid chain is read (transforms composed once per node).
        let chain: Vec<String> = (0..100)
            .map(|i| format!(r#"{{"children":[{}],"translation":[1,0,0]}}"#, i + 1))
            .chain([r#"{"mesh":0}"#.to_string()])
            .collect();
        let g = read(&gltf_json(
            &QUAD[..3],
            None,
            4,
            &format!("[{}]", chain.join(",")),
            "",
        ))
        .unwrap();
        assert_eq!(g.mesh.vertices[0], [100.0, 0.0, 0.0]);
    }

    #[test]
    fn expanded_size_is_bounded_before_decoding() {
        // One mesh instanced by 10 000 nodes: 10 000 triangles.
        let nodes: Vec<String> = (0..10_000).map(|_| r#"{"mesh":0}"#.to_string()).collect();
        let roots: Vec<String> = (0..10_000).map(|i| i.to_string()).collect();
        let many = String::from_utf8(gltf_json(
            &QUAD[..3],
            None,
            4,
            &format!("[{}]", nodes.join(",")),
            "",
        ))
        .unwrap()
        .replace(
            r#""scenes":[{"nodes":[0]}]"#,
            &format!(r#""scenes":[{{"nodes":[{}]}}]"#, roots.join(",")),
        );
        let limits = ReadLimits::triangles(9_999);
        let e = read_gltf_with_limits(many.as_bytes(), &BTreeMap::new(), &limits).unwrap_err();
        assert_eq!(e.kind(), "limit_exceeded");
        let msg = e.to_string();
        assert!(
            msg.contains("10000") && msg.contains("9999") && msg.contains("max-triangles"),
            "{msg}"
        );
        let g = read_gltf_with_limits(
            many.as_bytes(),
            &BTreeMap::new(),
            &ReadLimits {
                max_triangles: 10_000,
                max_vertices: 30_000,
            },
        )
        .unwrap();
        assert_eq!((g.mesh.triangles.len(), g.instances), (10_000, 10_000));
        // An accessor without a buffer view costs no bytes: its count is bounded too.
        let sparse: Vec<u8> = 0u32
            .to_le_bytes()
            .into_iter()
            .chain([1.0f32, 2.0, 3.0].iter().flat_map(|v| v.to_le_bytes()))
            .collect();
        let b64 = base64::engine::general_purpose::STANDARD.encode(&sparse);
        let zeros = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"accessors":[{{"componentType":5126,"count":COUNT,"type":"VEC3","min":[0,0,0],"max":[0,0,0],"sparse":{{"count":1,"indices":{{"bufferView":0,"componentType":5125}},"values":{{"bufferView":1}}}}}}],"bufferViews":[{{"buffer":0,"byteLength":4}},{{"buffer":0,"byteOffset":4,"byteLength":12}}],"buffers":[{{"byteLength":16,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#
        );
        let g = read(zeros.replace("COUNT", "6").as_bytes()).unwrap();
        assert_eq!(g.mesh.vertices[0], [1.0, 2.0, 3.0]);
        assert_eq!(g.mesh.vertices[5], [0.0, 0.0, 0.0]);
        let e = read(zeros.replace("COUNT", "90000000").as_bytes()).unwrap_err();
        assert_eq!(e.kind(), "limit_exceeded", "{e}");
        // Huge node transforms: refused naming the node.
        let e = read(&gltf_json(
            &QUAD[..3],
            None,
            4,
            r#"[{"mesh":0,"scale":[1e30,1e30,1e30],"children":[1]},{"mesh":0,"scale":[1e30,1,1]}]"#,
            "",
        ))
        .unwrap_err();
        assert_eq!(e.kind(), "out_of_range");
        assert!(e.to_string().contains("node 1: transform"), "{e}");
    }

    #[test]
    fn quantized_normalized_positions_decode() {
        // u16 normalized positions (KHR_mesh_quantization style).
        let raw: Vec<u8> = [[0u16, 0, 0], [65535, 0, 0], [0, 65535, 0]]
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .chain([0, 0])
            .collect();
        let b64 = base64::engine::general_purpose::STANDARD.encode(&raw);
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"accessors":[{{"bufferView":0,"componentType":5123,"normalized":true,"count":3,"type":"VEC3"}}],"bufferViews":[{{"buffer":0,"byteLength":18,"byteStride":8}}],"buffers":[{{"byteLength":20,"uri":"data:application/gltf-buffer;base64,{b64}"}}]}}"#
        );
        // byteStride 8 with 6-byte elements: the third element ends at 2*8+6 = 22 > 18 → refused.
        assert!(read(json.as_bytes()).is_err());
        let json = json.replace(r#","byteStride":8"#, "");
        let g = read(json.as_bytes()).unwrap();
        assert_eq!(g.mesh.vertices[1], [1.0, 0.0, 0.0]);
    }
}
