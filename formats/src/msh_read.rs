//! Gmsh `.msh` reader, formats 2.2 and 4.1, ASCII and binary (little-endian), hand-written as
//! the writer is: the tetrahedra (second-order ones by their corners) and the one-component
//! `$NodeData` fields, which is what a background mesh of a sizing field needs. Other elements
//! and sections are skipped.

use crate::error::Problem;
use delamesh_core::mesh::{CellField, TetMesh};
use glam::DVec3;
use std::collections::HashMap;

const GMSH_TETRA: u32 = 4;
const GMSH_TETRA10: u32 = 11;

/// Nodes per element of the Gmsh element types up to 19 (the first-order and the common
/// second-order ones): binary files give no per-element length, so unknown types are refused.
const NODES_PER_TYPE: [usize; 20] = [
    0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13,
];

/// The tetrahedra of a `.msh` file and its scalar node fields (one value per node, in the order
/// of the mesh's positions; NaN at nodes a field does not list).
pub(crate) fn read(bytes: &[u8]) -> Result<(TetMesh, Vec<CellField>), Problem> {
    let mut sections = Sections { bytes, at: 0 };
    let Some((name, body)) = sections.next_section()? else {
        return Err(Problem::bad("empty file (expected $MeshFormat)"));
    };
    if name != "MeshFormat" {
        return Err(Problem::at_byte(
            0,
            format!("expected $MeshFormat, found ${name} (not a Gmsh .msh file)"),
        ));
    }
    let format = mesh_format(body)?;
    let mut nodes: Option<Nodes> = None;
    let mut tets: Vec<[u64; 4]> = Vec::new();
    let mut fields: Vec<NodeData> = Vec::new();
    while let Some((name, body)) = sections.next_section()? {
        match name {
            "Nodes" => nodes = Some(read_nodes(body, format)?),
            "Elements" => read_elements(body, format, &mut tets)?,
            "NodeData" => {
                if let Some((name, values)) = read_node_data(body, format)?
                    && !fields.iter().any(|(n, _)| *n == name)
                {
                    fields.push((name, values));
                }
            }
            _ => {}
        }
    }
    let nodes = nodes.ok_or_else(|| Problem::bad("no $Nodes section"))?;
    let index =
        |tag: u64| {
            nodes.index.get(&tag).copied().ok_or_else(|| {
                Problem::bad(format!("an element names node {tag}, which $Nodes lacks"))
            })
        };
    let mut mesh = TetMesh {
        tets: Vec::with_capacity(tets.len()),
        ..TetMesh::default()
    };
    for tet in tets {
        let [a, b, c, d] = [
            index(tet[0])?,
            index(tet[1])?,
            index(tet[2])?,
            index(tet[3])?,
        ];
        let p = |v: u32| nodes.positions[v as usize];
        let positive = (p(b) - p(a)).dot((p(c) - p(a)).cross(p(d) - p(a))) >= 0.0;
        mesh.tets
            .push(if positive { [a, b, c, d] } else { [b, a, c, d] });
    }
    mesh.subdomains = vec![Default::default(); mesh.tets.len()];
    let fields = fields
        .into_iter()
        .map(|(name, listed)| {
            let mut values = vec![f64::NAN; nodes.positions.len()];
            for (tag, v) in listed {
                if let Some(&n) = nodes.index.get(&tag) {
                    values[n as usize] = v;
                }
            }
            CellField { name, values }
        })
        .collect();
    mesh.positions = nodes.positions;
    Ok((mesh, fields))
}

/// The version and encoding of the file.
#[derive(Clone, Copy)]
struct MeshFormat {
    v4: bool,
    binary: bool,
}

fn mesh_format(body: Section) -> Result<MeshFormat, Problem> {
    let mut c = Cursor::of(body);
    let line = c.line()?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let (version, binary, size) = match words[..] {
        [v, b, s] => (v, b, s),
        _ => {
            return Err(Problem::bad(format!(
                "$MeshFormat: expected `version binary size`, got {line:?}"
            )));
        }
    };
    let v4 = match version {
        "2.2" | "2" | "2.0" | "2.1" => false,
        "4.1" => true,
        _ => {
            return Err(Problem::Unsupported(format!(
                "Gmsh format version {version} (2.2 and 4.1 are read)"
            )));
        }
    };
    let binary = binary == "1";
    if binary {
        if size != "8" {
            return Err(Problem::Unsupported(format!(
                "binary .msh with {size}-byte sizes (8 is read)"
            )));
        }
        if c.i32()? != 1 {
            return Err(Problem::Unsupported(
                "big-endian binary .msh (little-endian is read)".into(),
            ));
        }
    }
    Ok(MeshFormat { v4, binary })
}

/// The file's `$Name ... $EndName` sections, in order.
struct Sections<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Sections<'a> {
    /// The next section's name and body (without the header line), with the body's offset kept
    /// for messages through [`Cursor`].
    fn next_section(&mut self) -> Result<Option<(&'a str, Section<'a>)>, Problem> {
        let rest = &self.bytes[self.at..];
        let Some(skip) = rest.iter().position(|b| !b.is_ascii_whitespace()) else {
            return Ok(None);
        };
        let start = self.at + skip;
        if self.bytes[start] != b'$' {
            return Err(Problem::at_byte(start as u64, "expected a $Section header"));
        }
        let line_end = self.bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(self.bytes.len(), |e| start + e);
        let name = std::str::from_utf8(&self.bytes[start + 1..line_end])
            .map_err(|_| Problem::at_byte(start as u64, "a section name that is not text"))?
            .trim();
        let body_start = (line_end + 1).min(self.bytes.len());
        let end_tag = format!("$End{name}");
        let Some(len) = find(&self.bytes[body_start..], end_tag.as_bytes()) else {
            return Err(Problem::at_byte(
                start as u64,
                format!("${name} has no {end_tag}"),
            ));
        };
        self.at = body_start + len + end_tag.len();
        Ok(Some((
            name,
            Section {
                bytes: &self.bytes[body_start..body_start + len],
                offset: body_start,
            },
        )))
    }
}

/// A section's body and where it starts in the file.
#[derive(Clone, Copy)]
struct Section<'a> {
    bytes: &'a [u8],
    offset: usize,
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// Reads a section's body: text lines or little-endian binary values.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    /// The body's offset in the file, for messages.
    offset: usize,
}

impl<'a> Cursor<'a> {
    /// The entity-block count that opens an MSH 4 `$Nodes` or `$Elements` section; the header's
    /// other three numbers (a total and a tag range) are read past, not needed.
    fn block_count(&mut self, binary: bool, what: &str) -> Result<usize, Problem> {
        Ok(if binary {
            let h = [self.u64()?, self.u64()?, self.u64()?, self.u64()?];
            h[0] as usize
        } else {
            self.numbers::<usize>(4, what)?[0]
        })
    }

    fn of(section: Section<'a>) -> Self {
        Cursor {
            bytes: section.bytes,
            at: 0,
            offset: section.offset,
        }
    }

    fn problem(&self, message: impl Into<String>) -> Problem {
        Problem::at_byte((self.offset + self.at) as u64, message)
    }

    /// The next line, without its end.
    fn line(&mut self) -> Result<&'a str, Problem> {
        if self.at >= self.bytes.len() {
            return Err(self.problem("the section ends early"));
        }
        let rest = &self.bytes[self.at..];
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let line = std::str::from_utf8(&rest[..len])
            .map_err(|_| self.problem("expected a line of text"))?;
        self.at += (len + 1).min(rest.len());
        Ok(line.trim())
    }

    /// The next non-empty line's numbers.
    fn numbers<T: std::str::FromStr>(&mut self, n: usize, what: &str) -> Result<Vec<T>, Problem> {
        let mut line = self.line()?;
        while line.is_empty() {
            line = self.line()?;
        }
        let values: Vec<T> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| self.problem(format!("{what}: not numbers: {line:?}")))?;
        if values.len() < n {
            return Err(self.problem(format!("{what}: expected {n} numbers, got {line:?}")));
        }
        Ok(values)
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], Problem> {
        let chunk = self
            .bytes
            .get(self.at..self.at + N)
            .ok_or_else(|| self.problem("the section ends early"))?;
        self.at += N;
        let mut out = [0; N];
        out.copy_from_slice(chunk);
        Ok(out)
    }

    fn i32(&mut self) -> Result<i32, Problem> {
        self.take().map(i32::from_le_bytes)
    }

    fn u64(&mut self) -> Result<u64, Problem> {
        self.take().map(u64::from_le_bytes)
    }

    fn f64(&mut self) -> Result<f64, Problem> {
        self.take().map(f64::from_le_bytes)
    }

    /// A binary count, tag or type (`int` in 2.2, `size_t` where 4.1 says so).
    fn count(&mut self, wide: bool) -> Result<usize, Problem> {
        let v = if wide {
            self.u64()?
        } else {
            u64::try_from(self.i32()?).map_err(|_| self.problem("a negative count or tag"))?
        };
        usize::try_from(v).map_err(|_| self.problem("a count too large"))
    }

    /// Room for `n` items of at least `size` bytes each, or an error: a lying header cannot
    /// make us allocate more than the section holds.
    fn capacity(&self, n: usize, size: usize) -> Result<usize, Problem> {
        if n.saturating_mul(size) > self.bytes.len() - self.at.min(self.bytes.len()) {
            return Err(self.problem(format!("announces {n} items, more than the section holds")));
        }
        Ok(n)
    }
}

/// Node positions in file order and the index of each tag.
struct Nodes {
    positions: Vec<DVec3>,
    index: HashMap<u64, u32>,
}

impl Nodes {
    fn push(&mut self, tag: u64, p: DVec3, c: &Cursor) -> Result<(), Problem> {
        let n = u32::try_from(self.positions.len()).map_err(|_| c.problem("too many nodes"))?;
        if !p.is_finite() {
            return Err(c.problem(format!("node {tag} has a coordinate that is not finite")));
        }
        if self.index.insert(tag, n).is_some() {
            return Err(c.problem(format!("node {tag} is listed twice")));
        }
        self.positions.push(p);
        Ok(())
    }
}

fn read_nodes(body: Section, format: MeshFormat) -> Result<Nodes, Problem> {
    let mut c = Cursor::of(body);
    let mut nodes = Nodes {
        positions: Vec::new(),
        index: HashMap::new(),
    };
    if !format.v4 {
        let n: usize = c.numbers::<usize>(1, "the node count")?[0];
        let n = c.capacity(n, if format.binary { 28 } else { 8 })?;
        nodes.positions.reserve(n);
        for _ in 0..n {
            let (tag, p) = if format.binary {
                let tag = c.count(false)? as u64;
                (tag, DVec3::new(c.f64()?, c.f64()?, c.f64()?))
            } else {
                let v = c.numbers::<f64>(4, "a node")?;
                (v[0] as u64, DVec3::new(v[1], v[2], v[3]))
            };
            nodes.push(tag, p, &c)?;
        }
        return Ok(nodes);
    }
    let blocks = c.block_count(format.binary, "the $Nodes header")?;
    for _ in 0..blocks {
        let (dim, parametric, n) = if format.binary {
            let dim = c.i32()?;
            let _entity = c.i32()?;
            let parametric = c.i32()?;
            (dim, parametric, c.count(true)?)
        } else {
            let h = c.numbers::<i64>(4, "a node block header")?;
            (h[0] as i32, h[2] as i32, usize::try_from(h[3]).unwrap_or(0))
        };
        let extra = if parametric == 1 {
            dim.clamp(0, 3) as usize
        } else {
            0
        };
        let n = c.capacity(n, if format.binary { 32 } else { 8 })?;
        let mut tags = Vec::with_capacity(n);
        for _ in 0..n {
            tags.push(if format.binary {
                c.u64()?
            } else {
                c.numbers::<u64>(1, "a node tag")?[0]
            });
        }
        for tag in tags {
            let p = if format.binary {
                let p = DVec3::new(c.f64()?, c.f64()?, c.f64()?);
                for _ in 0..extra {
                    c.f64()?;
                }
                p
            } else {
                let v = c.numbers::<f64>(3 + extra, "node coordinates")?;
                DVec3::new(v[0], v[1], v[2])
            };
            nodes.push(tag, p, &c)?;
        }
    }
    Ok(nodes)
}

/// The corner nodes of a (first- or second-order) tetrahedron's node list.
fn corners(element_type: u32, nodes: &[u64]) -> Option<[u64; 4]> {
    matches!(element_type, GMSH_TETRA | GMSH_TETRA10)
        .then(|| [nodes[0], nodes[1], nodes[2], nodes[3]])
}

fn nodes_per(element_type: u32, c: &Cursor) -> Result<usize, Problem> {
    NODES_PER_TYPE
        .get(element_type as usize)
        .copied()
        .filter(|&n| n > 0)
        .ok_or_else(|| c.problem(format!("unknown element type {element_type}")))
}

fn read_elements(
    body: Section,
    format: MeshFormat,
    tets: &mut Vec<[u64; 4]>,
) -> Result<(), Problem> {
    let mut c = Cursor::of(body);
    if !format.v4 {
        let n: usize = c.numbers::<usize>(1, "the element count")?[0];
        if !format.binary {
            for _ in 0..n {
                let v = c.numbers::<u64>(3, "an element")?;
                let skip = 3 + v[2] as usize;
                let element_type = u32::try_from(v[1]).unwrap_or(0);
                if let Some(nodes) = v.get(skip..)
                    && nodes.len() >= 4
                    && let Some(t) = corners(element_type, nodes)
                {
                    tets.push(t);
                }
            }
            return Ok(());
        }
        let mut read = 0;
        while read < n {
            let element_type = c.count(false)? as u32;
            let count = c.count(false)?;
            let tags = c.count(false)?;
            let per = nodes_per(element_type, &c)?;
            let count = c.capacity(count, 4 * (1 + tags + per))?;
            let mut list = vec![0u64; per];
            for _ in 0..count {
                c.i32()?;
                for _ in 0..tags {
                    c.i32()?;
                }
                for v in &mut list {
                    *v = c.count(false)? as u64;
                }
                if let Some(t) = corners(element_type, &list) {
                    tets.push(t);
                }
            }
            read += count.max(1);
        }
        return Ok(());
    }
    let blocks = c.block_count(format.binary, "the $Elements header")?;
    for _ in 0..blocks {
        let (element_type, n) = if format.binary {
            let _dim = c.i32()?;
            let _entity = c.i32()?;
            let element_type = c.count(false)? as u32;
            (element_type, c.count(true)?)
        } else {
            let h = c.numbers::<usize>(4, "an element block header")?;
            (u32::try_from(h[2]).unwrap_or(0), h[3])
        };
        let per = nodes_per(element_type, &c)?;
        let n = c.capacity(n, if format.binary { 8 } else { 2 } * (1 + per))?;
        let mut list = vec![0u64; per];
        for _ in 0..n {
            if format.binary {
                c.u64()?;
                for v in &mut list {
                    *v = c.u64()?;
                }
            } else {
                let v = c.numbers::<u64>(1 + per, "an element")?;
                list.copy_from_slice(&v[1..=per]);
            }
            if let Some(t) = corners(element_type, &list) {
                tets.push(t);
            }
        }
    }
    Ok(())
}

/// A node field as listed: its name and (node tag, value) pairs.
type NodeData = (String, Vec<(u64, f64)>);

/// A `$NodeData` section: its name and (node tag, value) pairs, `None` for a field of more than
/// one component.
fn read_node_data(body: Section, format: MeshFormat) -> Result<Option<NodeData>, Problem> {
    let mut c = Cursor::of(body);
    let strings: usize = c.numbers::<usize>(1, "the string tag count")?[0];
    let mut name = String::new();
    for k in 0..strings {
        let s = c.line()?;
        if k == 0 {
            name = s.trim_matches('"').to_string();
        }
    }
    let reals: usize = c.numbers::<usize>(1, "the real tag count")?[0];
    for _ in 0..reals {
        c.line()?;
    }
    let ints: usize = c.numbers::<usize>(1, "the integer tag count")?[0];
    let mut int_tags = Vec::with_capacity(ints.min(8));
    for _ in 0..ints {
        int_tags.push(c.numbers::<i64>(1, "an integer tag")?[0]);
    }
    let (Some(&components), Some(&count)) = (int_tags.get(1), int_tags.get(2)) else {
        return Err(c.problem("$NodeData needs the step, component and value counts"));
    };
    if components != 1 {
        return Ok(None);
    }
    let count = usize::try_from(count).map_err(|_| c.problem("a negative value count"))?;
    let count = c.capacity(count, if format.binary { 12 } else { 4 })?;
    let mut values = Vec::with_capacity(count);
    for _ in 0..count {
        values.push(if format.binary {
            (c.count(false)? as u64, c.f64()?)
        } else {
            let v = c.numbers::<f64>(2, "a node value")?;
            (v[0] as u64, v[1])
        });
    }
    Ok(Some((name, values)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const NODES: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
    ];
    /// Node tags as a file may give them: not 1..n.
    const TAGS: [u64; 5] = [10, 20, 30, 40, 50];
    /// The second tet is negatively oriented in the file.
    const TETS: [[u64; 4]; 2] = [[10, 20, 30, 40], [20, 30, 40, 50]];

    fn node_data(binary: bool) -> Vec<u8> {
        let mut s = b"$NodeData\n1\n\"h\"\n1\n0.0\n3\n0\n1\n5\n".to_vec();
        for (k, t) in TAGS.iter().enumerate() {
            let v = 0.1 * (k + 1) as f64;
            if binary {
                s.extend((*t as i32).to_le_bytes());
                s.extend(v.to_le_bytes());
            } else {
                s.extend(format!("{t} {v}\n").bytes());
            }
        }
        s.extend(b"\n$EndNodeData\n");
        // A vector field is skipped.
        s.extend(b"$NodeData\n1\n\"v\"\n0\n3\n0\n3\n0\n$EndNodeData\n");
        s
    }

    fn v22(binary: bool) -> Vec<u8> {
        let mut s = format!("$MeshFormat\n2.2 {} 8\n", u8::from(binary)).into_bytes();
        if binary {
            s.extend(1i32.to_le_bytes());
            s.push(b'\n');
        }
        s.extend(b"$EndMeshFormat\n$Nodes\n5\n");
        for (t, p) in TAGS.iter().zip(NODES) {
            if binary {
                s.extend((*t as i32).to_le_bytes());
                p.iter().for_each(|x| s.extend(x.to_le_bytes()));
            } else {
                s.extend(format!("{t} {} {} {}\n", p[0], p[1], p[2]).bytes());
            }
        }
        s.extend(b"\n$EndNodes\n$Elements\n3\n");
        if binary {
            // A triangle block (skipped), then the tets, each with two tags.
            for v in [2i32, 1, 2, 1, 7, 7, 10, 20, 30, 4, 2, 2] {
                s.extend(v.to_le_bytes());
            }
            for (e, tet) in TETS.iter().enumerate() {
                for v in [e as u64 + 2, 1, 1].iter().chain(tet) {
                    s.extend((*v as i32).to_le_bytes());
                }
            }
        } else {
            s.extend(b"1 2 2 7 7 10 20 30\n");
            for (e, t) in TETS.iter().enumerate() {
                s.extend(
                    format!("{} 4 2 1 1 {} {} {} {}\n", e + 2, t[0], t[1], t[2], t[3]).bytes(),
                );
            }
        }
        s.extend(b"\n$EndElements\n");
        s.extend(node_data(binary));
        s
    }

    fn v41(binary: bool) -> Vec<u8> {
        let mut s = format!("$MeshFormat\n4.1 {} 8\n", u8::from(binary)).into_bytes();
        let sizes = |s: &mut Vec<u8>, v: &[u64]| {
            if binary {
                v.iter().for_each(|x| s.extend(x.to_le_bytes()));
            } else {
                let words: Vec<String> = v.iter().map(u64::to_string).collect();
                s.extend(format!("{}\n", words.join(" ")).bytes());
            }
        };
        // The header of the one block of volume entity 1: `kind` (parametric 0 for nodes, the
        // element type for elements), then `n` members.
        let block = |s: &mut Vec<u8>, kind: i32, n: u64| {
            if binary {
                [3i32, 1, kind]
                    .iter()
                    .for_each(|x| s.extend(x.to_le_bytes()));
                s.extend(n.to_le_bytes());
            } else {
                s.extend(format!("3 1 {kind} {n}\n").bytes());
            }
        };
        if binary {
            s.extend(1i32.to_le_bytes());
            s.push(b'\n');
        }
        s.extend(b"$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n$Nodes\n");
        sizes(&mut s, &[1, 5, 10, 50]);
        block(&mut s, 0, 5);
        for t in TAGS {
            sizes(&mut s, &[t]);
        }
        for p in NODES {
            if binary {
                p.iter().for_each(|x| s.extend(x.to_le_bytes()));
            } else {
                s.extend(format!("{} {} {}\n", p[0], p[1], p[2]).bytes());
            }
        }
        s.extend(b"\n$EndNodes\n$Elements\n");
        sizes(&mut s, &[1, 2, 1, 2]);
        block(&mut s, 4, 2);
        for (e, t) in TETS.iter().enumerate() {
            sizes(&mut s, &[e as u64 + 1, t[0], t[1], t[2], t[3]]);
        }
        s.extend(b"\n$EndElements\n");
        s.extend(node_data(binary));
        s
    }

    #[test]
    fn every_version_and_encoding_gives_the_same_tets_and_field() {
        for (label, bytes) in [
            ("2.2 ASCII", v22(false)),
            ("2.2 binary", v22(true)),
            ("4.1 ASCII", v41(false)),
            ("4.1 binary", v41(true)),
        ] {
            let (mesh, fields) = read(&bytes).unwrap_or_else(|e| panic!("{label}: {e}"));
            assert_eq!(mesh.positions.len(), 5, "{label}");
            assert_eq!(mesh.positions[4], DVec3::ONE, "{label}");
            assert_eq!(mesh.tets.len(), 2, "{label}");
            for t in &mesh.tets {
                let p = t.map(|v| mesh.positions[v as usize]);
                let det = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
                assert!(det > 0.0, "{label}: tet {t:?} is not positively oriented");
            }
            assert_eq!(fields.len(), 1, "{label}: the vector field is skipped");
            assert_eq!(fields[0].name, "h", "{label}");
            let expected: Vec<f64> = (1..=5).map(|k| 0.1 * k as f64).collect();
            assert_eq!(fields[0].values, expected, "{label}");
        }
    }

    #[test]
    fn broken_files_are_refused_with_the_reason() {
        let text = String::from_utf8(v41(false)).expect("ASCII");
        let cases = [
            (text.replace("4.1 0 8", "3.0 0 8"), "version 3.0"),
            (text.replace("$EndNodes", "$EndNode"), "has no $EndNodes"),
            (text.replace("3 1 4 2\n1 10", "3 1 4 2\n1 99"), "node 99"),
            (text.replace("$MeshFormat", "$Mesh"), "expected $MeshFormat"),
        ];
        for (bad, expected) in cases {
            let e = read(bad.as_bytes()).expect_err(expected).to_string();
            assert!(e.contains(expected), "{e:?} lacks {expected:?}");
        }
        let mut truncated = v22(true);
        truncated.truncate(120);
        assert!(read(&truncated).is_err());
    }
}
