//! Triangle meshes in: Wavefront OBJ, PLY (ASCII and binary, either byte order) and STL
//! (ASCII and binary), read into the core's [`TriMesh`].
//!
//! What is kept is what hole filling needs: vertex positions and faces. Polygons of more
//! than three vertices are split into fans (counted in [`MeshFile::polygons_split`]);
//! normals, texture coordinates, colours and other PLY properties are read past. STL
//! stores every triangle's corners separately: corners with the same coordinates (bit
//! for bit, `−0` as `0`) become one vertex.
//!
//! Hostile files are refused before anything large is allocated: the file's size against
//! the `model` cap, every declared or counted element (vertices plus faces) against the
//! `entities` cap, and a binary body against the bytes that are really there. Errors name
//! the file and the place — `file:line` for text, the element and its index for binary
//! data — and the cause.

use pdeshape_core::Vec3;
use pdeshape_core::limits::{Cap, Limits};
use pdeshape_core::trimesh::TriMesh;
use std::collections::HashMap;
use std::path::Path;

/// The mesh formats read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY.
    Ply,
    /// STL.
    Stl,
}

impl MeshFormat {
    /// The format of a file name's extension (`obj`, `ply`, `stl`, any case).
    pub fn from_path(p: &Path) -> Option<MeshFormat> {
        match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "stl" => Some(MeshFormat::Stl),
            _ => None,
        }
    }

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Stl => "STL",
        }
    }
}

/// A mesh read from a file.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFile {
    /// The file.
    pub file: String,
    /// Its format.
    pub format: MeshFormat,
    /// Whether the file was binary.
    pub binary: bool,
    /// The mesh.
    pub mesh: TriMesh,
    /// Polygons of more than three vertices split into triangles.
    pub polygons_split: usize,
}

/// A mesh file that cannot be read, with its place.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}{}: {message}", place.as_ref().map(|p| format!(":{p}")).unwrap_or_default())]
pub struct MeshError {
    /// The file.
    pub file: String,
    /// The place: a line number for text, `vertex 12` / `face 7` / `triangle 3` for
    /// binary data.
    pub place: Option<String>,
    /// What is wrong.
    pub message: String,
}

/// Reads the mesh at `path`, its format from the extension.
pub fn read_mesh(path: &Path, limits: &Limits) -> Result<MeshFile, MeshError> {
    use std::io::Read;
    let file = path.display().to_string();
    let fail = |message: String| MeshError { file: file.clone(), place: None, message };
    let format = MeshFormat::from_path(path).ok_or_else(|| fail("not a mesh file (.obj, .ply or .stl)".into()))?;
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read the mesh: {e}")))?;
    if !meta.is_file() {
        return Err(fail("cannot read the mesh: it is not a regular file".into()));
    }
    let too_big = |len: u64| {
        limits.check(Cap::Model, len.div_ceil(1 << 20), "the mesh file's size").map_err(|e| fail(e.to_string()))
    };
    too_big(meta.len())?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(limits.model as u64 * (1 << 20) + 1).read_to_end(&mut bytes))
        .map_err(|e| fail(format!("cannot read the mesh: {e}")))?;
    too_big(bytes.len() as u64)?;
    parse_mesh(&bytes, &file, format, limits)
}

/// Reads a mesh from its bytes (`file` names it in errors).
pub fn parse_mesh(bytes: &[u8], file: &str, format: MeshFormat, limits: &Limits) -> Result<MeshFile, MeshError> {
    let mut r = Reader { file, limits, split: 0 };
    let (mesh, binary) = match format {
        MeshFormat::Obj => (r.obj(bytes)?, false),
        MeshFormat::Ply => r.ply(bytes)?,
        MeshFormat::Stl => r.stl(bytes)?,
    };
    Ok(MeshFile { file: file.to_string(), format, binary, mesh, polygons_split: r.split })
}

struct Reader<'a> {
    file: &'a str,
    limits: &'a Limits,
    split: usize,
}

impl Reader<'_> {
    fn err(&self, place: impl Into<Option<String>>, message: impl Into<String>) -> MeshError {
        MeshError { file: self.file.to_string(), place: place.into(), message: message.into() }
    }

    fn cap(&self, count: u128, what: &str) -> Result<(), MeshError> {
        self.limits.check(Cap::Entities, count, what).map_err(|e| self.err(None, e.to_string()))
    }

    /// Splits a polygon into a fan of triangles.
    /// `place` is formatted only for an error: a face is read once a line and most lines
    /// are fine.
    fn polygon(
        &mut self,
        idx: &[u32],
        out: &mut Vec<[u32; 3]>,
        place: impl FnOnce() -> String,
    ) -> Result<(), MeshError> {
        if idx.len() < 3 {
            return Err(self.err(place(), format!("a face of {} vertices", idx.len())));
        }
        if idx.len() > 3 {
            self.split += 1;
        }
        for k in 1..idx.len() - 1 {
            out.push([idx[0], idx[k], idx[k + 1]]);
        }
        Ok(())
    }

    fn obj(&mut self, bytes: &[u8]) -> Result<TriMesh, MeshError> {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            let line = bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
            self.err(line.to_string(), "not UTF-8 text")
        })?;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        // One buffer for every face's indices: no allocation a line.
        let mut idx = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            let place = || (ln + 1).to_string();
            let mut it = line.split_ascii_whitespace();
            match it.next() {
                Some("v") => {
                    let mut p = [0.0; 3];
                    for (k, slot) in p.iter_mut().enumerate() {
                        let Some(c) = it.next() else {
                            return Err(self.err(place(), format!("a vertex needs 3 coordinates, found {k}")));
                        };
                        *slot = c.parse::<f64>().map_err(|_| self.err(place(), format!("`{c}` is not a number")))?;
                    }
                    positions.push(Vec3::from_array(p));
                    self.cap((positions.len() + triangles.len()) as u128, "the mesh's vertices and faces")?;
                }
                Some("f") => {
                    idx.clear();
                    for tok in it {
                        let first = tok.split('/').next().unwrap_or("");
                        let i: i64 =
                            first.parse().map_err(|_| self.err(place(), format!("`{tok}` is not a vertex index")))?;
                        let n = positions.len() as i64;
                        let k = if i > 0 { i - 1 } else { n + i };
                        if i == 0 || k < 0 || k >= n {
                            return Err(self.err(
                                place(),
                                format!("vertex index {i} is out of range ({n} vertices defined so far)"),
                            ));
                        }
                        idx.push(k as u32);
                    }
                    self.polygon(&idx, &mut triangles, place)?;
                    self.cap((positions.len() + triangles.len()) as u128, "the mesh's vertices and faces")?;
                }
                _ => {}
            }
        }
        Ok(TriMesh { positions, triangles })
    }

    fn stl(&mut self, bytes: &[u8]) -> Result<(TriMesh, bool), MeshError> {
        let binary_len = |n: u32| 84u64 + 50 * n as u64;
        if bytes.len() >= 84 {
            let n = u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes"));
            if binary_len(n) == bytes.len() as u64 {
                self.cap(4 * n as u128, "the STL's corners and triangles")?;
                let mut corners = Vec::with_capacity(3 * n as usize);
                for t in 0..n as usize {
                    let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
                    for c in 0..3 {
                        let f = |k: usize| {
                            let o = 12 + 12 * c + 4 * k;
                            f32::from_le_bytes(rec[o..o + 4].try_into().expect("4 bytes")) as f64
                        };
                        corners.push(Vec3::new(f(0), f(1), f(2)));
                    }
                }
                return Ok((self.weld(&corners, true)?, true));
            }
        }
        let text = std::str::from_utf8(bytes).map_err(|_| {
            self.err(
                None,
                format!(
                    "neither binary STL ({} bytes, where the header's triangle count asks for {}) nor ASCII STL (not text)",
                    bytes.len(),
                    if bytes.len() >= 84 {
                        binary_len(u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes"))).to_string()
                    } else {
                        "at least 84".into()
                    }
                ),
            )
        })?;
        if !text.trim_start().starts_with("solid") {
            return Err(self.err(None, "not an STL file (no `solid` header, and not binary STL's length)"));
        }
        let mut corners = Vec::new();
        let mut in_loop = 0;
        for (ln, line) in text.lines().enumerate() {
            let place = || (ln + 1).to_string();
            let mut it = line.split_whitespace();
            match it.next() {
                Some("outer") => in_loop = 0,
                Some("vertex") => {
                    let c: Vec<&str> = it.collect();
                    if c.len() != 3 {
                        return Err(self.err(place(), format!("a vertex needs 3 coordinates, found {}", c.len())));
                    }
                    let mut p = [0.0; 3];
                    for k in 0..3 {
                        p[k] = c[k]
                            .parse::<f64>()
                            .map_err(|_| self.err(place(), format!("`{}` is not a number", c[k])))?;
                    }
                    corners.push(Vec3::from_array(p));
                    in_loop += 1;
                    self.cap(corners.len() as u128 * 4 / 3, "the STL's corners and triangles")?;
                }
                Some("endloop") if in_loop != 3 => {
                    return Err(self.err(place(), format!("a facet of {in_loop} vertices (STL facets are triangles)")));
                }
                _ => {}
            }
        }
        if corners.len() % 3 != 0 {
            return Err(self.err(None, "the file ends inside a facet"));
        }
        Ok((self.weld(&corners, false)?, false))
    }

    /// One vertex per distinct corner position; the corners in threes are the triangles.
    fn weld(&self, corners: &[Vec3], binary: bool) -> Result<TriMesh, MeshError> {
        let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(corners.len() / 2);
        let mut positions = Vec::new();
        let mut triangles = Vec::with_capacity(corners.len() / 3);
        for (t, tri) in corners.chunks(3).enumerate() {
            let mut ids = [0u32; 3];
            for (c, p) in tri.iter().enumerate() {
                if !p.is_finite() {
                    let place = if binary { format!("triangle {t}") } else { format!("facet {t}") };
                    return Err(self.err(place, format!("corner {c} has a coordinate that is not finite")));
                }
                // −0 and 0 are one position
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                ids[c] = *index.entry(key).or_insert_with(|| {
                    positions.push(*p);
                    positions.len() as u32 - 1
                });
            }
            triangles.push(ids);
        }
        Ok(TriMesh { positions, triangles })
    }

    fn ply(&mut self, bytes: &[u8]) -> Result<(TriMesh, bool), MeshError> {
        // the header: text lines up to `end_header`
        let end = find(bytes, b"end_header").ok_or_else(|| self.err(None, "not a PLY file (no `end_header`)"))?;
        let mut body = end + b"end_header".len();
        if bytes.get(body) == Some(&b'\r') {
            body += 1;
        }
        if bytes.get(body) != Some(&b'\n') {
            return Err(self.err(None, "the header's `end_header` is not followed by a line break"));
        }
        body += 1;
        let header = std::str::from_utf8(&bytes[..end]).map_err(|_| self.err(None, "the header is not text"))?;
        let mut lines = header.lines().enumerate();
        if lines.next().map(|l| l.1.trim()) != Some("ply") {
            return Err(self.err("1".to_string(), "not a PLY file (the first line is not `ply`)"));
        }
        let mut encoding = None;
        let mut elements: Vec<Element> = Vec::new();
        for (ln, line) in lines {
            let place = || (ln + 1).to_string();
            let w: Vec<&str> = line.split_whitespace().collect();
            match w.first().copied() {
                Some("format") => {
                    encoding = Some(match w.get(1).copied() {
                        Some("ascii") => Encoding::Ascii,
                        Some("binary_little_endian") => Encoding::Little,
                        Some("binary_big_endian") => Encoding::Big,
                        other => return Err(self.err(place(), format!("unknown format {other:?}"))),
                    })
                }
                Some("element") => {
                    let (Some(name), Some(count)) = (w.get(1), w.get(2).and_then(|c| c.parse::<u64>().ok())) else {
                        return Err(self.err(place(), "an element needs a name and a count"));
                    };
                    self.cap(
                        elements.iter().map(|e| e.count as u128).sum::<u128>() + count as u128,
                        "the PLY's declared elements",
                    )?;
                    elements.push(Element { name: name.to_string(), count, props: Vec::new() });
                }
                Some("property") => {
                    let Some(el) = elements.last_mut() else {
                        return Err(self.err(place(), "a property before any element"));
                    };
                    let prop = if w.get(1) == Some(&"list") {
                        let (Some(c), Some(i), Some(name)) =
                            (w.get(2).and_then(|t| Scalar::of(t)), w.get(3).and_then(|t| Scalar::of(t)), w.get(4))
                        else {
                            return Err(
                                self.err(place(), "a list property needs a count type, an item type and a name")
                            );
                        };
                        Prop { name: name.to_string(), kind: Kind::List(c, i) }
                    } else {
                        let (Some(t), Some(name)) = (w.get(1).and_then(|t| Scalar::of(t)), w.get(2)) else {
                            return Err(self.err(place(), format!("unknown property `{line}`")));
                        };
                        Prop { name: name.to_string(), kind: Kind::Scalar(t) }
                    };
                    el.props.push(prop);
                }
                Some("comment") | Some("obj_info") | None => {}
                Some(other) => return Err(self.err(place(), format!("unknown header keyword `{other}`"))),
            }
        }
        let encoding = encoding.ok_or_else(|| self.err(None, "the header has no `format` line"))?;
        let vertex = elements.iter().position(|e| e.name == "vertex");
        let face = elements.iter().position(|e| e.name == "face");
        let (Some(vi), Some(fi)) = (vertex, face) else {
            return Err(self.err(None, "a PLY mesh needs `vertex` and `face` elements"));
        };
        let xyz: Vec<usize> = ["x", "y", "z"]
            .iter()
            .map(|n| elements[vi].props.iter().position(|p| p.name == *n && matches!(p.kind, Kind::Scalar(_))))
            .collect::<Option<_>>()
            .ok_or_else(|| self.err(None, "the vertex element needs scalar properties x, y and z"))?;
        let list = elements[fi]
            .props
            .iter()
            .position(|p| (p.name == "vertex_indices" || p.name == "vertex_index") && matches!(p.kind, Kind::List(..)))
            .ok_or_else(|| self.err(None, "the face element needs a list property `vertex_indices`"))?;
        let nv = elements[vi].count as usize;
        let mut positions = Vec::with_capacity(nv.min(bytes.len()));
        let mut triangles = Vec::new();
        let mut src = Source { bytes, at: body, encoding, line: header.lines().count() + 1 };
        for (e, el) in elements.iter().enumerate() {
            for i in 0..el.count {
                let place = || format!("{} {i}", el.name);
                src.start_record();
                let mut p = [0.0; 3];
                let mut idx: Vec<u32> = Vec::new();
                for (k, prop) in el.props.iter().enumerate() {
                    match prop.kind {
                        Kind::Scalar(t) => {
                            let v = src.scalar(t).ok_or_else(|| self.err(place(), src.problem(&prop.name)))?;
                            if e == vi
                                && let Some(c) = xyz.iter().position(|&x| x == k)
                            {
                                p[c] = v;
                            }
                        }
                        Kind::List(ct, it) => {
                            let n = src.scalar(ct).ok_or_else(|| self.err(place(), src.problem(&prop.name)))?;
                            if !((0.0..=1e6).contains(&n) && n.fract() == 0.0) {
                                return Err(self.err(place(), format!("list `{}` has length {n}", prop.name)));
                            }
                            for _ in 0..n as usize {
                                let v = src.scalar(it).ok_or_else(|| self.err(place(), src.problem(&prop.name)))?;
                                if e == fi && k == list {
                                    if !((0.0..nv as f64).contains(&v) && v.fract() == 0.0) {
                                        return Err(self.err(
                                            place(),
                                            format!("vertex index {v} is out of range (the file has {nv} vertices)"),
                                        ));
                                    }
                                    idx.push(v as u32);
                                }
                            }
                        }
                    }
                }
                src.end_record().map_err(|m| self.err(place(), m))?;
                if e == vi {
                    positions.push(Vec3::from_array(p));
                } else if e == fi {
                    self.polygon(&idx, &mut triangles, place)?;
                }
            }
        }
        Ok((TriMesh { positions, triangles }, encoding != Encoding::Ascii))
    }
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn of(t: &str) -> Option<Scalar> {
        Some(match t {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
struct Prop {
    name: String,
    kind: Kind,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Prop>,
}

/// The body of a PLY file: binary values, or ASCII records one a line.
struct Source<'a> {
    bytes: &'a [u8],
    at: usize,
    encoding: Encoding,
    line: usize,
}

impl Source<'_> {
    fn start_record(&mut self) {
        if self.encoding == Encoding::Ascii {
            // skip blank lines
            while self.at < self.bytes.len() && self.bytes[self.at].is_ascii_whitespace() {
                if self.bytes[self.at] == b'\n' {
                    self.line += 1;
                }
                self.at += 1;
            }
        }
    }

    fn end_record(&mut self) -> Result<(), String> {
        if self.encoding != Encoding::Ascii {
            return Ok(());
        }
        while self.at < self.bytes.len() && self.bytes[self.at] != b'\n' {
            if !self.bytes[self.at].is_ascii_whitespace() {
                return Err(format!("line {}: more values than the element's properties", self.line + 1));
            }
            self.at += 1;
        }
        Ok(())
    }

    fn problem(&self, prop: &str) -> String {
        // binary values fail only where the bytes run out
        if self.encoding != Encoding::Ascii || self.at >= self.bytes.len() {
            format!("the file ends before property `{prop}` (truncated)")
        } else {
            format!("line {}: property `{prop}` is not a number of its type", self.line + 1)
        }
    }

    fn scalar(&mut self, t: Scalar) -> Option<f64> {
        match self.encoding {
            Encoding::Ascii => {
                while self.at < self.bytes.len() && matches!(self.bytes[self.at], b' ' | b'\t' | b'\r') {
                    self.at += 1;
                }
                let start = self.at;
                while self.at < self.bytes.len() && !self.bytes[self.at].is_ascii_whitespace() {
                    self.at += 1;
                }
                let tok = std::str::from_utf8(&self.bytes[start..self.at]).ok()?;
                if tok.is_empty() {
                    return None;
                }
                match t {
                    Scalar::F32 | Scalar::F64 => tok.parse().ok(),
                    _ => tok.parse::<i64>().ok().map(|v| v as f64),
                }
            }
            Encoding::Little | Encoding::Big => {
                let n = t.size();
                let raw = self.bytes.get(self.at..self.at + n)?;
                self.at += n;
                let mut b = [0u8; 8];
                b[..n].copy_from_slice(raw);
                if self.encoding == Encoding::Big {
                    b[..n].reverse();
                }
                Some(match t {
                    Scalar::I8 => b[0] as i8 as f64,
                    Scalar::U8 => b[0] as f64,
                    Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(bytes: &[u8], f: MeshFormat) -> Result<MeshFile, MeshError> {
        parse_mesh(bytes, "m", f, &Limits::default())
    }

    #[test]
    fn obj_faces_and_errors() {
        let m =
            parse(b"# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 -1//1\n", MeshFormat::Obj)
                .unwrap();
        assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.polygons_split, 1);
        let e = parse(b"v 0 0 0\nv 1 0 0\nf 1 2 7\n", MeshFormat::Obj).unwrap_err();
        assert_eq!(e.to_string(), "m:3: vertex index 7 is out of range (2 vertices defined so far)");
        let e = parse(b"v 0 0 x\n", MeshFormat::Obj).unwrap_err();
        assert_eq!(e.to_string(), "m:1: `x` is not a number");
    }

    #[test]
    fn stl_both_kinds_weld() {
        let ascii =
            b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex -0 1 0\nendloop\nendfacet\nendsolid t\n";
        let m = parse(ascii, MeshFormat::Stl).unwrap();
        assert_eq!(m.mesh.positions.len(), 4);
        assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        let mut bin = vec![0u8; 80];
        bin.extend(1u32.to_le_bytes());
        for v in [0f32, 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0.] {
            bin.extend(v.to_le_bytes());
        }
        bin.extend([0, 0]);
        let m = parse(&bin, MeshFormat::Stl).unwrap();
        assert!(m.binary);
        assert_eq!(m.mesh.triangles, vec![[0, 1, 2]]);
        bin.pop();
        let e = parse(&bin, MeshFormat::Stl).unwrap_err();
        assert!(
            e.message.contains("neither binary STL (133 bytes, where the header's triangle count asks for 134)"),
            "{e}"
        );
    }

    #[test]
    fn ply_binary_and_ascii() {
        let head = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
property uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        let mut b = head.as_bytes().to_vec();
        for v in 0..3 {
            for c in [v as f32, 2.0 * v as f32, 0.5] {
                b.extend(c.to_be_bytes());
            }
            b.push(7);
        }
        b.push(3);
        for i in [0i32, 1, 2] {
            b.extend(i.to_be_bytes());
        }
        let m = parse(&b, MeshFormat::Ply).unwrap();
        assert_eq!(m.mesh.positions[2], Vec3::new(2.0, 4.0, 0.5));
        assert_eq!(m.mesh.triangles, vec![[0, 1, 2]]);
        b.truncate(b.len() - 2);
        let e = parse(&b, MeshFormat::Ply).unwrap_err();
        assert_eq!(e.to_string(), "m:face 0: the file ends before property `vertex_indices` (truncated)");
        let a = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n\
element face 1\nproperty list uchar uint vertex_index\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n";
        let e = parse(a, MeshFormat::Ply).unwrap_err();
        assert_eq!(e.to_string(), "m:face 0: vertex index 5 is out of range (the file has 3 vertices)");
        // a declared count beyond the cap is refused before anything is allocated
        let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n";
        let e = parse(huge, MeshFormat::Ply).unwrap_err();
        assert!(e.message.contains("`entities` cap"), "{e}");
    }

    /// Every single-byte change and every truncation of small valid files in each format
    /// is read or refused, never a panic; what is read passes the topology check or is
    /// refused by it.
    #[test]
    fn corrupted_files_never_panic() {
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n".to_vec();
        let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
            .to_vec();
        let mut plyb =
            b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
property double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
                .to_vec();
        for v in [0f64, 0., 0., 1., 0., 0., 0., 1., 0.] {
            plyb.extend(v.to_le_bytes());
        }
        plyb.push(3);
        for i in [0u32, 1, 2] {
            plyb.extend(i.to_le_bytes());
        }
        let mut stl = vec![0u8; 80];
        stl.extend(1u32.to_le_bytes());
        for v in [0f32, 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0.] {
            stl.extend(v.to_le_bytes());
        }
        stl.extend([0, 0]);
        let mut read = 0;
        for (bytes, f) in
            [(obj, MeshFormat::Obj), (ply, MeshFormat::Ply), (plyb, MeshFormat::Ply), (stl, MeshFormat::Stl)]
        {
            for k in 0..bytes.len() {
                for b in [0u8, b'\n', b'9', b'-', 0xff, bytes[k] ^ 1] {
                    let mut c = bytes.clone();
                    c[k] = b;
                    if let Ok(m) = parse(&c, f) {
                        read += 1;
                        let _ = pdeshape_core::trimesh::boundary(&m.mesh);
                    }
                }
                let _ = parse(&bytes[..k], f);
            }
        }
        // many of the changes are harmless (a digit in a coordinate, a comment's byte)
        assert!(read > 100, "{read}");
    }
}
