//! A read STEP model written back with new faces sewn into its holes.
//!
//! Every byte of the input stays as it was but for the shells that receive faces: each
//! new face's entities are appended after the file's last entity (ids above its largest),
//! and the shell's face list gains the new faces. A new face is an `ADVANCED_FACE` over
//! its `B_SPLINE_SURFACE_WITH_KNOTS` (a fill: `u = 0` the hole's loop, `u = 1` a pole,
//! closed in `v`), bounded by one loop that runs counter-clockwise in `(u, v)`: the seam
//! `v = v₀` (a new edge from the hole's vertex at `v = 0` to the pole; the pole itself is
//! a degenerate side left out, as in `export/step.rs`), the seam back, then the hole's own
//! `EDGE_CURVE`s — not copies — run against the direction their faces run them, so each
//! joins its old face and the new one and the shell stays consistently oriented.
//!
//! Faces removed from the model (`StepModel::removed`, faces replaced by fills) leave their
//! shells' face lists (their entities stay in the file, unreferenced); a shell the file
//! calls closed must then have every hole filled.
//!
//! Where a hole runs from one part to another that touches it (two vertex entities at one
//! point, see `brep::holes`), the edges at the second vertex are rewritten to use the
//! first, so the new face's loop runs through shared vertices; a hole along faces of two
//! shells is refused.
//!
//! A shell whose holes are all filled becomes a `CLOSED_SHELL`; when it was the only shell
//! of a `SHELL_BASED_SURFACE_MODEL` in a `MANIFOLD_SURFACE_SHAPE_REPRESENTATION`, the
//! model becomes a `MANIFOLD_SOLID_BREP` in an `ADVANCED_BREP_SHAPE_REPRESENTATION` (the
//! same entity ids, rewritten in place).

use super::step::Entities;
use crate::import::step::StepModel;
use pdeshape_core::Vec3;
use pdeshape_core::brep::Hole;
use pdeshape_core::fit::BSplineSurface;

/// A new face for a hole of the model.
pub struct SewnFace<'a> {
    /// The fitted surface: `u = 0` the hole's loop from its vertex at `v = 0`, in the
    /// direction the faces around run it.
    pub surface: &'a BSplineSurface,
    /// The hole.
    pub hole: &'a Hole,
    /// Whether every hole of the face's shell is filled (the shell is then closed).
    pub closes_shell: bool,
}

/// The model's bytes with `faces` sewn in. `tol` is the distance within which the new
/// face's corner must meet a vertex of its hole.
pub fn sewn_step(m: &StepModel, faces: &[SewnFace], tol: f64) -> Result<Vec<u8>, String> {
    let b = &m.brep;
    let mut e = Entities { text: String::new(), next: m.max_id as usize };
    let start_of = |u: &pdeshape_core::brep::HoleUse| u.ends(b).0;
    let end_of = |u: &pdeshape_core::brep::HoleUse| u.ends(b).1;
    // where a hole passes from one part to another that touches it (two vertex entities
    // at one point, `brep::holes`), the vertices become one — the smallest index of each
    // such class — so that each new face's loop runs through shared vertices
    let mut same = pdeshape_core::classes::Classes::new(b.vertices.len());
    for f in faces {
        let uses = &f.hole.uses;
        for k in 0..uses.len() {
            same.join(end_of(&uses[k]), start_of(&uses[(k + 1) % uses.len()]));
        }
    }
    let same = same.all();
    // (shell id, new face ids)
    let mut added: Vec<(u64, Vec<usize>, bool)> = Vec::new();
    for f in faces {
        let s = f.surface;
        if s.control.iter().any(|p| !p.is_finite()) {
            return Err("a new face has a non-finite control point".into());
        }
        if !s.periodic_v {
            return Err("a new face is not closed around its hole".into());
        }
        let (nu, nv) = s.counts();
        let start = s.control[0];
        // the hole's vertex where the face's v = 0 starts
        let n = f.hole.uses.len();
        let (k0, d) = (0..n)
            .map(|k| (k, (b.vertices[start_of(&f.hole.uses[k])].1 - start).norm()))
            .min_by(|a, c| a.1.total_cmp(&c.1))
            .ok_or("a hole without edges")?;
        if d.is_nan() || d > tol {
            return Err(format!(
                "the new face starts {d:.3e} from the nearest vertex of its hole (the tolerance is {tol:.3e})"
            ));
        }
        let v0 = b.vertices[same[start_of(&f.hole.uses[k0])]].0;
        let srf = e.surface(s);
        // the pole: the u = 1 row, one point
        let pole_row: Vec<Vec3> = (0..nv).map(|j| s.control[(nu - 1) * nv + j]).collect();
        let pole = pole_row[0];
        if let Some(q) = pole_row.iter().find(|q| (**q - pole).norm() > tol) {
            return Err(format!("a new face's u = 1 side is not a point ({q} vs {pole})"));
        }
        let pp = e.point(pole);
        let pv = e.add(&format!("VERTEX_POINT('',#{pp})"));
        let seam_pts: Vec<Vec3> = (0..nu).map(|i| s.control[i * nv]).collect();
        let seam_curve = e.curve(&seam_pts, &s.u, tol);
        let seam = e.add(&format!("EDGE_CURVE('',#{v0},#{pv},#{seam_curve},.T.)"));
        let mut oes = vec![
            e.add(&format!("ORIENTED_EDGE('',*,*,#{seam},.T.)")),
            e.add(&format!("ORIENTED_EDGE('',*,*,#{seam},.F.)")),
        ];
        // u = 0 backwards: the hole's uses from the last before k0 down to k0, each
        // against its face's direction
        for i in 0..n {
            let u = &f.hole.uses[(k0 + n - 1 - i) % n];
            let flag = if u.forward { ".F." } else { ".T." };
            oes.push(e.add(&format!("ORIENTED_EDGE('',*,*,#{},{flag})", b.edges[u.edge].id)));
        }
        let lp = e.add(&format!("EDGE_LOOP('',{})", Entities::list(oes)));
        let bound = e.add(&format!("FACE_OUTER_BOUND('',#{lp},.T.)"));
        let face = e.add(&format!("ADVANCED_FACE('',(#{bound}),#{srf},.T.)"));
        let shell = b.shells[b.faces[f.hole.uses[0].face].shell].id;
        // parts that touch in different shells: the new face would join them, and the
        // shells' structure (one surface model, or separate parts) is the file's to say
        if let Some(other) = f.hole.uses.iter().map(|u| b.shells[b.faces[u.face].shell].id).find(|&id| id != shell) {
            return Err(format!(
                "a hole runs along faces of the shells #{shell} and #{other}: a new face joining two shells is not written"
            ));
        }
        match added.iter_mut().find(|a| a.0 == shell) {
            Some(a) => {
                a.1.push(face);
                a.2 &= f.closes_shell;
            }
            None => added.push((shell, vec![face], f.closes_shell)),
        }
    }
    // edits of the source: (byte start, byte end, replacement)
    let text = |id: u64| -> Result<(usize, usize, String), String> {
        let &(s, t, _) = m.spans.get(&id).ok_or(format!("#{id} is not in the file"))?;
        let (s, t) = (s as usize, t as usize);
        let body = std::str::from_utf8(&m.source[s..t]).map_err(|_| format!("#{id} is not UTF-8 text"))?;
        Ok((s, t, body.to_string()))
    };
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    // the edges at a merged vertex: `EDGE_CURVE('name',#start,#end,#curve,sense)` with
    // the vertex replaced
    for edge in &b.edges {
        let [s0, s1] = edge.vertices;
        if same[s0] == s0 && same[s1] == s1 {
            continue;
        }
        let (s, t, body) = text(edge.id)?;
        let (start, end) = (b.vertices[same[s0]].0, b.vertices[same[s1]].0);
        edits.push((
            s,
            t,
            edge_with_vertices(&body, start, end).ok_or(format!("#{}: not an EDGE_CURVE as read", edge.id))?,
        ));
    }
    // shells that lost faces and gain none
    for sh in &b.shells {
        let lost = m.shell_lost_faces(sh.id);
        if lost && !added.iter().any(|a| a.0 == sh.id) {
            added.push((sh.id, Vec::new(), false));
        }
    }
    for (shell, new, closes) in &added {
        let (s, t, mut body) = text(*shell)?;
        let closed_in_file = m.types.get(shell).map(String::as_str) == Some("CLOSED_SHELL");
        let lost = m.shell_lost_faces(*shell);
        if lost && closed_in_file && !*closes {
            return Err(format!(
                "#{shell} CLOSED_SHELL: faces of it were removed, and not every hole they leave is filled (the shell would be open)"
            ));
        }
        // `#N = OPEN_SHELL('name',(#a,#b));`: the removed faces out of the list, the new
        // ones before its `)`
        let close = body.rfind(')').ok_or(format!("#{shell}: no closing parenthesis"))?;
        let list_end = body[..close].trim_end();
        if !list_end.ends_with(')') {
            return Err(format!("#{shell}: its face list is not the last attribute"));
        }
        let at = list_end.len() - 1;
        let open = body[..at].rfind('(').ok_or(format!("#{shell}: its face list has no `(`"))?;
        let kept: Vec<String> = body[open + 1..at]
            .split(',')
            .map(|x| x.trim().to_string())
            .filter(|x| !x.is_empty() && !m.removed.iter().any(|id| *x == format!("#{id}")))
            .chain(new.iter().map(|i| format!("#{i}")))
            .collect();
        if kept.is_empty() {
            return Err(format!("#{shell}: every face of the shell was removed"));
        }
        body.replace_range(open + 1..at, &kept.join(","));
        let mut solid = None;
        if *closes && m.types.get(shell).map(String::as_str) == Some("OPEN_SHELL") {
            body = body.replacen("OPEN_SHELL", "CLOSED_SHELL", 1);
            // the only shell of a surface model in a surface representation: a solid
            let users = m.users.get(shell).cloned().unwrap_or_default();
            if let [sbsm] = users.as_slice()
                && m.types.get(sbsm).map(String::as_str) == Some("SHELL_BASED_SURFACE_MODEL")
                && m.users.get(shell).is_some_and(|u| u.len() == 1)
            {
                let reps = m.users.get(sbsm).cloned().unwrap_or_default();
                let (_, _, sbody) = text(*sbsm)?;
                let only_this = sbody.matches('#').count() == 2;
                if only_this
                    && !reps.is_empty()
                    && reps
                        .iter()
                        .all(|r| m.types.get(r).map(String::as_str) == Some("MANIFOLD_SURFACE_SHAPE_REPRESENTATION"))
                {
                    solid = Some((*sbsm, reps));
                }
            }
        }
        edits.push((s, t, body));
        if let Some((sbsm, reps)) = solid {
            let (s, t, _) = text(sbsm)?;
            edits.push((s, t, format!("#{sbsm} = MANIFOLD_SOLID_BREP('',#{shell});")));
            for r in reps {
                let (s, t, body) = text(r)?;
                edits.push((
                    s,
                    t,
                    body.replacen("MANIFOLD_SURFACE_SHAPE_REPRESENTATION", "ADVANCED_BREP_SHAPE_REPRESENTATION", 1),
                ));
            }
        }
    }
    // the new entities after the last one
    let last = m.spans.values().map(|s| s.1 as usize).max().ok_or("the file has no entities")?;
    edits.push((last, last, format!("\n{}", e.text.trim_end())));
    edits.sort_by_key(|x| std::cmp::Reverse(x.0));
    let mut out = m.source.clone();
    for (s, t, body) in edits {
        out.splice(s..t, body.into_bytes());
    }
    Ok(out)
}

/// `#N = EDGE_CURVE('name', #a, #b, #curve, sense);` with `#start` and `#end` for `#a`
/// and `#b` (`None` when the text is not of that form).
fn edge_with_vertices(body: &str, start: u64, end: u64) -> Option<String> {
    let open = body.find("EDGE_CURVE")? + "EDGE_CURVE".len();
    let rest = body[open..].trim_start().strip_prefix('(')?;
    // the name: a string whose quotes are doubled inside it
    let rest_t = rest.trim_start();
    let mut i = body.len() - rest_t.len();
    if !rest_t.starts_with('\'') {
        return None;
    }
    i += 1;
    let bytes = body.as_bytes();
    loop {
        match bytes.get(i)? {
            b'\'' if bytes.get(i + 1) == Some(&b'\'') => i += 2,
            b'\'' => break,
            _ => i += 1,
        }
    }
    let after_name = i + 1;
    // the two vertex references: `, #a , #b ,`
    let mut parts = body[after_name..].splitn(4, ',');
    let (lead, a, bb, tail) = (parts.next()?, parts.next()?, parts.next()?, parts.next()?);
    if !lead.trim().is_empty() || !a.trim().starts_with('#') || !bb.trim().starts_with('#') {
        return None;
    }
    Some(format!("{},#{start},#{end},{tail}", &body[..after_name]))
}
