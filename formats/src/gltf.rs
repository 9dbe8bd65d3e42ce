//! glTF 2.0 (`.gltf` with data-URI or external buffers, and `.glb`) through the `gltf` crate: walks the
//! default scene applying every node's transform; each primitive instance becomes a patch; TRIANGLES,
//! TRIANGLE_STRIP and TRIANGLE_FAN, indexed (u8/u16/u32) or not. Other modes are skipped with a
//! warning. Vertices are per primitive, so the caller welds them.

use crate::error::Problem;
use base64::Engine;
use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::{DMat4, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::{Accessor, Node, Semantic};
use std::borrow::Cow;
use std::io::Read;
use std::path::Path;

/// Checks a `.glb` container's declared lengths against the bytes before the `gltf` crate reads
/// it: its GLB parser subtracts and slices by them unchecked (found by fuzzing).
fn glb_within_bounds(bytes: &[u8]) -> Result<(), Problem> {
    const HEADER: usize = 12;
    const CHUNK_HEADER: usize = 8;
    let word = |at: usize| -> Option<usize> {
        let b = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let Some(length) = word(8) else {
        return Err(Problem::at_byte(0, "truncated GLB: no 12-byte header"));
    };
    if length < HEADER + CHUNK_HEADER || length > bytes.len() {
        return Err(Problem::at_byte(
            8,
            format!(
                "the GLB header announces {length} bytes, the file holds {}",
                bytes.len()
            ),
        ));
    }
    let mut at = HEADER;
    while at < length {
        let chunk = match word(at) {
            Some(n) if at + CHUNK_HEADER <= length => n,
            _ => {
                return Err(Problem::at_byte(
                    at as u64,
                    "truncated GLB: a chunk header past the announced length",
                ));
            }
        };
        let end = at + CHUNK_HEADER + chunk;
        if end > length {
            return Err(Problem::at_byte(
                at as u64,
                format!("a GLB chunk of {chunk} bytes runs past the announced length {length}"),
            ));
        }
        at = end;
    }
    Ok(())
}

pub(crate) fn read(
    bytes: &[u8],
    dir: Option<&Path>,
) -> Result<(SurfaceMesh, Vec<String>), Problem> {
    let gltf = parse(bytes)?;
    let buffers = load_buffers(&gltf, dir)?;
    check_tree(&gltf)?;
    let roots = scene_roots(&gltf);
    let mut out = Reader {
        buffers: &buffers,
        mesh: SurfaceMesh::default(),
        warnings: Vec::new(),
    };
    let max_depth = gltf.nodes().len();
    let mut stack: Vec<(Node, DMat4, usize)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, DMat4::IDENTITY, 0))
        .collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > max_depth {
            return Err(Problem::bad("the node hierarchy has a cycle"));
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            let multi = mesh.primitives().len() > 1;
            let base = mesh
                .name()
                .or(node.name())
                .map_or_else(|| format!("mesh {}", mesh.index()), str::to_owned);
            for prim in mesh.primitives() {
                let name = if multi {
                    format!("{base}/{}", prim.index())
                } else {
                    base.clone()
                };
                out.primitive(&prim, &world, name)?;
            }
        }
        let children: Vec<Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }
    Ok((out.mesh, out.warnings))
}

/// The document (JSON or GLB), validated.
fn parse(bytes: &[u8]) -> Result<gltf::Gltf, Problem> {
    let not_gltf = |e: gltf::Error| Problem::bad(format!("not a readable glTF file: {e}"));
    // JSON glTF is text (a Latin-1 byte in a name should not sink it); `.glb` starts with a magic.
    let text = (!bytes.starts_with(b"glTF")).then(|| String::from_utf8_lossy(bytes));
    if text.is_none() {
        glb_within_bounds(bytes)?;
    }
    let json = text.as_deref().map_or(bytes, str::as_bytes);
    let raw = gltf::Gltf::from_slice_without_validation(json).map_err(not_gltf)?;
    // gltf-json's validation indexes the POSITION accessor without a bounds check: check it first.
    let json = raw.document.into_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &prim.attributes {
                if accessor.value() >= json.accessors.len() {
                    return Err(Problem::bad(format!(
                        "mesh {m} primitive {p}: attribute {semantic:?} refers to accessor {} of {}",
                        accessor.value(),
                        json.accessors.len()
                    )));
                }
            }
        }
    }
    Ok(gltf::Gltf {
        document: gltf::Document::from_json(json).map_err(not_gltf)?,
        blob: raw.blob,
    })
}

/// The bytes of every buffer, each checked to hold the length it declares.
fn load_buffers<'g>(
    gltf: &'g gltf::Gltf,
    dir: Option<&Path>,
) -> Result<Vec<Cow<'g, [u8]>>, Problem> {
    let mut buffers: Vec<Cow<[u8]>> = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(gltf.blob.as_deref().ok_or_else(|| {
                Problem::bad("buffer 0 refers to the GLB binary chunk, which is missing")
            })?),
            gltf::buffer::Source::Uri(uri) => Cow::Owned(load_uri(uri, dir, buffer.length())?),
        };
        if data.len() < buffer.length() {
            return Err(Problem::bad(format!(
                "buffer {} declares {} bytes but holds {}",
                buffer.index(),
                buffer.length(),
                data.len()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The root nodes to read.
fn scene_roots(gltf: &gltf::Gltf) -> Vec<Node<'_>> {
    // The default scene, else the first; a file without scenes shows every root node.
    let scene = gltf.default_scene().or_else(|| gltf.scenes().next());
    match &scene {
        Some(s) => s.nodes().collect(),
        None => {
            let children: Vec<usize> = gltf
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()))
                .collect();
            gltf.nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    }
}

/// Refuses a node with two parents.
fn check_tree(gltf: &gltf::Gltf) -> Result<(), Problem> {
    // glTF node hierarchies are disjoint trees: a node reached twice would make the number of
    // instances exponential in the number of nodes (60 nodes, each the child of the two before).
    let mut parents = vec![0u8; gltf.nodes().len()];
    for child in gltf.nodes().flat_map(|n| n.children()) {
        let count = &mut parents[child.index()];
        *count = count.saturating_add(1);
        if *count > 1 {
            return Err(Problem::bad(format!(
                "node {} has more than one parent (glTF node hierarchies are trees)",
                child.index()
            )));
        }
    }
    Ok(())
}

/// A buffer's bytes: a base64 data URI, or a file next to the glTF.
fn load_uri(uri: &str, dir: Option<&Path>, length: usize) -> Result<Vec<u8>, Problem> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| Problem::Unsupported("data URIs must be base64-encoded".into()))?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| Problem::bad(format!("bad base64 in a data URI: {e}")));
    }
    let dir = dir.ok_or_else(|| {
        Problem::Unsupported(format!(
            "external buffer {} cannot be resolved without a file location",
            crate::text::quote(uri)
        ))
    })?;
    let path = inside_folder(dir, uri)?;
    let file = std::fs::File::open(&path)
        .map_err(|e| Problem::bad(format!("external buffer {}: {e}", path.display())))?;
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        return Err(Problem::Unsupported(format!(
            "external buffer {}: not a regular file",
            path.display()
        )));
    }
    // Never read more than the buffer declares (a FIFO or a huge file next to the glTF).
    let mut data = Vec::new();
    file.take(length as u64)
        .read_to_end(&mut data)
        .map_err(|e| Problem::bad(format!("external buffer {}: {e}", path.display())))?;
    Ok(data)
}

/// The file a relative buffer URI names in the glTF's folder `dir`; anything that could leave
/// that folder (absolute paths, schemes, `..` even percent-encoded, symbolic links pointing out)
/// is refused.
fn inside_folder(dir: &Path, uri: &str) -> Result<std::path::PathBuf, Problem> {
    let refuse = |why: &str| {
        Problem::Unsupported(format!(
            "buffer URI {}: {why}; only files in the glTF's folder are read",
            crate::text::quote(uri)
        ))
    };
    let decoded = percent_decode(uri);
    let relative = Path::new(&decoded);
    if decoded.contains("://") || decoded.contains('\\') || decoded.contains('\0') {
        return Err(refuse("not a relative file name"));
    }
    let plain = relative.components().all(|c| {
        matches!(
            c,
            std::path::Component::Normal(_) | std::path::Component::CurDir
        )
    });
    if !plain {
        return Err(refuse("it leaves the folder"));
    }
    let path = dir.join(relative);
    // Symbolic links are followed only where they stay inside the folder.
    if let (Ok(real), Ok(base)) = (path.canonicalize(), dir.canonicalize()) {
        if !real.starts_with(&base) {
            return Err(refuse("it links out of the folder"));
        }
    }
    Ok(path)
}

/// URIs escape spaces and other bytes as `%XX`.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (b[i], hex) {
            (b'%', Some(x)) => {
                out.push(x);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

struct Reader<'b> {
    buffers: &'b [Cow<'b, [u8]>],
    mesh: SurfaceMesh,
    warnings: Vec<String>,
}

impl Reader<'_> {
    /// Checks what the gltf crate's accessor iterators assume (its debug assertions and unchecked
    /// arithmetic would otherwise panic on a malformed file).
    fn check(
        &self,
        a: &Accessor,
        what: &str,
        types: &[DataType],
        dims: Dimensions,
    ) -> Result<(), Problem> {
        let name = format!("{what} accessor {}", a.index());
        if !types.contains(&a.data_type()) || a.dimensions() != dims {
            return Err(Problem::bad(format!(
                "{name} has type {:?} {:?}",
                a.data_type(),
                a.dimensions()
            )));
        }
        if a.sparse().is_some() {
            return Err(Problem::Unsupported(format!("{name} is sparse")));
        }
        let view = a
            .view()
            .ok_or_else(|| Problem::Unsupported(format!("{name} has no buffer view")))?;
        if a.count() == 0 {
            return Err(Problem::bad(format!("{name} is empty")));
        }
        let elem = a.size();
        let stride = view.stride().unwrap_or(elem);
        let end = stride
            .checked_mul(a.count() - 1)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(a.offset()));
        if stride < elem || end.is_none_or(|e| e > view.length()) {
            return Err(Problem::bad(format!("{name} runs past its buffer view")));
        }
        let buffer_len = self
            .buffers
            .get(view.buffer().index())
            .map_or(0, |b| b.len());
        if view
            .offset()
            .checked_add(view.length())
            .is_none_or(|e| e > buffer_len)
        {
            return Err(Problem::bad(format!(
                "buffer view {} runs past its buffer",
                view.index()
            )));
        }
        Ok(())
    }

    fn primitive(
        &mut self,
        prim: &gltf::Primitive,
        world: &DMat4,
        name: String,
    ) -> Result<(), Problem> {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warnings
                .push(format!("skipped primitive {name:?} of mode {mode:?}"));
            return Ok(());
        }
        let positions = prim
            .get(&Semantic::Positions)
            .ok_or_else(|| Problem::bad(format!("primitive {name:?} has no POSITION")))?;
        self.check(&positions, "POSITION", &[DataType::F32], Dimensions::Vec3)?;
        if let Some(ind) = prim.indices() {
            self.check(
                &ind,
                "index",
                &[DataType::U8, DataType::U16, DataType::U32],
                Dimensions::Scalar,
            )?;
        }
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
        let points: Vec<DVec3> = reader
            .read_positions()
            .ok_or_else(|| Problem::bad(format!("primitive {name:?}: unreadable positions")))?
            .map(|p| world.transform_point3(DVec3::new(p[0].into(), p[1].into(), p[2].into())))
            .collect();
        if let Some(bad) = points.iter().find(|p| !p.is_finite()) {
            return Err(Problem::bad(format!(
                "primitive {name:?} has a non-finite vertex {bad}"
            )));
        }
        let n = points.len() as u32;
        let indices: Vec<u32> = match reader.read_indices() {
            Some(ind) => ind.into_u32().collect(),
            None => (0..n).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i >= n) {
            return Err(Problem::bad(format!(
                "primitive {name:?}: index {bad} out of range (only {n} vertices)"
            )));
        }
        let k = indices.len();
        let mut tris: Vec<[u32; 3]> = match mode {
            Mode::Triangles => {
                if k % 3 != 0 {
                    self.warnings.push(format!(
                        "primitive {name:?}: {k} indices is not a multiple of 3"
                    ));
                }
                indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect()
            }
            // Every other strip triangle is reversed to keep one orientation; the degenerate
            // triangles that join strips are dropped.
            Mode::TriangleStrip => (0..k.saturating_sub(2))
                .map(|i| {
                    let (a, b, c) = (indices[i], indices[i + 1], indices[i + 2]);
                    if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
                })
                .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
                .collect(),
            _ => (1..k.saturating_sub(1))
                .map(|i| [indices[0], indices[i], indices[i + 1]])
                .collect(),
        };
        // A mirroring transform turns counter-clockwise triangles clockwise.
        if world.determinant() < 0.0 {
            tris.iter_mut().for_each(|t| t.swap(1, 2));
        }
        let m = &mut self.mesh;
        let base = m.positions.len() as u32;
        let patch = PatchId(m.patch_names.len() as u32);
        m.patch_names.push(name);
        m.positions.extend(points);
        m.patches.extend(std::iter::repeat_n(patch, tris.len()));
        m.triangles
            .extend(tris.into_iter().map(|t| t.map(|v| v + base)));
        Ok(())
    }
}
