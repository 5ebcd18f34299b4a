//! STEP (ISO 10303-21) writer for B-spline surface models, application protocol 214
//! (`AUTOMOTIVE_DESIGN`), the schema every CAD reader takes.
//!
//! The file holds one product (`PRODUCT` → `PRODUCT_DEFINITION` → `PRODUCT_DEFINITION_SHAPE`
//! → `SHAPE_DEFINITION_REPRESENTATION`; without the whole chain some readers import
//! nothing) whose shape holds one shell per set of faces joined by shared edges
//! (boundary curves with the same knots and control points within the uncertainty — faces
//! fitted with common knots along a common edge — are one `EDGE_CURVE`; faces are flipped
//! where needed so that the two faces of a shared edge run it in opposite directions). A
//! shell in which every edge joins two faces is a `CLOSED_SHELL` bounding a
//! `MANIFOLD_SOLID_BREP`, oriented outward (the faces of a solid say which side is out);
//! the others are `OPEN_SHELL`s of a `SHELL_BASED_SURFACE_MODEL`. The representation is an
//! `ADVANCED_BREP_SHAPE_REPRESENTATION` (solids only), a
//! `MANIFOLD_SURFACE_SHAPE_REPRESENTATION` (surfaces only) or a `SHAPE_REPRESENTATION`
//! holding both. Each face is an `ADVANCED_FACE`
//! over a `B_SPLINE_SURFACE_WITH_KNOTS`, bounded by the four boundary isocurves of its
//! clamped net (exactly its first and last control rows and columns, with the surface's
//! knots, as `B_SPLINE_CURVE_WITH_KNOTS`):
//!
//! - the loop runs counter-clockwise in `(u, v)`: `v = v₀` forward, `u = 1` forward,
//!   `v = v₁` reversed, `u = 0` reversed, so the face's normal is `S_u × S_v`;
//! - a boundary row shorter than the uncertainty (a pole) is left out of the loop (a
//!   degenerate edge has no 3D curve; readers rebuild it from the surface);
//! - a surface closed in `v` uses one edge for `v = v₀` and `v = v₁` (the seam, once in
//!   each direction);
//! - corners closer than the uncertainty share their vertex;
//! - holes (trim curves) are inner `FACE_BOUND`s of one closed edge each, run clockwise
//!   in `(u, v)`; the edge is a `SURFACE_CURVE`: its 3D curve (the master; it lies on the
//!   written surface, or is the boundary of a face standing on the hole, whose edge it then
//!   is: the dolphin's fins on its body) and the trim curve in `(u, v)` as a `PCURVE` on
//!   the trimmed face.
//!
//! Lengths are written in millimetres (a scene's unit becomes 1 mm); the uncertainty —
//! the distance below which two points are one — is the caller's (the fit tolerance).

use pdeshape_core::Vec3;
use pdeshape_core::fit::{BSplineCurve3, BSplineSurface, Knots};
use std::fmt::Write as _;
use std::io::{self, Write};

/// A face to write.
pub struct StepFace<'a> {
    /// The face's name (the patch's).
    pub name: &'a str,
    /// Its surface.
    pub surface: &'a BSplineSurface,
    /// Inner boundaries (holes).
    pub holes: Vec<StepHole<'a>>,
    /// A face of a solid: whether `S_u × S_v` points out of it (its closed shell is then
    /// oriented outward).
    pub outward: Option<bool>,
}

/// A hole of a face: a closed space curve on its surface.
pub struct StepHole<'a> {
    /// The edge's 3D curve.
    pub curve: &'a BSplineCurve3,
    /// The same curve in the face's `(u, v)` (a planar spline, `z = 0`): written as the
    /// edge's `PCURVE` on the face.
    pub pcurve: Option<&'a BSplineCurve3>,
    /// Whether the curve runs counter-clockwise in the face's `(u, v)`.
    pub counter_clockwise: bool,
}

/// STEP's REAL: shortest round-trip digits with a decimal point and an upper-case exponent.
pub(super) fn real(x: f64) -> String {
    let mut s = String::new();
    push_real(&mut s, x);
    s
}

/// Appends [`real`]'s text of `x` to `out`, with no allocation of its own (the writer's
/// control points: 35 000 numbers for the dolphin).
pub(super) fn push_real(out: &mut String, x: f64) {
    let start = out.len();
    let _ = write!(out, "{x:?}");
    match out[start..].find('e') {
        Some(e) => {
            let e = start + e;
            let with = if out[start..e].contains('.') { "E" } else { ".E" };
            out.replace_range(e..e + 1, with);
        }
        None if !out[start..].contains('.') => out.push('.'),
        None => {}
    }
}

/// STEP's STRING: apostrophes doubled, only printable ASCII kept (others as `?`; the
/// names are the scene's, for display only).
fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('\'');
    for c in s.chars() {
        match c {
            '\'' => out.push_str("''"),
            '\\' => out.push_str("\\\\"),
            ' '..='~' => out.push(c),
            _ => out.push('?'),
        }
    }
    out.push('\'');
    out
}

/// Entities numbered in order of creation, after `next`.
pub(super) struct Entities {
    pub(super) text: String,
    pub(super) next: usize,
}

impl Entities {
    pub(super) fn add(&mut self, body: &str) -> usize {
        self.add_with(|text| text.push_str(body))
    }

    /// [`add`](Self::add) with the body written into the text in place by `body`.
    fn add_with(&mut self, body: impl FnOnce(&mut String)) -> usize {
        self.next += 1;
        let _ = write!(self.text, "#{}=", self.next);
        body(&mut self.text);
        self.text.push_str(";\n");
        self.next
    }

    pub(super) fn point(&mut self, p: Vec3) -> usize {
        self.add_with(|text| {
            text.push_str("CARTESIAN_POINT('',(");
            for (k, x) in [p.x, p.y, p.z].into_iter().enumerate() {
                if k > 0 {
                    text.push(',');
                }
                push_real(text, x);
            }
            text.push_str("))");
        })
    }

    pub(super) fn list(ids: impl IntoIterator<Item = usize>) -> String {
        let v: Vec<String> = ids.into_iter().map(|i| format!("#{i}")).collect();
        format!("({})", v.join(","))
    }

    fn knots(k: &Knots) -> (String, String) {
        let (t, m) = k.multiplicities();
        let m: Vec<String> = m.iter().map(|x| x.to_string()).collect();
        let t: Vec<String> = t.iter().map(|&x| real(x)).collect();
        (format!("({})", m.join(",")), format!("({})", t.join(",")))
    }

    pub(super) fn curve(&mut self, pts: &[Vec3], k: &Knots, tol: f64) -> usize {
        let ids: Vec<usize> = pts.iter().map(|&p| self.point(p)).collect();
        let (m, t) = Self::knots(k);
        let closed = if (pts[0] - pts[pts.len() - 1]).norm() <= tol { ".T." } else { ".F." };
        self.add(&format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},{},.UNSPECIFIED.,{closed},.F.,{m},{t},.UNSPECIFIED.)",
            k.degree,
            Self::list(ids)
        ))
    }

    /// A planar curve (`z` of the control points dropped) for a pcurve.
    fn curve2d(&mut self, c: &BSplineCurve3) -> usize {
        let ids: Vec<usize> =
            c.control.iter().map(|p| self.add(&format!("CARTESIAN_POINT('',({},{}))", real(p.x), real(p.y)))).collect();
        let (m, t) = Self::knots(&c.knots);
        self.add(&format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},{},.UNSPECIFIED.,.F.,.F.,{m},{t},.UNSPECIFIED.)",
            c.knots.degree,
            Self::list(ids)
        ))
    }

    pub(super) fn surface(&mut self, s: &BSplineSurface) -> usize {
        let (nu, nv) = s.counts();
        let mut rows = Vec::with_capacity(nu);
        for i in 0..nu {
            let ids: Vec<usize> = (0..nv).map(|j| self.point(s.control[i * nv + j])).collect();
            rows.push(Self::list(ids));
        }
        let (mu, tu) = Self::knots(&s.u);
        let (mv, tv) = Self::knots(&s.v);
        let vclosed = if s.periodic_v { ".T." } else { ".F." };
        self.add(&format!(
            "B_SPLINE_SURFACE_WITH_KNOTS('',{},{},({}),.UNSPECIFIED.,.F.,{vclosed},.F.,{mu},{mv},{tu},{tv},.UNSPECIFIED.)",
            s.u.degree,
            s.v.degree,
            rows.join(",")
        ))
    }
}

/// The length of a polyline of control points (an upper bound of its curve's length).
fn hull_length(p: &[Vec3]) -> f64 {
    p.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// A boundary side of a face: its curve (control points and knots), the corners it joins
/// (indices into the face's corners) and its direction in the face's loop.
struct Side<'a> {
    pts: Vec<Vec3>,
    knots: &'a Knots,
    from: usize,
    to: usize,
    forward: bool,
}

/// The sides of a face's outer loop, counter-clockwise in `(u, v)`, without poles; a
/// surface closed in `v` has its seam (`v = v₀` and `v = v₁`) as side 0 and side 2.
fn sides<'a>(s: &'a BSplineSurface, tol: f64) -> Vec<(usize, Side<'a>)> {
    let all = [
        Side { pts: s.v_edge(false), knots: &s.u, from: 0, to: 1, forward: true },
        Side { pts: s.u_edge(true), knots: &s.v, from: 1, to: 2, forward: true },
        Side { pts: s.v_edge(true), knots: &s.u, from: 3, to: 2, forward: false },
        Side { pts: s.u_edge(false), knots: &s.v, from: 0, to: 3, forward: false },
    ];
    all.into_iter().enumerate().filter(|(_, side)| hull_length(&side.pts) > tol).collect()
}

/// Checks that the uncertainty `tol` is small beside the face's boundary: each of its four
/// boundary rows is either a pole (its control polygon shorter than `tol`) or longer than
/// 100 × `tol`, and at least two are not poles. A tolerance that exceeds the geometry would
/// otherwise merge corners and drop sides — empty `EDGE_LOOP`s, one-face "closed" shells,
/// seams between boundaries that do not touch — so it is refused, naming the face.
pub fn check_uncertainty(name: &str, s: &BSplineSurface, tol: f64) -> Result<(), String> {
    let rows = [s.v_edge(false), s.u_edge(true), s.v_edge(true), s.u_edge(false)];
    let what = ["v = v0", "u = 1", "v = v1", "u = 0"];
    let mut kept = 0;
    for (r, w) in rows.iter().zip(what) {
        let l = hull_length(r);
        if l.is_nan() {
            return Err(format!("face `{name}`: its boundary {w} is not finite"));
        }
        if l > tol && l <= 100.0 * tol {
            return Err(format!(
                "face `{name}`: its boundary {w} is {l:.3e} long, within 100 × the tolerance {tol:.3e}; the tolerance exceeds the geometry (lower --tolerance or --relative-tolerance)"
            ));
        }
        kept += usize::from(l > tol);
    }
    if kept < 2 {
        return Err(format!(
            "face `{name}`: its boundary is shorter than the tolerance {tol:.3e}; the tolerance exceeds the geometry (lower --tolerance or --relative-tolerance)"
        ));
    }
    Ok(())
}

/// The corners `(0, v₀), (1, v₀), (1, v₁), (0, v₁)` (a clamped net interpolates them).
fn corners(s: &BSplineSurface) -> [Vec3; 4] {
    let (nu, nv) = s.counts();
    let c = |i: usize, j: usize| s.control[i * nv + j];
    [c(0, 0), c(nu - 1, 0), c(nu - 1, nv - 1), c(0, nv - 1)]
}

/// The shell's topology: edges shared by faces whose boundary curves coincide (same knots,
/// control points within the uncertainty: faces fitted with common knots along a common
/// edge), and which faces to flip so that every shared edge is run in opposite directions
/// by its two faces (a consistently oriented shell).
struct Topology {
    /// Per face and side: the index of its edge in `edges`.
    edge_of: Vec<Vec<(usize, usize)>>,
    /// Edges: (face, side) that defines the curve.
    edges: Vec<(usize, usize)>,
    /// Faces to write with `same_sense` false.
    flip: Vec<bool>,
    /// Connected components (one shell each), and whether each is closed (every edge
    /// joins two faces, or one face to itself along its seam).
    shells: Vec<(Vec<usize>, bool)>,
}

/// The sides of a face's outer loop ([`sides`]) and its holes as sides `4, 5, …` (a hole
/// runs clockwise in the face's loop; a face standing on the hole shares its edge).
fn all_sides<'a>(f: &'a StepFace, tol: f64) -> Vec<(usize, Side<'a>)> {
    let mut out = sides(f.surface, tol);
    for (i, h) in f.holes.iter().enumerate() {
        let c = h.curve;
        out.push((
            4 + i,
            Side { pts: c.control.clone(), knots: &c.knots, from: 0, to: 0, forward: !h.counter_clockwise },
        ));
    }
    out
}

fn topology(faces: &[StepFace], tol: f64) -> Topology {
    let sides: Vec<Vec<(usize, Side)>> = faces.iter().map(|f| all_sides(f, tol)).collect();
    let mut edges: Vec<(usize, usize)> = Vec::new();
    let mut edge_of: Vec<Vec<(usize, usize)>> = Vec::with_capacity(faces.len());
    // uses[e]: (face, runs forward)
    let mut uses: Vec<Vec<(usize, bool)>> = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        let mut mine = Vec::new();
        for (k, side) in &sides[fi] {
            let own_seam = *k == 2 && f.surface.periodic_v;
            let found = if own_seam {
                mine.iter().find(|(kk, _)| *kk == 0).map(|&(_, e)| e)
            } else {
                // an edge joins at most two faces (a manifold shell): a third gets its own
                edges.iter().enumerate().position(|(ei, &(g, gk))| {
                    let other = &sides[g].iter().find(|(k2, _)| *k2 == gk).expect("registered").1;
                    g != fi
                        && uses[ei].len() == 1
                        && other.knots == side.knots
                        && other.pts.len() == side.pts.len()
                        && other.pts.iter().zip(&side.pts).all(|(a, b)| (*a - *b).norm() <= tol)
                })
            };
            let e = found.unwrap_or_else(|| {
                edges.push((fi, *k));
                uses.push(Vec::new());
                edges.len() - 1
            });
            uses[e].push((fi, side.forward));
            mine.push((*k, e));
        }
        edge_of.push(mine);
    }
    // flips by a walk over faces joined by shared edges
    let n = faces.len();
    let (mut flip, mut seen) = (vec![false; n], vec![false; n]);
    let mut shells = Vec::new();
    for start in 0..n {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let (mut stack, mut comp) = (vec![start], vec![start]);
        while let Some(f) = stack.pop() {
            for &(_, e) in &edge_of[f] {
                let here = uses[e].iter().find(|(g, _)| *g == f).map(|u| u.1);
                for &(g, dir) in &uses[e] {
                    if g == f || seen[g] {
                        continue;
                    }
                    // opposite directions after the flips: flip_g = flip_f xor (dir_f == dir_g)
                    flip[g] = flip[f] ^ (here == Some(dir));
                    seen[g] = true;
                    stack.push(g);
                    comp.push(g);
                }
            }
        }
        comp.sort_unstable();
        // a solid's shell faces outward: flip the whole component if its first face with
        // a known outward side would be written inward
        if let Some((f, o)) = comp.iter().find_map(|&f| faces[f].outward.map(|o| (f, o)))
            && flip[f] == o
        {
            for &g in &comp {
                flip[g] = !flip[g];
            }
        }
        let closed = comp.iter().all(|&f| edge_of[f].iter().all(|&(_, e)| uses[e].len() == 2));
        shells.push((comp, closed));
    }
    Topology { edge_of, edges, flip, shells }
}

/// Writes the faces' vertices and edges (shared ones once) and the faces; returns the
/// face ids.
fn write_faces(e: &mut Entities, faces: &[StepFace], t: &Topology, tol: f64) -> Vec<usize> {
    let mut verts: Vec<(Vec3, usize)> = Vec::new();
    let mut vertex = |e: &mut Entities, p: Vec3| -> usize {
        if let Some(&(_, id)) = verts.iter().find(|(q, _)| (*q - p).norm() <= tol) {
            return id;
        }
        let pt = e.point(p);
        let id = e.add(&format!("VERTEX_POINT('',#{pt})"));
        verts.push((p, id));
        id
    };
    let mut edge_ids: Vec<Option<usize>> = vec![None; t.edges.len()];
    let srfs: Vec<usize> = faces.iter().map(|f| e.surface(f.surface)).collect();
    // hole edges first, so that the trimmed face's pcurve is on the edge even where a face
    // standing on the hole comes first: one closed edge from and to the curve's start, its
    // geometry the 3D curve (master) with the trim curve in (u, v) as the pcurve
    let mut ctx2d = None;
    for (fi, f) in faces.iter().enumerate() {
        for (i, h) in f.holes.iter().enumerate() {
            let ei = t.edge_of[fi].iter().find(|(kk, _)| *kk == 4 + i).expect("every hole has an edge").1;
            if edge_ids[ei].is_some() {
                continue;
            }
            let c = h.curve;
            let start = vertex(e, c.control[0]);
            let mut curve = e.curve(&c.control, &c.knots, tol);
            if let Some(pc) = h.pcurve {
                let ctx = *ctx2d.get_or_insert_with(|| {
                    e.add("(GEOMETRIC_REPRESENTATION_CONTEXT(2)PARAMETRIC_REPRESENTATION_CONTEXT()REPRESENTATION_CONTEXT('2D SPACE',''))")
                });
                let c2 = e.curve2d(pc);
                let rep = e.add(&format!("DEFINITIONAL_REPRESENTATION('',(#{c2}),#{ctx})"));
                let pcurve = e.add(&format!("PCURVE('',#{},#{rep})", srfs[fi]));
                curve = e.add(&format!("SURFACE_CURVE('',#{curve},(#{pcurve}),.CURVE_3D.)"));
            }
            edge_ids[ei] = Some(e.add(&format!("EDGE_CURVE('',#{start},#{start},#{curve},.T.)")));
        }
    }
    let mut out = Vec::with_capacity(faces.len());
    for (fi, f) in faces.iter().enumerate() {
        let s = f.surface;
        let srf = srfs[fi];
        let cs = corners(s);
        let sd = sides(s, tol);
        let mut loop_edges = Vec::new();
        for (k, side) in &sd {
            let ei = t.edge_of[fi].iter().find(|(kk, _)| kk == k).expect("every side has an edge").1;
            let id = match edge_ids[ei] {
                Some(id) => id,
                None => {
                    let (a, b) = (vertex(e, cs[side.from]), vertex(e, cs[side.to]));
                    let curve = e.curve(&side.pts, side.knots, tol);
                    let id = e.add(&format!("EDGE_CURVE('',#{a},#{b},#{curve},.T.)"));
                    edge_ids[ei] = Some(id);
                    id
                }
            };
            let flag = if side.forward { ".T." } else { ".F." };
            loop_edges.push(e.add(&format!("ORIENTED_EDGE('',*,*,#{id},{flag})")));
        }
        // a flipped face (normal −S_u × S_v) runs its loops the other way round
        let sense = |b: bool| if b != t.flip[fi] { ".T." } else { ".F." };
        let lp = e.add(&format!("EDGE_LOOP('',{})", Entities::list(loop_edges)));
        let mut bounds = vec![e.add(&format!("FACE_OUTER_BOUND('',#{lp},{})", sense(true)))];
        for (i, h) in f.holes.iter().enumerate() {
            // an inner loop runs clockwise
            let ei = t.edge_of[fi].iter().find(|(kk, _)| *kk == 4 + i).expect("every hole has an edge").1;
            let edge = edge_ids[ei].expect("hole edges are written first");
            let flag = if h.counter_clockwise { ".F." } else { ".T." };
            let oe = e.add(&format!("ORIENTED_EDGE('',*,*,#{edge},{flag})"));
            let lp = e.add(&format!("EDGE_LOOP('',(#{oe}))"));
            bounds.push(e.add(&format!("FACE_BOUND('',#{lp},{})", sense(true))));
        }
        out.push(e.add(&format!(
            "ADVANCED_FACE({},{},#{srf},{})",
            string(f.name),
            Entities::list(bounds),
            sense(true)
        )));
    }
    out
}

/// Writes `faces` as one product named `product` (solids of the closed shells, a surface
/// model of the open ones). `uncertainty` is the distance below which points are one (the fit tolerance).
/// Refuses non-finite control points.
pub fn write_step(w: &mut dyn Write, product: &str, faces: &[StepFace], uncertainty: f64) -> io::Result<()> {
    if let Some(f) = faces.iter().find(|f| f.surface.control.iter().any(|p| !p.is_finite())) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("face `{}` has a non-finite control point", f.name),
        ));
    }
    if !(uncertainty.is_finite() && uncertainty > 0.0) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("the uncertainty {uncertainty:e} is not a positive finite number"),
        ));
    }
    for f in faces {
        check_uncertainty(f.name, f.surface, uncertainty).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
    }
    let mut e = Entities { text: String::new(), next: 0 };
    let name = string(product);
    let app = e.add("APPLICATION_CONTEXT('automotive design')");
    e.add(&format!("APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"));
    let pctx = e.add(&format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let prod = e.add(&format!("PRODUCT({name},{name},'',(#{pctx}))"));
    e.add(&format!("PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{prod}))"));
    let form = e.add(&format!("PRODUCT_DEFINITION_FORMATION('','',#{prod})"));
    let dctx = e.add(&format!("PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"));
    let pdef = e.add(&format!("PRODUCT_DEFINITION('design','',#{form},#{dctx})"));
    let pds = e.add(&format!("PRODUCT_DEFINITION_SHAPE('','',#{pdef})"));
    let length = e.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))");
    let angle = e.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))");
    let solid = e.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())");
    let unc = e.add(&format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{length},'distance_accuracy_value','fit tolerance')",
        real(uncertainty)
    ));
    let ctx = e.add(&format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{solid}))REPRESENTATION_CONTEXT('',''))"
    ));
    let o = e.point(Vec3::ZERO);
    let z = e.add("DIRECTION('',(0.,0.,1.))");
    let x = e.add("DIRECTION('',(1.,0.,0.))");
    let axes = e.add(&format!("AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})"));
    let topo = topology(faces, uncertainty);
    let ids = write_faces(&mut e, faces, &topo, uncertainty);
    let (mut open, mut solids) = (Vec::new(), Vec::new());
    for (comp, closed) in &topo.shells {
        let names: Vec<&str> = comp.iter().map(|&k| faces[k].name).collect();
        let list = Entities::list(comp.iter().map(|&k| ids[k]));
        if *closed {
            let shell = e.add(&format!("CLOSED_SHELL({},{list})", string(&names.join("+"))));
            solids.push(e.add(&format!("MANIFOLD_SOLID_BREP({},#{shell})", string(&names.join("+")))));
        } else {
            open.push(e.add(&format!("OPEN_SHELL({},{list})", string(&names.join("+")))));
        }
    }
    // solids alone: an advanced B-rep; surfaces alone: a surface model; both: the generic
    // shape representation holding both kinds of item
    let mut items = vec![axes];
    items.extend(&solids);
    if !open.is_empty() {
        items.push(e.add(&format!("SHELL_BASED_SURFACE_MODEL('',{})", Entities::list(open.iter().copied()))));
    }
    let kind = match (solids.is_empty(), open.is_empty()) {
        (false, true) => "ADVANCED_BREP_SHAPE_REPRESENTATION",
        (true, _) => "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
        (false, false) => "SHAPE_REPRESENTATION",
    };
    let rep = e.add(&format!("{kind}({name},{},#{ctx})", Entities::list(items)));
    e.add(&format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));

    writeln!(w, "ISO-10303-21;")?;
    writeln!(w, "HEADER;")?;
    writeln!(w, "FILE_DESCRIPTION(('pdeshape B-spline surface model'),'2;1');")?;
    writeln!(w, "FILE_NAME({name},'',(''),(''),'pdeshape {}','pdeshape','');", env!("CARGO_PKG_VERSION"))?;
    writeln!(w, "FILE_SCHEMA(('AUTOMOTIVE_DESIGN {{ 1 0 10303 214 1 1 1 1 }}'));")?;
    writeln!(w, "ENDSEC;")?;
    writeln!(w, "DATA;")?;
    w.write_all(e.text.as_bytes())?;
    writeln!(w, "ENDSEC;")?;
    writeln!(w, "END-ISO-10303-21;")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_have_a_point_and_an_upper_case_exponent() {
        assert_eq!(real(1.0), "1.0");
        assert_eq!(real(-0.25), "-0.25");
        assert_eq!(real(1e-7), "1.E-7");
        assert_eq!(real(1.5e-7), "1.5E-7");
        assert_eq!(real(2e20), "2.E20");
        // appended after other text (the writer's lines): only the number is touched
        let mut line = String::from("(1.5e,");
        for x in [1e-7, 2.5, 3.0, -4.25e30] {
            push_real(&mut line, x);
            line.push(',');
        }
        assert_eq!(line, "(1.5e,1.E-7,2.5,3.0,-4.25E30,");
        // round trip
        for x in [0.1, 1.0 / 3.0, -7.123456789e-12, 6.02e23] {
            let s = real(x).replace('E', "e");
            assert_eq!(s.parse::<f64>().unwrap(), x);
        }
    }

    #[test]
    fn strings_escape_quotes_and_drop_non_ascii() {
        assert_eq!(string("fin's"), "'fin''s'");
        assert_eq!(string("a\\b"), "'a\\\\b'");
        assert_eq!(string("wing–root"), "'wing?root'");
    }
}
