//! VTK legacy (`.vtk`) and XML (`.vtu`, `.vtp`) readers through `vtkio`: unstructured grids and poly
//! data; tetrahedra, triangles (polygons and strips triangulated), lines as feature edges, with the
//! cell data `subdomain`, `patch`, `curve` and any other one-component cell array on tets.

use crate::error::{Problem, contain_panics};
use crate::{AnyMesh, Format};
use delamesh_core::mesh::{CellField, CurveId, PatchId, SubdomainId, TetMesh};
use glam::DVec3;
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece, VertexNumbers};

pub(crate) fn read(bytes: &[u8], format: Format) -> Result<(AnyMesh, Vec<String>), Problem> {
    let (mesh, warnings, poly) = read_cells(bytes, format)?;
    if poly || (mesh.tets.is_empty() && format == Format::Vtp) {
        let mut s = mesh.boundary_surface();
        if mesh.boundary_patches.iter().all(|p| p.0 == 0) {
            s.patch_names = vec!["surface".into()];
        }
        Ok((AnyMesh::Surface(s), warnings))
    } else {
        Ok((AnyMesh::Volume(mesh), warnings))
    }
}

/// Every cell of the file as a volume mesh (line cells as feature edges), its warnings, and whether
/// it was poly data.
pub(crate) fn read_cells(
    bytes: &[u8],
    format: Format,
) -> Result<(TetMesh, Vec<String>, bool), Problem> {
    read_cells_and_point_fields(bytes, format).map(|(m, _, w, poly)| (m, w, poly))
}

/// [`read_cells`] with the one-component point arrays (NaN in pieces that lack one).
pub(crate) fn read_cells_and_point_fields(
    bytes: &[u8],
    format: Format,
) -> Result<(TetMesh, Vec<CellField>, Vec<String>, bool), Problem> {
    let vtk = parse(bytes, format)?;
    let poly = matches!(vtk.data, DataSet::PolyData { .. });
    let mut b = Builder::default();
    add_pieces(&mut b, vtk.data)?;
    let Builder {
        mesh,
        point_fields,
        mut warnings,
        skipped,
    } = b;
    for (ty, n) in skipped {
        warnings.push(format!("skipped {n} cells of VTK type {ty}"));
    }
    Ok((mesh, point_fields, warnings, poly))
}

/// The file parsed by vtkio, after its magic is checked and what vtkio cannot read is re-encoded.
fn parse(bytes: &[u8], format: Format) -> Result<vtkio::Vtk, Problem> {
    let start = bytes.trim_ascii_start();
    let magic_ok = match format {
        Format::Vtk => start.starts_with(b"# vtk DataFile"),
        _ => start.starts_with(b"<"),
    };
    if !magic_ok {
        let want = if format == Format::Vtk {
            "\"# vtk DataFile Version\""
        } else {
            "an XML tag"
        };
        return Err(Problem::at_byte(
            0,
            format!("wrong magic: a {format} file starts with {want}"),
        ));
    }
    let reencoded = match format {
        Format::Vtk => spell_nan_for_vtkio(bytes),
        _ => raw_appended_to_base64(bytes)?,
    };
    let bytes = reencoded.as_deref().unwrap_or(bytes);
    // With raw appended data re-encoded, an XML file is text: a Latin-1 byte in a comment or a
    // name should not sink it.
    let text = (format != Format::Vtk).then(|| String::from_utf8_lossy(bytes));
    let bytes = text.as_deref().map_or(bytes, str::as_bytes);
    let parsed = contain_panics(|| match format {
        Format::Vtk => vtkio::Vtk::parse_legacy_be(bytes),
        _ => vtkio::Vtk::parse_xml(bytes),
    })
    .map_err(|why| {
        Problem::bad(format!(
            "malformed VTK file (vtkio gave up: {})",
            plain(&why)
        ))
    })?;
    parsed.map_err(|e| {
        Problem::bad(format!(
            "not a readable VTK file: {}",
            plain(&e.to_string())
        ))
    })
}

/// Adds every piece of an unstructured grid or poly data set to `b`.
fn add_pieces(b: &mut Builder, data: DataSet) -> Result<(), Problem> {
    match data {
        DataSet::UnstructuredGrid { pieces, .. } => {
            for piece in pieces {
                let p = inline(piece)?;
                let cells = cell_list(p.cells.cell_verts)?;
                let types: Vec<u8> = p.cells.types.iter().map(|&t| t as u8).collect();
                if types.len() != cells.len() {
                    return Err(Problem::bad(format!(
                        "{} cell types for {} cells",
                        types.len(),
                        cells.len()
                    )));
                }
                b.piece(
                    &p.points,
                    cells.iter().zip(types),
                    &p.data.cell,
                    &p.data.point,
                )?;
            }
        }
        DataSet::PolyData { pieces, .. } => {
            for piece in pieces {
                let p = inline(piece)?;
                // VTK numbers poly data cells verts, then lines, then polys, then strips.
                let mut all = Vec::new();
                for (topo, ty) in [
                    (p.verts, CellType::Vertex),
                    (p.lines, CellType::PolyLine),
                    (p.polys, CellType::Polygon),
                    (p.strips, CellType::TriangleStrip),
                ] {
                    if let Some(t) = topo {
                        all.extend(cell_list(t)?.into_iter().map(|c| (c, ty as u8)));
                    }
                }
                b.piece(
                    &p.points,
                    all.iter().map(|(c, t)| (c, *t)),
                    &p.data.cell,
                    &p.data.point,
                )?;
            }
        }
        _ => {
            return Err(Problem::Unsupported(
                "only UnstructuredGrid and PolyData VTK data sets hold meshes".into(),
            ));
        }
    }
    Ok(())
}

/// vtkio's messages in plain words: its errors end in `Debug` dumps of nested library errors
/// (`InvalidInt(ParseIntError { kind: PosOverflow })`); keep the words before the first dump,
/// spell its variant name out (`invalid int`) and cut the result to one short line.
fn plain(message: &str) -> String {
    let line = message.lines().next().unwrap_or_default();
    let dump = line.char_indices().find(|&(i, c)| {
        (c == '(' || c == '{') && line[..i].ends_with(|p: char| p.is_alphanumeric())
    });
    let (words, variant) = match dump {
        Some((i, _)) => {
            let head = &line[..i];
            let cut = head
                .char_indices()
                .rfind(|&(_, c)| !c.is_alphanumeric())
                .map_or(0, |(k, c)| k + c.len_utf8());
            (&head[..cut], &head[cut..])
        }
        None => (line, ""),
    };
    let mut out = words.trim_end().to_string();
    if !variant.is_empty() {
        let mut spelled = String::new();
        for (k, c) in variant.chars().enumerate() {
            if c.is_uppercase() && k > 0 {
                spelled.push(' ');
            }
            spelled.extend(c.to_lowercase());
        }
        out = format!("{} {spelled}", out.trim_end()).trim().to_string();
    }
    match out.char_indices().nth(160) {
        Some((cut, _)) => format!("{}…", &out[..cut]),
        None => out,
    }
}

/// vtkio's ASCII number parser rejects `nan`, which VTK writes (and we write for the cells a per-tet
/// field does not apply to): spell it as a number that overflows to infinity. `None` if no `nan`.
fn spell_nan_for_vtkio(bytes: &[u8]) -> Option<Vec<u8>> {
    let ascii = bytes
        .split(|&b| b == b'\n')
        .nth(2)
        .is_some_and(|l| l.trim_ascii().eq_ignore_ascii_case(b"ASCII"));
    if !ascii {
        return None;
    }
    let mut out = Vec::with_capacity(bytes.len());
    let mut changed = false;
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_whitespace() {
            out.push(bytes[i]);
            i += 1;
            continue;
        }
        let end = bytes[i..]
            .iter()
            .position(u8::is_ascii_whitespace)
            .map_or(bytes.len(), |k| i + k);
        let word = &bytes[i..end];
        if word.eq_ignore_ascii_case(b"nan") {
            out.extend_from_slice(b"1e999");
            changed = true;
        } else {
            out.extend_from_slice(word);
        }
        i = end;
    }
    changed.then_some(out)
}

/// vtkio reads appended data only base64-encoded, while VTK and ParaView (and our writer) default to
/// raw bytes: re-encode each raw block as base64 and rewrite the offsets. `None` when there is no raw
/// appended data.
pub(crate) fn raw_appended_to_base64(bytes: &[u8]) -> Result<Option<Vec<u8>>, Problem> {
    use base64::Engine;
    let find = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).position(|w| w == needle);
    let Some(tag) = find(bytes, b"<AppendedData") else {
        return Ok(None);
    };
    let tag_len = find(&bytes[tag..], b">")
        .ok_or_else(|| Problem::at_byte(tag as u64, "unterminated AppendedData tag"))?;
    // XML allows either quote around attribute values.
    let quoted = |hay: &[u8], value: &str| {
        find(hay, format!("\"{value}\"").as_bytes())
            .or_else(|| find(hay, format!("'{value}'").as_bytes()))
            .is_some()
    };
    if !quoted(&bytes[tag..tag + tag_len], "raw") {
        return Ok(None);
    }
    let head = &bytes[..tag];
    let layout = BlockLayout {
        header_bytes: if quoted(head, "UInt64") { 8 } else { 4 },
        big_endian: quoted(head, "BigEndian"),
        compressed: find(head, b"compressor=").is_some(),
    };
    let underscore = find(&bytes[tag + tag_len..], b"_")
        .map(|i| tag + tag_len + i)
        .ok_or_else(|| Problem::at_byte(tag as u64, "AppendedData without the '_' marker"))?;
    let start = underscore + 1;
    let end = bytes[start..]
        .windows(b"</AppendedData>".len())
        .rposition(|w| w == b"</AppendedData>")
        .map(|i| start + i)
        .ok_or_else(|| {
            Problem::at_byte(bytes.len() as u64, "truncated file: no </AppendedData>")
        })?;
    let raw = &bytes[start..end];

    // Offsets of the DataArrays, in file order.
    let mut marks = Vec::new();
    let mut at = 0;
    while let Some(i) = find(&head[at..], b" offset=") {
        let quote_at = at + i + b" offset=".len();
        let quote = head
            .get(quote_at)
            .copied()
            .filter(|&q| q == b'"' || q == b'\'');
        let Some(quote) = quote else {
            at = quote_at;
            continue;
        };
        let value_start = quote_at + 1;
        let len = head[value_start..]
            .iter()
            .position(|&b| b == quote)
            .ok_or_else(|| Problem::at_byte(value_start as u64, "unterminated offset attribute"))?;
        let value = std::str::from_utf8(&head[value_start..value_start + len])
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok());
        let value = value.filter(|&v| v <= raw.len()).ok_or_else(|| {
            Problem::at_byte(
                value_start as u64,
                format!("offset outside the {} bytes of appended data", raw.len()),
            )
        })?;
        marks.push((value_start, value_start + len, value));
        at = value_start + len;
    }
    let mut blocks: Vec<usize> = marks.iter().map(|m| m.2).collect();
    blocks.sort_unstable();
    blocks.dedup();
    let mut encoded = Vec::with_capacity(raw.len() * 4 / 3 + 8);
    let mut new_offset = std::collections::BTreeMap::new();
    for (k, &b) in blocks.iter().enumerate() {
        let limit = blocks.get(k + 1).copied().unwrap_or(raw.len());
        new_offset.insert(b, encoded.len());
        // VTK base64-encodes a compressed block's header and its data separately, an uncompressed
        // block's header and data together: mirror that, which is what vtkio decodes.
        for part in layout.split(&raw[b..limit], start + b)? {
            encoded.extend(
                base64::engine::general_purpose::STANDARD
                    .encode(part)
                    .bytes(),
            );
        }
    }
    let mut out = Vec::with_capacity(bytes.len() * 4 / 3 + 64);
    let mut copied = 0;
    for (s, e, v) in marks {
        out.extend_from_slice(&head[copied..s]);
        out.extend(new_offset.get(&v).copied().unwrap_or(0).to_string().bytes());
        copied = e;
    }
    out.extend_from_slice(&head[copied..]);
    out.extend_from_slice(b"<AppendedData encoding=\"base64\">_");
    out.extend_from_slice(&encoded);
    out.extend_from_slice(&bytes[end..]);
    Ok(Some(out))
}

/// The most deflate can expand data (RFC 1951: a 258-byte match costs at least 2 bits), rounded up.
const MAX_INFLATE_RATIO: usize = 1100;

/// How the blocks of raw appended data are framed (VTKFile attributes `header_type`, `byte_order`,
/// `compressor`).
struct BlockLayout {
    header_bytes: usize,
    big_endian: bool,
    compressed: bool,
}

impl BlockLayout {
    fn uint(&self, b: &[u8], at: usize) -> Option<usize> {
        let field = b.get(at..at.checked_add(self.header_bytes)?)?;
        let fold = |v: u64, &b: &u8| (v << 8) | u64::from(b);
        let v = if self.big_endian {
            field.iter().fold(0, fold)
        } else {
            field.iter().rev().fold(0, fold)
        };
        usize::try_from(v).ok()
    }

    /// The header and data of one block (which may be followed by padding up to the next block),
    /// checked against the space the block has; `file_offset` locates errors.
    fn split<'a>(&self, block: &'a [u8], file_offset: usize) -> Result<Vec<&'a [u8]>, Problem> {
        let overrun = || {
            Problem::at_byte(
                file_offset as u64,
                "appended data block runs past its end (truncated or corrupt)",
            )
        };
        let h = self.header_bytes;
        if !self.compressed {
            let n = self.uint(block, 0).ok_or_else(overrun)?;
            let end = n
                .checked_add(h)
                .filter(|&e| e <= block.len())
                .ok_or_else(overrun)?;
            return Ok(vec![&block[..end]]);
        }
        // [number of blocks, block size, last block size, compressed size of each block], then data.
        let count = self.uint(block, 0).ok_or_else(overrun)?;
        let header_len = count
            .checked_add(3)
            .and_then(|c| c.checked_mul(h))
            .filter(|&l| l <= block.len())
            .ok_or_else(overrun)?;
        let mut data_len = 0usize;
        for i in 0..count {
            let size = self.uint(block, (3 + i) * h).ok_or_else(overrun)?;
            data_len = data_len.checked_add(size).ok_or_else(overrun)?;
        }
        let end = header_len
            .checked_add(data_len)
            .filter(|&e| e <= block.len())
            .ok_or_else(overrun)?;
        // The decompressor reserves what the header announces: refuse more than zlib can make of
        // the compressed bytes (deflate expands at most 1032:1).
        let (block_size, last) = (
            self.uint(block, h).ok_or_else(overrun)?,
            self.uint(block, 2 * h).ok_or_else(overrun)?,
        );
        let most = data_len
            .saturating_mul(MAX_INFLATE_RATIO)
            .saturating_add(count * 64);
        let announced = block_size
            .saturating_mul(count.saturating_sub(1))
            .saturating_add(if last == 0 { block_size } else { last });
        // VTK announces its 32 KiB block size even for one short block: allow a block size of up
        // to a mebibyte whatever the data.
        if block_size > most.max(1 << 20) || announced > most {
            return Err(Problem::at_byte(
                file_offset as u64,
                format!(
                    "the compression header announces {announced} bytes from {data_len} compressed: \
                     corrupt"
                ),
            ));
        }
        Ok(vec![&block[..header_len], &block[header_len..end]])
    }
}

fn inline<P>(piece: Piece<P>) -> Result<P, Problem> {
    match piece {
        Piece::Inline(p) => Ok(*p),
        _ => Err(Problem::Unsupported(
            "pieces stored in other files are not supported".into(),
        )),
    }
}

/// Cells as vertex lists, checking the counts and offsets that vtkio leaves unchecked.
fn cell_list(v: VertexNumbers) -> Result<Vec<Vec<u64>>, Problem> {
    let mut cells = Vec::new();
    match v {
        VertexNumbers::Legacy {
            num_cells,
            vertices,
        } => {
            let mut rest = vertices.as_slice();
            while let Some((&n, tail)) = rest.split_first() {
                let n = n as usize;
                let verts = tail.get(..n).ok_or_else(|| {
                    Problem::bad(format!(
                        "cell {} has {n} vertices but the cell list ends first",
                        cells.len()
                    ))
                })?;
                cells.push(verts.iter().map(|&x| u64::from(x)).collect());
                rest = &tail[n..];
            }
            if cells.len() != num_cells as usize {
                return Err(Problem::bad(format!(
                    "the CELLS header announces {num_cells} cells, the list holds {}",
                    cells.len()
                )));
            }
        }
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            let mut start = 0usize;
            for &end in &offsets {
                let end = usize::try_from(end).unwrap_or(usize::MAX);
                let verts = connectivity.get(start..end).ok_or_else(|| {
                    Problem::bad(format!(
                        "cell {} has offset {end} outside the connectivity array",
                        cells.len()
                    ))
                })?;
                cells.push(verts.to_vec());
                start = end;
            }
        }
    }
    Ok(cells)
}

/// Every array with its name and component count, whether SCALARS / DataArray or legacy FIELD
/// arrays.
fn named_arrays(data: &[Attribute]) -> impl Iterator<Item = (&str, usize, &IOBuffer)> {
    data.iter().flat_map(|attr| match attr {
        Attribute::DataArray(a) => vec![(a.name.as_str(), a.num_comp(), &a.data)],
        Attribute::Field { data_array, .. } => data_array
            .iter()
            .map(|f| (f.name.as_str(), f.num_comp(), &f.data))
            .collect(),
    })
}

/// Where a file cell went in the mesh, to distribute cell data.
#[derive(Clone, Copy)]
enum Slot {
    Tet(usize),
    Triangles(usize, usize),
    Edges(usize, usize),
    Skipped,
}

#[derive(Default)]
struct Builder {
    mesh: TetMesh,
    /// One-component point arrays, one value per point of `mesh`.
    point_fields: Vec<CellField>,
    warnings: Vec<String>,
    /// Skipped cells per VTK type, sorted so warnings come out in a fixed order.
    skipped: std::collections::BTreeMap<u8, usize>,
}

impl Builder {
    fn piece<'a>(
        &mut self,
        points: &IOBuffer,
        cells: impl Iterator<Item = (&'a Vec<u64>, u8)>,
        cell_data: &[Attribute],
        point_data: &[Attribute],
    ) -> Result<(), Problem> {
        let (base, n) = self.add_points(points)?;
        let slots = self.add_cells(cells, base, n)?;
        self.add_cell_data(&slots, cell_data)?;
        self.add_point_data(base, n, point_data)
    }

    /// Keeps the piece's one-component point arrays (points `base..base + n`).
    fn add_point_data(
        &mut self,
        base: usize,
        n: usize,
        point_data: &[Attribute],
    ) -> Result<(), Problem> {
        let total = self.mesh.positions.len();
        for field in &mut self.point_fields {
            field.values.resize(total, f64::NAN);
        }
        for (name, components, data) in named_arrays(point_data) {
            if components != 1 {
                continue;
            }
            let Some(values) = data.cast_into::<f64>() else {
                continue;
            };
            if values.len() != n {
                return Err(Problem::bad(format!(
                    "point array {name:?} has {} values for {n} points",
                    values.len()
                )));
            }
            let at = match self.point_fields.iter().position(|f| f.name == name) {
                Some(i) => i,
                None => {
                    self.point_fields.push(CellField {
                        name: name.into(),
                        values: vec![f64::NAN; total],
                    });
                    self.point_fields.len() - 1
                }
            };
            self.point_fields[at].values[base..base + n].copy_from_slice(&values);
        }
        Ok(())
    }

    /// Appends the piece's points; returns the index of its first point and its point count.
    fn add_points(&mut self, points: &IOBuffer) -> Result<(usize, usize), Problem> {
        let coords: Vec<f64> = points
            .cast_into()
            .ok_or_else(|| Problem::bad("points are not numbers"))?;
        if coords.len() % 3 != 0 {
            return Err(Problem::bad(format!(
                "{} point coordinates is not a multiple of 3",
                coords.len()
            )));
        }
        let base = self.mesh.positions.len();
        self.mesh
            .positions
            .extend(coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])));
        Ok((base, coords.len() / 3))
    }

    /// Appends the piece's cells (tets, triangulated faces, edges), vertices numbered from `base`
    /// among its `n` points; returns where each file cell went.
    fn add_cells<'a>(
        &mut self,
        cells: impl Iterator<Item = (&'a Vec<u64>, u8)>,
        base: usize,
        n: usize,
    ) -> Result<Vec<Slot>, Problem> {
        let index = |cell: usize, v: u64| -> Result<u32, Problem> {
            if v >= n as u64 {
                return Err(Problem::bad(format!(
                    "cell {cell} refers to point {v}, there are {n} points"
                )));
            }
            u32::try_from(base as u64 + v)
                .map_err(|_| Problem::Unsupported("more than 2^32 points".into()))
        };
        let m = &mut self.mesh;
        let mut slots = Vec::new();
        for (i, (verts, ty)) in cells.enumerate() {
            let ids = verts
                .iter()
                .map(|&v| index(i, v))
                .collect::<Result<Vec<u32>, _>>()?;
            let (t0, e0) = (m.boundary.len(), m.feature_edges.len());
            let slot = match (ty, ids.len()) {
                (t, 4) if t == CellType::Tetra as u8 => {
                    m.tets.push([ids[0], ids[1], ids[2], ids[3]]);
                    Slot::Tet(m.tets.len() - 1)
                }
                (t, k)
                    if (t == CellType::Triangle as u8 && k == 3)
                        || ((t == CellType::Polygon as u8 || t == CellType::Quad as u8)
                            && k >= 3) =>
                {
                    m.boundary
                        .extend((1..k - 1).map(|j| [ids[0], ids[j], ids[j + 1]]));
                    Slot::Triangles(t0, m.boundary.len())
                }
                (t, k) if t == CellType::Pixel as u8 && k == 4 => {
                    m.boundary
                        .extend([[ids[0], ids[1], ids[3]], [ids[0], ids[3], ids[2]]]);
                    Slot::Triangles(t0, m.boundary.len())
                }
                (t, k) if t == CellType::TriangleStrip as u8 && k >= 3 => {
                    m.boundary.extend((0..k - 2).map(|j| {
                        if j % 2 == 0 {
                            [ids[j], ids[j + 1], ids[j + 2]]
                        } else {
                            [ids[j + 1], ids[j], ids[j + 2]]
                        }
                    }));
                    Slot::Triangles(t0, m.boundary.len())
                }
                (t, k)
                    if (t == CellType::Line as u8 || t == CellType::PolyLine as u8) && k >= 2 =>
                {
                    m.feature_edges.extend(ids.windows(2).map(|w| [w[0], w[1]]));
                    Slot::Edges(e0, m.feature_edges.len())
                }
                _ => {
                    *self.skipped.entry(ty).or_default() += 1;
                    Slot::Skipped
                }
            };
            slots.push(slot);
        }
        Ok(slots)
    }

    /// Distributes the piece's one-component cell arrays: labels (`subdomain`, `patch`, `curve`)
    /// and per-tet fields, resized for the cells just added.
    fn add_cell_data(&mut self, slots: &[Slot], cell_data: &[Attribute]) -> Result<(), Problem> {
        let m = &mut self.mesh;
        let tets_before = m.subdomains.len();
        m.subdomains.resize(m.tets.len(), SubdomainId(0));
        m.boundary_patches.resize(m.boundary.len(), PatchId(0));
        m.feature_curves.resize(m.feature_edges.len(), CurveId(0));
        for field in &mut m.cell_fields {
            field.values.resize(m.tets.len(), f64::NAN);
        }
        for (name, components, data) in named_arrays(cell_data) {
            if components != 1 {
                continue;
            }
            let Some(values) = data.cast_into::<f64>() else {
                continue;
            };
            if values.len() != slots.len() {
                return Err(Problem::bad(format!(
                    "cell array {:?} has {} values for {} cells",
                    name,
                    values.len(),
                    slots.len()
                )));
            }
            let label = |x: f64| -> Result<u32, Problem> {
                if x.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&x) {
                    Ok(x as u32)
                } else {
                    Err(Problem::bad(format!(
                        "cell array {name:?} holds {x}, not a label"
                    )))
                }
            };
            for (slot, &x) in slots.iter().zip(&values) {
                match (name, *slot) {
                    ("subdomain", Slot::Tet(t)) => m.subdomains[t] = SubdomainId(label(x)?),
                    ("patch", Slot::Triangles(s, e)) => {
                        m.boundary_patches[s..e].fill(PatchId(label(x)?))
                    }
                    ("curve", Slot::Edges(s, e)) => m.feature_curves[s..e].fill(CurveId(label(x)?)),
                    ("subdomain" | "patch" | "curve", _) => {}
                    (name, Slot::Tet(t)) => {
                        let at = match m.cell_fields.iter().position(|f| f.name == name) {
                            Some(i) => i,
                            None => {
                                m.cell_fields.push(CellField {
                                    name: name.into(),
                                    values: vec![f64::NAN; m.tets.len()],
                                });
                                m.cell_fields.len() - 1
                            }
                        };
                        m.cell_fields[at].values[t] = x;
                    }
                    _ => {}
                }
            }
        }
        if tets_before > 0
            && m.cell_fields
                .iter()
                .any(|f| f.values[..tets_before].iter().all(|v| v.is_nan()))
        {
            self.warnings
                .push("a cell field is missing from some pieces (filled with NaN)".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::plain;

    #[test]
    fn vtkio_debug_dumps_become_words() {
        let m = plain(
            "XML error: Deserialization error: InvalidInt(ParseIntError { kind: PosOverflow })",
        );
        assert_eq!(m, "XML error: Deserialization error: invalid int");
        assert_eq!(plain("plain words\nsecond line"), "plain words");
        // A multi-byte separator before the variant (found by fuzzing): cut on its boundary.
        assert_eq!(plain("bad «BigValue(3)"), "bad « big value");
    }
}
