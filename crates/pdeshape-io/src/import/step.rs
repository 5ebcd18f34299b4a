//! STEP (ISO 10303-21) models in: the B-rep of every shell — faces, loops, edges,
//! vertices — with each face's surface and each edge's curve exact
//! (`pdeshape_core::brep`).
//!
//! The file is parsed by `step-io`'s Part 21 parser (entities with their `#id`, type,
//! attributes and place in the file); this module reads the geometry and topology
//! entities of AP203/AP214/AP242 from it: `CLOSED_SHELL`/`OPEN_SHELL` → `ADVANCED_FACE`
//! (or `FACE_SURFACE`) → `FACE_OUTER_BOUND`/`FACE_BOUND` → `EDGE_LOOP` → `ORIENTED_EDGE`
//! → `EDGE_CURVE` → `VERTEX_POINT`; surfaces `PLANE`, `CYLINDRICAL_SURFACE`,
//! `CONICAL_SURFACE`, `SPHERICAL_SURFACE`, `TOROIDAL_SURFACE`,
//! `B_SPLINE_SURFACE_WITH_KNOTS` (rational ones as the complex instance with
//! `RATIONAL_B_SPLINE_SURFACE`); curves `LINE`, `CIRCLE`, `ELLIPSE`,
//! `B_SPLINE_CURVE_WITH_KNOTS` (and rational), through `SURFACE_CURVE`, `SEAM_CURVE`
//! and `TRIMMED_CURVE`. A face or edge on geometry outside that list is kept in the
//! topology without geometry and listed in [`StepModel::unsupported`]; it is written back
//! as it was and only the holes that touch it cannot be filled.
//!
//! Lengths stay in the file's unit ([`StepModel::unit`]); plane angles (a cone's
//! semi-angle) are converted to radians by the file's angle unit.
//!
//! Errors name the file, the line, the entity (`#id` and type) and the cause.

use pdeshape_core::Vec3;
use pdeshape_core::brep::{Brep, BrepEdge, BrepFace, BrepShell, EdgeCurve, FaceSurface};
use pdeshape_core::data::analytic::{AnalyticCurve, AnalyticKind, AnalyticSurface, Frame};
use pdeshape_core::data::{Field, NurbsCurve, NurbsSurface};
use pdeshape_core::limits::{Cap, Limits};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;
use step_io::parser::{Attribute, Graph, RawEntity, RawEntityPart};

mod assembly;
pub use assembly::{MAX_INSTANCES, ShellInstance};

/// A read STEP model.
pub struct StepModel {
    /// The file's name as given.
    pub file: String,
    /// The file's bytes (written back unchanged but for the shells that get new faces).
    pub source: Vec<u8>,
    /// The B-rep of all its shells, each in its part's coordinates.
    pub brep: Brep,
    /// Where the assembly places each shell, and how many times (every shell at least
    /// once; see [`ShellInstance`]).
    pub instances: Vec<ShellInstance>,
    /// The length unit: its name and its size in metres.
    pub unit: (String, f64),
    /// Faces and edges whose geometry is not read: `(#id, type)` of the face or edge
    /// and the entity that is not supported.
    pub unsupported: Vec<(u64, String)>,
    /// Each entity's place in the file: byte range (from its `#` to after its `;`) and line.
    pub spans: BTreeMap<u64, (u64, u64, u32)>,
    /// Entity types, by id.
    pub types: BTreeMap<u64, String>,
    /// Entities that reference each entity (ids), for rewriting shells and their users.
    pub users: HashMap<u64, Vec<u64>>,
    /// The largest `#id` in the file.
    pub max_id: u64,
    /// Faces taken out of the model ([`StepModel::without_faces`]), by `#id`: left out of
    /// their shells' face lists when the model is written back.
    pub removed: Vec<u64>,
}

impl StepModel {
    /// Whether faces of the shell `#shell` were taken out ([`StepModel::without_faces`]).
    pub fn shell_lost_faces(&self, shell: u64) -> bool {
        self.removed.iter().any(|id| self.users.get(id).is_some_and(|u| u.contains(&shell)))
    }

    /// The model without the faces `ids` (`#id`s of faces of its shells, as `holes` names
    /// them): their loops become holes — a face to be replaced by a fill. An id that is not
    /// a face of the model, or a face of more than one loop (holes through it, each of
    /// which would get a cap of its own over the others), is an error naming it.
    pub fn without_faces(mut self, ids: &[u64]) -> Result<StepModel, StepError> {
        let mut at = Vec::with_capacity(ids.len());
        for &id in ids {
            let Some(i) = self.brep.faces.iter().position(|f| f.id == id) else {
                let what = self.types.get(&id).map_or("no entity of the file".to_string(), |t| format!("a {t}"));
                return Err(StepError {
                    file: self.file.clone(),
                    line: self.spans.get(&id).map(|s| s.2),
                    message: format!("#{id} is {what}, not a face of the model's shells"),
                });
            };
            let loops = self.brep.faces[i].loops.len();
            if loops > 1 {
                return Err(StepError {
                    file: self.file.clone(),
                    line: self.spans.get(&id).map(|s| s.2),
                    message: format!(
                        "#{id} ADVANCED_FACE has {loops} loops (an outer bound and holes through it): a fill replaces a face of one loop (each loop would get its own cap, the caps overlapping)"
                    ),
                });
            }
            if !at.contains(&i) {
                at.push(i);
                self.removed.push(id);
            }
        }
        self.brep = self.brep.without_faces(&at);
        Ok(self)
    }
}

/// A STEP file that cannot be read, with its place.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct StepError {
    /// The file.
    pub file: String,
    /// The line, where known.
    pub line: Option<u32>,
    /// What is wrong, naming the entity (`#id TYPE`).
    pub message: String,
}

/// [`read_step`] and then [`StepModel::without_faces`] (`replace` empty: the model as read).
pub fn read_step_without(path: &Path, replace: &[u64], limits: &Limits) -> Result<StepModel, StepError> {
    let m = read_step(path, limits)?;
    if replace.is_empty() { Ok(m) } else { m.without_faces(replace) }
}

/// Reads the STEP file at `path` (at most the `model` cap of bytes and the `entities`
/// cap of entities).
pub fn read_step(path: &Path, limits: &Limits) -> Result<StepModel, StepError> {
    use std::io::Read;
    let file = path.display().to_string();
    let fail = |message: String| StepError { file: file.clone(), line: None, message };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read the model: {e}")))?;
    if !meta.is_file() {
        return Err(fail("cannot read the model: it is not a regular file".into()));
    }
    let cap = limits.model as u64 * (1 << 20);
    let too_big = |len: u64| {
        limits.check(Cap::Model, len.div_ceil(1 << 20), "the model file's size").map_err(|e| fail(e.to_string()))
    };
    too_big(meta.len())?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(cap + 1).read_to_end(&mut bytes))
        .map_err(|e| fail(format!("cannot read the model: {e}")))?;
    too_big(bytes.len() as u64)?;
    parse_step(bytes, &file, limits)
}

/// Reads a STEP model from its bytes (`file` names it in errors).
pub fn parse_step(source: Vec<u8>, file: &str, limits: &Limits) -> Result<StepModel, StepError> {
    let graph = step_io::parser::parse(source.as_slice()).map_err(|e| StepError {
        file: file.to_string(),
        line: None,
        message: format!("not a STEP (ISO 10303-21) file: {e}"),
    })?;
    limits.check(Cap::Entities, graph.entities.len() as u64, "the model's entity count").map_err(|e| StepError {
        file: file.to_string(),
        line: None,
        message: e.to_string(),
    })?;
    let mut r = Reader {
        g: &graph,
        file,
        brep: Brep::default(),
        vertex_of: HashMap::new(),
        edge_of: HashMap::new(),
        unsupported: Vec::new(),
        angle: 1.0,
    };
    let unit = r.units()?;
    let shells: Vec<(u64, bool)> = graph
        .entities
        .values()
        .filter_map(|e| match e {
            RawEntity::Simple { id, name, .. } if name == "CLOSED_SHELL" => Some((*id, true)),
            RawEntity::Simple { id, name, .. } if name == "OPEN_SHELL" => Some((*id, false)),
            _ => None,
        })
        .collect();
    for (id, closed) in shells {
        r.shell(id, closed)?;
    }
    let instances = r.instances()?;
    let mut spans = BTreeMap::new();
    let mut types = BTreeMap::new();
    let mut users: HashMap<u64, Vec<u64>> = HashMap::new();
    for (id, e) in &graph.entities {
        let s = e.span();
        spans.insert(*id, (s.start, entity_end(&source, s.start as usize) as u64, s.line));
        let (name, attrs): (String, Vec<&Attribute>) = match e {
            RawEntity::Simple { name, attributes, .. } => (name.clone(), attributes.iter().collect()),
            RawEntity::Complex { parts, .. } => (
                parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join("+"),
                parts.iter().flat_map(|p| &p.attributes).collect(),
            ),
        };
        types.insert(*id, name);
        let mut refs = Vec::new();
        for a in attrs {
            collect_refs(a, &mut refs);
        }
        for r in refs {
            users.entry(r).or_default().push(*id);
        }
    }
    // a manifold model: each edge bounds at most two faces (a seam edge is one face's,
    // run both ways)
    let mut uses: Vec<Vec<u64>> = vec![Vec::new(); r.brep.edges.len()];
    for f in &r.brep.faces {
        for &(e, _) in f.loops.iter().flatten() {
            uses[e].push(f.id);
        }
    }
    if let Some((e, faces)) = uses.iter().enumerate().find(|(_, f)| f.len() > 2) {
        let id = r.brep.edges[e].id;
        let list: Vec<String> = faces.iter().map(|f| format!("#{f}")).collect();
        return Err(StepError {
            file: file.to_string(),
            line: spans.get(&id).map(|s| s.2),
            message: format!(
                "#{id} EDGE_CURVE: a non-manifold edge, used {} times by the faces {} (an edge bounds at most two faces)",
                faces.len(),
                list.join(", ")
            ),
        });
    }
    let max_id = graph.entities.keys().next_back().copied().unwrap_or(0);
    Ok(StepModel {
        file: file.to_string(),
        source,
        brep: r.brep,
        instances,
        unit,
        unsupported: r.unsupported,
        spans,
        types,
        users,
        max_id,
        removed: Vec::new(),
    })
}

/// The end (after its `;`) of the entity instance starting at byte `start`: the first `;`
/// outside strings and comments.
fn entity_end(src: &[u8], start: usize) -> usize {
    let mut i = start;
    while i < src.len() {
        match src[i] {
            b';' => return i + 1,
            // a string; `''` inside is an apostrophe and reads as two strings back to back
            b'\'' => {
                i += 1;
                while i < src.len() && src[i] != b'\'' {
                    i += 1;
                }
            }
            b'/' if src.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < src.len() && !(src[i] == b'*' && src[i + 1] == b'/') {
                    i += 1;
                }
                i += 1;
            }
            _ => {}
        }
        i += 1;
    }
    src.len()
}

fn collect_refs(a: &Attribute, out: &mut Vec<u64>) {
    match a {
        Attribute::EntityRef(r) => out.push(*r),
        Attribute::List(l) => l.iter().for_each(|x| collect_refs(x, out)),
        Attribute::Typed { value, .. } => collect_refs(value, out),
        _ => {}
    }
}

struct Reader<'g> {
    g: &'g Graph,
    file: &'g str,
    brep: Brep,
    vertex_of: HashMap<u64, usize>,
    edge_of: HashMap<u64, usize>,
    unsupported: Vec<(u64, String)>,
    /// Radians per unit of plane angle.
    angle: f64,
}

/// The entity's type name (parts joined by `+` for a complex instance).
fn type_name(e: &RawEntity) -> String {
    match e {
        RawEntity::Simple { name, .. } => name.clone(),
        RawEntity::Complex { parts, .. } => parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join("+"),
    }
}

impl<'g> Reader<'g> {
    fn err_at(&self, id: u64, message: impl std::fmt::Display) -> StepError {
        let (line, what) = match self.g.get(id) {
            Some(e) => (Some(e.span().line), format!("#{id} {}", type_name(e))),
            None => (None, format!("#{id}")),
        };
        StepError { file: self.file.to_string(), line, message: format!("{what}: {message}") }
    }

    fn entity(&self, id: u64, from: u64) -> Result<&'g RawEntity, StepError> {
        self.g.get(id).ok_or_else(|| self.err_at(from, format!("refers to #{id}, which the file does not define")))
    }

    /// A simple entity's type and attributes.
    fn simple(&self, id: u64, from: u64) -> Result<(&'g str, &'g [Attribute]), StepError> {
        match self.entity(id, from)? {
            RawEntity::Simple { name, attributes, .. } => Ok((name, attributes)),
            RawEntity::Complex { .. } => Err(self.err_at(id, "a complex instance where a simple entity is expected")),
        }
    }

    fn attr(&self, id: u64, attrs: &'g [Attribute], k: usize) -> Result<&'g Attribute, StepError> {
        attrs.get(k).ok_or_else(|| self.err_at(id, format!("attribute {} is missing", k + 1)))
    }

    fn reference(&self, id: u64, a: &Attribute, what: &str) -> Result<u64, StepError> {
        match a {
            Attribute::EntityRef(r) => Ok(*r),
            _ => Err(self.err_at(id, format!("{what} is not a reference"))),
        }
    }

    fn real(&self, id: u64, a: &Attribute, what: &str) -> Result<f64, StepError> {
        let x = match a {
            Attribute::Real(x) => *x,
            Attribute::Integer(i) => *i as f64,
            Attribute::Typed { value, .. } => return self.real(id, value, what),
            _ => return Err(self.err_at(id, format!("{what} is not a number"))),
        };
        if !x.is_finite() {
            return Err(self.err_at(id, format!("{what} is not finite")));
        }
        Ok(x)
    }

    fn boolean(&self, id: u64, a: &Attribute, what: &str) -> Result<bool, StepError> {
        match a {
            Attribute::Enum(e) if e == "T" => Ok(true),
            Attribute::Enum(e) if e == "F" => Ok(false),
            _ => Err(self.err_at(id, format!("{what} is not .T. or .F."))),
        }
    }

    fn list(&self, id: u64, a: &'g Attribute, what: &str) -> Result<&'g [Attribute], StepError> {
        match a {
            Attribute::List(l) => Ok(l),
            _ => Err(self.err_at(id, format!("{what} is not a list"))),
        }
    }

    fn string(&self, a: &Attribute) -> String {
        match a {
            Attribute::String(s) => s.clone(),
            _ => String::new(),
        }
    }

    /// Length and plane-angle units of the geometric contexts: one length unit for the
    /// whole file (several are refused), the angle unit's size in radians kept.
    fn units(&mut self) -> Result<(String, f64), StepError> {
        let mut lengths: Vec<(String, f64)> = Vec::new();
        let mut angles: Vec<f64> = Vec::new();
        for e in self.g.entities.values() {
            let RawEntity::Complex { parts, .. } = e else { continue };
            let Some(ctx) = parts.iter().find(|p| p.name == "GLOBAL_UNIT_ASSIGNED_CONTEXT") else { continue };
            let Some(Attribute::List(units)) = ctx.attributes.first() else { continue };
            for u in units {
                let Attribute::EntityRef(uid) = u else { continue };
                let Some(RawEntity::Complex { parts, .. }) = self.g.get(*uid) else { continue };
                let has = |n: &str| parts.iter().any(|p| p.name == n);
                if has("LENGTH_UNIT") {
                    lengths.push(self.unit_size(*uid, parts, "METRE", 0)?);
                } else if has("PLANE_ANGLE_UNIT") {
                    angles.push(self.unit_size(*uid, parts, "RADIAN", 0)?.1);
                }
            }
        }
        if let Some(a) = angles.first() {
            self.angle = *a;
        }
        if let Some(w) = lengths.iter().find(|l| (l.1 - lengths[0].1).abs() > 1e-12 * lengths[0].1) {
            return Err(StepError {
                file: self.file.to_string(),
                line: None,
                message: format!(
                    "the model uses two length units ({} and {}); models in one unit are read",
                    lengths[0].0, w.0
                ),
            });
        }
        Ok(lengths.into_iter().next().unwrap_or_else(|| ("millimetre".into(), 1e-3)))
    }

    /// An SI unit with its prefix, or a conversion-based unit (inch, degree): name and
    /// size in the SI base unit `base`. `depth` counts the conversions followed (a cycle
    /// of them is refused).
    fn unit_size(
        &self,
        id: u64,
        parts: &[RawEntityPart],
        base: &str,
        depth: usize,
    ) -> Result<(String, f64), StepError> {
        if depth > 8 {
            return Err(self.err_at(id, "more than 8 unit conversions in a row (a cycle?)"));
        }
        if let Some(si) = parts.iter().find(|p| p.name == "SI_UNIT") {
            let prefix = match si.attributes.first() {
                Some(Attribute::Enum(p)) => p.clone(),
                _ => String::new(),
            };
            let f = match prefix.as_str() {
                "" => 1.0,
                "KILO" => 1e3,
                "HECTO" => 1e2,
                "DECA" => 1e1,
                "DECI" => 1e-1,
                "CENTI" => 1e-2,
                "MILLI" => 1e-3,
                "MICRO" => 1e-6,
                "NANO" => 1e-9,
                p => return Err(self.err_at(id, format!("the unit prefix .{p}. is not supported"))),
            };
            let name = format!("{}{}", prefix.to_lowercase(), base.to_lowercase());
            return Ok((name, f));
        }
        if let Some(cb) = parts.iter().find(|p| p.name == "CONVERSION_BASED_UNIT") {
            let name = self.string(cb.attributes.first().unwrap_or(&Attribute::Unset)).to_lowercase();
            let m = self.reference(id, self.attr(id, &cb.attributes, 1)?, "the conversion factor")?;
            let (_, attrs) = match self.entity(m, id)? {
                RawEntity::Simple { name, attributes, .. } => (name.as_str(), attributes.as_slice()),
                RawEntity::Complex { parts, .. } => {
                    let p = parts
                        .iter()
                        .find(|p| p.name.ends_with("MEASURE_WITH_UNIT"))
                        .ok_or_else(|| self.err_at(m, "not a measure with unit"))?;
                    (p.name.as_str(), p.attributes.as_slice())
                }
            };
            let value = self.real(m, self.attr(m, attrs, 0)?, "the measure")?;
            let of = self.reference(m, self.attr(m, attrs, 1)?, "the unit")?;
            let inner = match self.entity(of, m)? {
                RawEntity::Complex { parts, .. } => self.unit_size(of, parts, base, depth + 1)?.1,
                _ => return Err(self.err_at(of, "a unit is expected")),
            };
            // finite: `real` refuses others
            if value <= 0.0 {
                return Err(self.err_at(m, format!("the conversion factor {value} is not positive")));
            }
            return Ok((name, value * inner));
        }
        Err(self.err_at(id, "a unit that is neither an SI unit nor conversion-based"))
    }

    fn shell(&mut self, id: u64, closed: bool) -> Result<(), StepError> {
        let (_, attrs) = self.simple(id, id)?;
        let faces = self.list(id, self.attr(id, attrs, 1)?, "the face list")?;
        let shell = self.brep.shells.len();
        self.brep.shells.push(BrepShell { id, closed, faces: Vec::new() });
        for f in faces {
            let fid = self.reference(id, f, "a face")?;
            let fi = self.face(fid, id, shell)?;
            self.brep.shells[shell].faces.push(fi);
        }
        Ok(())
    }

    fn face(&mut self, id: u64, from: u64, shell: usize) -> Result<usize, StepError> {
        let (kind, attrs) = self.simple(id, from)?;
        if kind != "ADVANCED_FACE" && kind != "FACE_SURFACE" {
            return Err(self.err_at(id, "a shell's face must be an ADVANCED_FACE or FACE_SURFACE"));
        }
        let name = self.string(self.attr(id, attrs, 0)?);
        let bounds = self.list(id, self.attr(id, attrs, 1)?, "the bounds")?;
        let sid = self.reference(id, self.attr(id, attrs, 2)?, "the surface")?;
        let same_sense = self.boolean(id, self.attr(id, attrs, 3)?, "same_sense")?;
        let surface = match self.surface(sid, id)? {
            Ok(s) => Some(s),
            Err(what) => {
                self.unsupported.push((id, what));
                None
            }
        };
        let mut loops = Vec::new();
        for b in bounds {
            let bid = self.reference(id, b, "a bound")?;
            let (bk, battrs) = self.simple(bid, id)?;
            if bk != "FACE_OUTER_BOUND" && bk != "FACE_BOUND" {
                return Err(self.err_at(bid, "a face's bound must be a FACE_BOUND or FACE_OUTER_BOUND"));
            }
            let lid = self.reference(bid, self.attr(bid, battrs, 1)?, "the loop")?;
            let orientation = self.boolean(bid, self.attr(bid, battrs, 2)?, "the orientation")?;
            let (lk, lattrs) = self.simple(lid, bid)?;
            match lk {
                "EDGE_LOOP" => {}
                // a single point (a sphere's pole): no edge
                "VERTEX_LOOP" => continue,
                _ => return Err(self.err_at(lid, "a loop must be an EDGE_LOOP or VERTEX_LOOP")),
            }
            let oes = self.list(lid, self.attr(lid, lattrs, 1)?, "the edge list")?;
            let mut lp = Vec::with_capacity(oes.len());
            for oe in oes {
                let oid = self.reference(lid, oe, "an edge")?;
                let (ok, oattrs) = self.simple(oid, lid)?;
                if ok != "ORIENTED_EDGE" {
                    return Err(self.err_at(oid, "an edge loop's member must be an ORIENTED_EDGE"));
                }
                let eid = self.reference(oid, self.attr(oid, oattrs, 3)?, "the edge element")?;
                let o = self.boolean(oid, self.attr(oid, oattrs, 4)?, "the orientation")?;
                let e = self.edge(eid, oid)?;
                lp.push((e, o == orientation));
            }
            if !orientation {
                lp.reverse();
            }
            self.check_loop(lid, &lp)?;
            loops.push(lp);
        }
        self.brep.faces.push(BrepFace::new(id, name, surface, same_sense, loops, shell));
        Ok(self.brep.faces.len() - 1)
    }

    /// Each edge of a loop ends where the next starts.
    fn check_loop(&self, lid: u64, lp: &[(usize, bool)]) -> Result<(), StepError> {
        let ends = |(e, f): (usize, bool)| {
            let v = self.brep.edges[e].vertices;
            if f { (v[0], v[1]) } else { (v[1], v[0]) }
        };
        for k in 0..lp.len() {
            let (a, b) = (ends(lp[k]), ends(lp[(k + 1) % lp.len()]));
            if a.1 != b.0 {
                return Err(self.err_at(
                    lid,
                    format!(
                        "the loop does not close: edge #{} ends at vertex #{}, the next edge #{} starts at vertex #{}",
                        self.brep.edges[lp[k].0].id,
                        self.brep.vertices[a.1].0,
                        self.brep.edges[lp[(k + 1) % lp.len()].0].id,
                        self.brep.vertices[b.0].0
                    ),
                ));
            }
        }
        Ok(())
    }

    fn vertex(&mut self, id: u64, from: u64) -> Result<usize, StepError> {
        if let Some(&v) = self.vertex_of.get(&id) {
            return Ok(v);
        }
        let (k, attrs) = self.simple(id, from)?;
        if k != "VERTEX_POINT" {
            return Err(self.err_at(id, "an edge's vertex must be a VERTEX_POINT"));
        }
        let pid = self.reference(id, self.attr(id, attrs, 1)?, "the point")?;
        let p = self.point(pid, id)?;
        self.brep.vertices.push((id, p));
        self.vertex_of.insert(id, self.brep.vertices.len() - 1);
        Ok(self.brep.vertices.len() - 1)
    }

    fn edge(&mut self, id: u64, from: u64) -> Result<usize, StepError> {
        if let Some(&e) = self.edge_of.get(&id) {
            return Ok(e);
        }
        let (k, attrs) = self.simple(id, from)?;
        if k != "EDGE_CURVE" {
            return Err(self.err_at(id, "an oriented edge's element must be an EDGE_CURVE"));
        }
        let v0 = self.reference(id, self.attr(id, attrs, 1)?, "the start vertex")?;
        let v1 = self.reference(id, self.attr(id, attrs, 2)?, "the end vertex")?;
        let cid = self.reference(id, self.attr(id, attrs, 3)?, "the curve")?;
        let same_sense = self.boolean(id, self.attr(id, attrs, 4)?, "same_sense")?;
        let vertices = [self.vertex(v0, id)?, self.vertex(v1, id)?];
        let (p0, p1) = (self.brep.vertices[vertices[0]].1, self.brep.vertices[vertices[1]].1);
        let curve = match self.curve(cid, id, 0)? {
            Ok(c) => Some(c),
            Err(what) => {
                self.unsupported.push((id, what));
                None
            }
        };
        let closed = v0 == v1;
        let tau = std::f64::consts::TAU;
        let range = match &curve {
            // an edge without geometry is written back as it was; holes along it are not
            // filled
            None => (0.0, 1.0),
            Some(EdgeCurve::Analytic(a)) => {
                let t0 = a.invert(p0);
                let sign = if same_sense { 1.0 } else { -1.0 };
                let t1 = if closed {
                    t0 + sign * tau
                } else if a.is_closed() {
                    // the arc from t0 in the edge's direction, less than a turn
                    let d = (a.invert(p1) - t0).rem_euclid(tau);
                    if same_sense { t0 + d } else { t0 - (tau - d) }
                } else {
                    a.invert(p1)
                };
                (t0, t1)
            }
            Some(EdgeCurve::Nurbs(n)) => {
                let (a, b) = n.domain();
                if closed {
                    if same_sense { (a, b) } else { (b, a) }
                } else {
                    let [t0, t1] = invert_curve(n.as_ref(), [p0, p1], (a, b));
                    (t0, t1)
                }
            }
        };
        if !closed && (p0 - p1).norm() == 0.0 {
            return Err(self.err_at(id, "an open edge whose two vertices are at one point (zero length)"));
        }
        self.brep.edges.push(BrepEdge { id, curve, vertices, range });
        self.edge_of.insert(id, self.brep.edges.len() - 1);
        Ok(self.brep.edges.len() - 1)
    }

    fn point(&self, id: u64, from: u64) -> Result<Vec3, StepError> {
        let (k, attrs) = self.simple(id, from)?;
        if k != "CARTESIAN_POINT" {
            return Err(self.err_at(id, "a CARTESIAN_POINT is expected"));
        }
        self.triple(id, self.attr(id, attrs, 1)?, "the coordinates")
    }

    fn triple(&self, id: u64, a: &Attribute, what: &str) -> Result<Vec3, StepError> {
        let l = self.list(id, a, what)?;
        if l.len() != 3 {
            return Err(self.err_at(id, format!("{what} have {} components; 3 are read", l.len())));
        }
        Ok(Vec3::new(self.real(id, &l[0], what)?, self.real(id, &l[1], what)?, self.real(id, &l[2], what)?))
    }

    fn direction(&self, id: u64, from: u64) -> Result<Vec3, StepError> {
        let (k, attrs) = self.simple(id, from)?;
        if k != "DIRECTION" {
            return Err(self.err_at(id, "a DIRECTION is expected"));
        }
        self.triple(id, self.attr(id, attrs, 1)?, "the direction ratios")
    }

    fn placement(&self, id: u64, from: u64) -> Result<Frame, StepError> {
        let (k, attrs) = self.simple(id, from)?;
        if k != "AXIS2_PLACEMENT_3D" {
            return Err(self.err_at(id, "an AXIS2_PLACEMENT_3D is expected"));
        }
        let o = self.point(self.reference(id, self.attr(id, attrs, 1)?, "the location")?, id)?;
        let dir = |k: usize| -> Result<Option<Vec3>, StepError> {
            match attrs.get(k) {
                Some(Attribute::EntityRef(d)) => Ok(Some(self.direction(*d, id)?)),
                _ => Ok(None),
            }
        };
        let axis = dir(2)?.unwrap_or(Vec3::new(0.0, 0.0, 1.0));
        Frame::new(o, axis, dir(3)?).ok_or_else(|| self.err_at(id, "the axis is zero or the directions are parallel"))
    }

    /// The surface, or (`Err`) the name of what is not supported.
    fn surface(&self, id: u64, from: u64) -> Result<Result<FaceSurface, String>, StepError> {
        let e = self.entity(id, from)?;
        let (kind, attrs) = match e {
            RawEntity::Simple { name, attributes, .. } => (name.as_str(), attributes.as_slice()),
            RawEntity::Complex { parts, .. } => {
                if parts.iter().any(|p| p.name == "B_SPLINE_SURFACE_WITH_KNOTS") {
                    return self.bspline_surface(id, parts.as_slice()).map(Ok);
                }
                return Ok(Err(format!("#{id} {}", type_name(e))));
            }
        };
        let positive = |k: usize, what: &str| -> Result<f64, StepError> {
            let r = self.real(id, self.attr(id, attrs, k)?, what)?;
            if r > 0.0 { Ok(r) } else { Err(self.err_at(id, format!("{what} {r} is not positive"))) }
        };
        let frame = || self.placement(self.reference(id, self.attr(id, attrs, 1)?, "the position")?, id);
        let kind = match kind {
            "PLANE" => AnalyticKind::Plane,
            "CYLINDRICAL_SURFACE" => AnalyticKind::Cylinder { r: positive(2, "the radius")? },
            "CONICAL_SURFACE" => {
                let r = self.real(id, self.attr(id, attrs, 2)?, "the radius")?;
                let alpha = self.real(id, self.attr(id, attrs, 3)?, "the semi-angle")? * self.angle;
                if r < 0.0 || !(alpha > 0.0 && alpha < std::f64::consts::FRAC_PI_2) {
                    return Err(self.err_at(id, format!("radius {r} or semi-angle {alpha} rad out of range")));
                }
                AnalyticKind::Cone { r, alpha }
            }
            "SPHERICAL_SURFACE" => AnalyticKind::Sphere { r: positive(2, "the radius")? },
            "TOROIDAL_SURFACE" => {
                AnalyticKind::Torus { major: positive(2, "the major radius")?, minor: positive(3, "the minor radius")? }
            }
            "B_SPLINE_SURFACE_WITH_KNOTS" => {
                let part = RawEntityPart { name: kind.to_string(), attributes: attrs.to_vec() };
                return self.bspline_surface(id, std::slice::from_ref(&part)).map(Ok);
            }
            other => return Ok(Err(format!("#{id} {other}"))),
        };
        Ok(Ok(FaceSurface::Analytic(AnalyticSurface { kind, frame: frame()? })))
    }

    fn knots(&self, id: u64, mults: &Attribute, knots: &Attribute) -> Result<Vec<f64>, StepError> {
        let m = self.list(id, mults, "the knot multiplicities")?;
        let k = self.list(id, knots, "the knots")?;
        if m.len() != k.len() {
            return Err(self.err_at(id, format!("{} multiplicities for {} knots", m.len(), k.len())));
        }
        // the expanded vector is as long as the control points plus the degree plus one;
        // a file cannot hold more points than entities
        let total: i64 = m.iter().map(|x| if let Attribute::Integer(n) = x { (*n).clamp(0, 64) } else { 0 }).sum();
        if total as usize > self.g.entities.len() + 26 {
            return Err(self.err_at(id, format!("the multiplicities add up to {total}, more than the file has points")));
        }
        let mut out = Vec::new();
        for (mi, ki) in m.iter().zip(k) {
            let Attribute::Integer(n) = mi else { return Err(self.err_at(id, "a multiplicity is not an integer")) };
            if !(1..=64).contains(n) {
                return Err(self.err_at(id, format!("the multiplicity {n} is out of range")));
            }
            let x = self.real(id, ki, "a knot")?;
            out.extend(std::iter::repeat_n(x, *n as usize));
        }
        Ok(out)
    }

    fn degree(&self, id: u64, a: &Attribute) -> Result<usize, StepError> {
        match a {
            Attribute::Integer(d) if (1..=25).contains(d) => Ok(*d as usize),
            _ => Err(self.err_at(id, "the degree is not an integer in 1 … 25")),
        }
    }

    /// `B_SPLINE_SURFACE_WITH_KNOTS` alone, or the complex instance with
    /// `B_SPLINE_SURFACE`, `B_SPLINE_SURFACE_WITH_KNOTS` and `RATIONAL_B_SPLINE_SURFACE`.
    fn bspline_surface(&self, id: u64, parts: &[RawEntityPart]) -> Result<FaceSurface, StepError> {
        let find = |n: &str| parts.iter().find(|p| p.name == n).map(|p| p.attributes.as_slice());
        let wk = find("B_SPLINE_SURFACE_WITH_KNOTS").ok_or_else(|| self.err_at(id, "no knots"))?;
        // simple instance: name, u_degree, v_degree, points, form, u_closed, v_closed,
        // self_intersect, u_mults, v_mults, u_knots, v_knots, spec; complex: the first
        // seven in B_SPLINE_SURFACE (without the name) and the rest in ..._WITH_KNOTS
        let (head, tail): (Vec<&Attribute>, &[Attribute]) = match find("B_SPLINE_SURFACE") {
            Some(b) => (b.iter().collect(), wk),
            None => {
                if wk.len() < 13 {
                    return Err(self.err_at(id, format!("{} attributes; 13 are expected", wk.len())));
                }
                (wk[1..8].iter().collect(), &wk[8..])
            }
        };
        if head.len() < 3 || tail.len() < 4 {
            return Err(self.err_at(id, "too few attributes"));
        }
        let (pu, pv) = (self.degree(id, head[0])?, self.degree(id, head[1])?);
        let rows = self.list(id, head[2], "the control points")?;
        let mut pts = Vec::new();
        let nu = rows.len();
        let mut nv = None;
        for r in rows {
            let row = self.list(id, r, "a row of control points")?;
            if *nv.get_or_insert(row.len()) != row.len() {
                return Err(self.err_at(id, "the rows of control points differ in length"));
            }
            for p in row {
                pts.push(self.point(self.reference(id, p, "a control point")?, id)?);
            }
        }
        let nv = nv.unwrap_or(0);
        let ku = self.knots(id, &tail[0], &tail[2])?;
        let kv = self.knots(id, &tail[1], &tail[3])?;
        let weights = match find("RATIONAL_B_SPLINE_SURFACE") {
            Some(w) => {
                let rows = self.list(id, self.attr(id, w, 0)?, "the weights")?;
                let mut out = Vec::new();
                for r in rows {
                    for x in self.list(id, r, "a row of weights")? {
                        out.push(self.real(id, x, "a weight")?);
                    }
                }
                Some(out)
            }
            None => None,
        };
        NurbsSurface::new((pu, pv), ku, kv, (nu, nv), &pts, weights.as_deref())
            .map(|s| FaceSurface::Nurbs(Arc::new(s)))
            .map_err(|e| self.err_at(id, e))
    }

    /// The curve, or (`Err`) the name of what is not supported.
    fn curve(&self, id: u64, from: u64, depth: usize) -> Result<Result<EdgeCurve, String>, StepError> {
        if depth > 8 {
            return Err(self.err_at(id, "more than 8 nested curves on surfaces or trimmed curves (a cycle?)"));
        }
        let e = self.entity(id, from)?;
        let (kind, attrs) = match e {
            RawEntity::Simple { name, attributes, .. } => (name.as_str(), attributes.as_slice()),
            RawEntity::Complex { parts, .. } => {
                if parts.iter().any(|p| p.name == "B_SPLINE_CURVE_WITH_KNOTS") {
                    return self.bspline_curve(id, parts.as_slice()).map(Ok);
                }
                return Ok(Err(format!("#{id} {}", type_name(e))));
            }
        };
        match kind {
            // the 3D curve of a curve on surfaces (the pcurves are not needed: faces'
            // parameters come from the feet of the 3D curve)
            "SURFACE_CURVE" | "SEAM_CURVE" | "TRIMMED_CURVE" => {
                let c = self.reference(id, self.attr(id, attrs, 1)?, "the basis curve")?;
                self.curve(c, id, depth + 1)
            }
            "LINE" => {
                let o = self.point(self.reference(id, self.attr(id, attrs, 1)?, "the point")?, id)?;
                let vid = self.reference(id, self.attr(id, attrs, 2)?, "the vector")?;
                let (vk, vattrs) = self.simple(vid, id)?;
                if vk != "VECTOR" {
                    return Err(self.err_at(vid, "a VECTOR is expected"));
                }
                let d = self.direction(self.reference(vid, self.attr(vid, vattrs, 1)?, "the direction")?, vid)?;
                let m = self.real(vid, self.attr(vid, vattrs, 2)?, "the magnitude")?;
                if m <= 0.0 {
                    return Err(self.err_at(vid, format!("the magnitude {m} is not positive")));
                }
                let d = d.normalized().ok_or_else(|| self.err_at(vid, "the direction is zero"))? * m;
                Ok(Ok(EdgeCurve::Analytic(AnalyticCurve::Line { o, d })))
            }
            "CIRCLE" | "ELLIPSE" => {
                let frame = self.placement(self.reference(id, self.attr(id, attrs, 1)?, "the position")?, id)?;
                let a = self.real(id, self.attr(id, attrs, 2)?, "the radius")?;
                let b = if kind == "ELLIPSE" {
                    self.real(id, self.attr(id, attrs, 3)?, "the second semi-axis")?
                } else {
                    a
                };
                if !(a > 0.0 && b > 0.0) {
                    return Err(self.err_at(id, "a radius is not positive"));
                }
                Ok(Ok(EdgeCurve::Analytic(AnalyticCurve::Ellipse { frame, a, b })))
            }
            "B_SPLINE_CURVE_WITH_KNOTS" => {
                let part = RawEntityPart { name: kind.to_string(), attributes: attrs.to_vec() };
                self.bspline_curve(id, std::slice::from_ref(&part)).map(Ok)
            }
            other => Ok(Err(format!("#{id} {other}"))),
        }
    }

    fn bspline_curve(&self, id: u64, parts: &[RawEntityPart]) -> Result<EdgeCurve, StepError> {
        let find = |n: &str| parts.iter().find(|p| p.name == n).map(|p| p.attributes.as_slice());
        let wk = find("B_SPLINE_CURVE_WITH_KNOTS").ok_or_else(|| self.err_at(id, "no knots"))?;
        // simple: name, degree, points, form, closed, self_intersect, mults, knots, spec
        let (head, tail): (Vec<&Attribute>, &[Attribute]) = match find("B_SPLINE_CURVE") {
            Some(b) => (b.iter().collect(), wk),
            None => {
                if wk.len() < 9 {
                    return Err(self.err_at(id, format!("{} attributes; 9 are expected", wk.len())));
                }
                (wk[1..6].iter().collect(), &wk[6..])
            }
        };
        if head.len() < 2 || tail.len() < 2 {
            return Err(self.err_at(id, "too few attributes"));
        }
        let p = self.degree(id, head[0])?;
        let mut pts = Vec::new();
        for q in self.list(id, head[1], "the control points")? {
            pts.push(self.point(self.reference(id, q, "a control point")?, id)?);
        }
        let knots = self.knots(id, &tail[0], &tail[1])?;
        let weights = match find("RATIONAL_B_SPLINE_CURVE") {
            Some(w) => Some(
                self.list(id, self.attr(id, w, 0)?, "the weights")?
                    .iter()
                    .map(|x| self.real(id, x, "a weight"))
                    .collect::<Result<Vec<_>, _>>()?,
            ),
            None => None,
        };
        NurbsCurve::new(p, knots, &pts, weights.as_deref())
            .map(|c| EdgeCurve::Nurbs(Arc::new(c)))
            .map_err(|e| self.err_at(id, e))
    }
}

/// The parameters of the points of `c` nearest `ps`: each the best of 257 samples (the
/// first of equals; the samples evaluated once for all points), then Newton's method.
fn invert_curve<const N: usize>(c: &NurbsCurve, ps: [Vec3; N], (a, b): (f64, f64)) -> [f64; N] {
    let n = 256;
    let ts: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    let values = c.values(&ts);
    ps.map(|p| {
        let mut best = (f64::INFINITY, a);
        for (x, t) in values.iter().zip(&ts) {
            let d = (*x - p).norm();
            // NaN never wins, as with `total_cmp`'s order of finite distances
            if d < best.0 {
                best = (d, *t);
            }
        }
        let mut t = best.1;
        for _ in 0..30 {
            let mut d = [Vec3::ZERO; 3];
            c.derivatives_in(&[t], 0, &mut d);
            let r = d[0] - p;
            let g = r.dot(d[1]);
            let h = d[1].dot(d[1]) + r.dot(d[2]);
            if h.is_nan() || h <= 0.0 {
                break;
            }
            let step = g / h;
            t = (t - step).clamp(a, b);
            if step.abs() <= 1e-15 * (1.0 + t.abs()) {
                break;
            }
        }
        t
    })
}
