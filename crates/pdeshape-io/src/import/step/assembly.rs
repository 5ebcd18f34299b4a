//! The product structure of a STEP file (AP203/AP214/AP242 assemblies): where each shell
//! is placed, and how many times.
//!
//! A part's shells are read once, in the part's coordinates (the B-rep, which fills are
//! made in and the writer writes back). An assembly places parts by
//! `NEXT_ASSEMBLY_USAGE_OCCURRENCE`s (parent and child `PRODUCT_DEFINITION`), each given
//! its motion by a `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` whose
//! `REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION` relates the child's shape
//! representation (`rep_1`) to the parent's (`rep_2`) through an
//! `ITEM_DEFINED_TRANSFORMATION` of two `AXIS2_PLACEMENT_3D`s: `item_1` in `rep_1`,
//! `item_2` in `rep_2`, the motion taking `item_1` onto `item_2`,
//!
//! `x_parent = F₂(F₁⁻¹(x_child))`
//!
//! (`F(q) = o + q_x x + q_y y + q_z z`). Writers that swap `rep_1` and `rep_2` are read
//! the other way round: the child is the side whose representation is the child
//! product's. A product's shells are those of the representations its
//! `SHAPE_DEFINITION_REPRESENTATION`s name, of the ones these are related to without a
//! motion (`SHAPE_REPRESENTATION_RELATIONSHIP`), and of `MAPPED_ITEM`s in them (placed by
//! `mapping_target ∘ mapping_origin⁻¹`). Each root product (no parent) is walked down,
//! composing the motions; a shell that no product reaches (a file without a product
//! structure) is placed once where it is.

use super::{Reader, StepError, collect_refs};
use pdeshape_core::data::analytic::Frame;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use step_io::parser::{Attribute, RawEntity};

/// The most copies of shells an assembly may place (a hostile file nesting assemblies
/// of many uses each multiplies them).
pub const MAX_INSTANCES: usize = 100_000;

/// Deeper product structures are refused (a cycle of assembly uses is one).
const MAX_DEPTH: usize = 64;

/// The most products and mapped items the walk visits (each use and mapping counted every
/// time it is reached): nested uses of many copies each multiply, with or without shells.
const MAX_VISITS: usize = 1_000_000;

/// One placed copy of a shell.
#[derive(Clone, Debug, PartialEq)]
pub struct ShellInstance {
    /// The shell (index into the B-rep's shells).
    pub shell: usize,
    /// Its motion from the part's coordinates to the model's.
    pub placement: Frame,
    /// The products from the root down, each `name (#id)` of its
    /// `NEXT_ASSEMBLY_USAGE_OCCURRENCE` (the root's `#id` its `PRODUCT_DEFINITION`'s);
    /// empty for a shell no product reaches.
    pub path: Vec<String>,
}

/// An entity's type and attributes: a simple entity's, or the part `part` of a complex
/// instance.
fn attrs_of<'g>(e: &'g RawEntity, part: &str) -> Option<&'g [Attribute]> {
    match e {
        RawEntity::Simple { name, attributes, .. } if name == part => Some(attributes),
        RawEntity::Complex { parts, .. } => parts.iter().find(|p| p.name == part).map(|p| p.attributes.as_slice()),
        _ => None,
    }
}

fn simple_name(e: &RawEntity) -> Option<&str> {
    match e {
        RawEntity::Simple { name, .. } => Some(name),
        RawEntity::Complex { .. } => None,
    }
}

fn reference(a: Option<&Attribute>) -> Option<u64> {
    match a {
        Some(Attribute::EntityRef(r)) => Some(*r),
        _ => None,
    }
}

/// What the walk reads off the file, gathered in one pass.
#[derive(Default)]
struct Structure {
    /// Assembly uses: `(#id, parent, child)`.
    uses: Vec<(u64, u64, u64)>,
    /// `PRODUCT_DEFINITION_SHAPE`s by what they define (a product or an assembly use).
    shape_of: HashMap<u64, Vec<u64>>,
    /// Representations by the `PRODUCT_DEFINITION_SHAPE` they represent.
    reps_of: HashMap<u64, Vec<u64>>,
    /// The relationship with a motion placing an assembly use, by the use's shape.
    motion_of: HashMap<u64, u64>,
    /// Representations related without a motion (both ways).
    same: HashMap<u64, Vec<u64>>,
    /// Product definitions.
    products: BTreeSet<u64>,
}

impl Structure {
    fn read(r: &Reader) -> Structure {
        let mut s = Structure::default();
        for (&id, e) in &r.g.entities {
            let Some(name) = simple_name(e) else { continue };
            let a = match e {
                RawEntity::Simple { attributes, .. } => attributes.as_slice(),
                RawEntity::Complex { .. } => continue,
            };
            match name {
                "NEXT_ASSEMBLY_USAGE_OCCURRENCE" => {
                    if let (Some(p), Some(c)) = (reference(a.get(3)), reference(a.get(4))) {
                        s.uses.push((id, p, c));
                        s.products.extend([p, c]);
                    }
                }
                "PRODUCT_DEFINITION" => {
                    s.products.insert(id);
                }
                "PRODUCT_DEFINITION_SHAPE" => {
                    if let Some(d) = reference(a.get(2)) {
                        s.shape_of.entry(d).or_default().push(id);
                    }
                }
                "SHAPE_DEFINITION_REPRESENTATION" => {
                    if let (Some(d), Some(rep)) = (reference(a.first()), reference(a.get(1))) {
                        s.reps_of.entry(d).or_default().push(rep);
                    }
                }
                "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION" => {
                    if let (Some(rel), Some(d)) = (reference(a.first()), reference(a.get(1))) {
                        s.motion_of.insert(d, rel);
                    }
                }
                "SHAPE_REPRESENTATION_RELATIONSHIP" | "REPRESENTATION_RELATIONSHIP" => {
                    if let (Some(r1), Some(r2)) = (reference(a.get(2)), reference(a.get(3))) {
                        s.same.entry(r1).or_default().push(r2);
                        s.same.entry(r2).or_default().push(r1);
                    }
                }
                _ => {}
            }
        }
        s
    }

    /// The representations of product definition `pd`: its shapes' and those related to
    /// them without a motion.
    fn reps(&self, pd: u64) -> BTreeSet<u64> {
        let mut out = BTreeSet::new();
        let mut todo: Vec<u64> = self
            .shape_of
            .get(&pd)
            .into_iter()
            .flatten()
            .flat_map(|s| self.reps_of.get(s).into_iter().flatten())
            .copied()
            .collect();
        while let Some(rep) = todo.pop() {
            if out.insert(rep) {
                todo.extend(self.same.get(&rep).into_iter().flatten().copied());
            }
        }
        out
    }
}

impl<'g> Reader<'g> {
    /// The items of representation `rep` (any entity with a `REPRESENTATION` part or
    /// named `…REPRESENTATION`, or a `…_MODEL`); none for anything else.
    fn rep_items(&self, rep: u64) -> Vec<u64> {
        let Some(e) = self.g.get(rep) else { return Vec::new() };
        let items = match e {
            RawEntity::Simple { name, attributes, .. }
                if name.ends_with("REPRESENTATION") || name.ends_with("_MODEL") =>
            {
                attributes.get(1)
            }
            RawEntity::Complex { .. } => attrs_of(e, "REPRESENTATION").and_then(|a| a.get(1)),
            _ => None,
        };
        let mut out = Vec::new();
        if let Some(Attribute::List(l)) = items {
            for a in l {
                collect_refs(a, &mut out);
            }
        }
        out
    }

    /// The shells an item holds, each with its motion (`at` the item's), into `out`.
    fn item_shells(
        &self,
        item: u64,
        at: &Frame,
        depth: usize,
        shells: &HashMap<u64, usize>,
        out: &mut Vec<(usize, Frame)>,
        visits: &mut usize,
    ) -> Result<(), StepError> {
        *visits += 1;
        if *visits > MAX_VISITS {
            return Err(
                self.err_at(item, format!("the assembly's structure takes more than {MAX_VISITS} steps to walk"))
            );
        }
        if let Some(&k) = shells.get(&item) {
            out.push((k, *at));
            return Ok(());
        }
        let Some(e) = self.g.get(item) else { return Ok(()) };
        match simple_name(e) {
            Some("MANIFOLD_SOLID_BREP" | "BREP_WITH_VOIDS" | "SHELL_BASED_SURFACE_MODEL" | "FACETED_BREP") => {
                let mut refs = Vec::new();
                if let RawEntity::Simple { attributes, .. } = e {
                    attributes.iter().for_each(|a| collect_refs(a, &mut refs));
                }
                out.extend(refs.iter().filter_map(|r| shells.get(r)).map(|&k| (k, *at)));
            }
            Some("MAPPED_ITEM") => {
                if depth >= MAX_DEPTH {
                    return Err(self.err_at(item, format!("mapped items nested deeper than {MAX_DEPTH} (a cycle?)")));
                }
                let RawEntity::Simple { attributes: a, .. } = e else { return Ok(()) };
                let map = self.reference(item, self.attr(item, a, 1)?, "the mapping source")?;
                let target = self.reference(item, self.attr(item, a, 2)?, "the mapping target")?;
                let (kind, m) = self.simple(map, item)?;
                if kind != "REPRESENTATION_MAP" {
                    return Err(self.err_at(map, "a REPRESENTATION_MAP is expected"));
                }
                let origin = self.reference(map, self.attr(map, m, 0)?, "the mapping origin")?;
                let rep = self.reference(map, self.attr(map, m, 1)?, "the mapped representation")?;
                let motion = self.placement(target, item)?.then_in(&self.placement(origin, map)?.inverse());
                let placed = at.then_in(&motion);
                for i in self.rep_items(rep) {
                    self.item_shells(i, &placed, depth + 1, shells, out, visits)?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// The motion of the assembly use whose shape is `use_shape`, from the child's
    /// coordinates (`child_reps`) to the parent's; `None` when no
    /// `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` places it.
    fn use_motion(
        &self,
        s: &Structure,
        use_shape: u64,
        child_reps: &BTreeSet<u64>,
    ) -> Result<Option<Frame>, StepError> {
        let Some(&rel) = s.motion_of.get(&use_shape) else { return Ok(None) };
        let e = self.entity(rel, use_shape)?;
        let (Some(rr), Some(rrwt)) = (
            attrs_of(e, "REPRESENTATION_RELATIONSHIP"),
            attrs_of(e, "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION"),
        ) else {
            return Err(self.err_at(rel, "a REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION is expected"));
        };
        let rep1 = self.reference(rel, self.attr(rel, rr, 2)?, "rep_1")?;
        let idt = self.reference(rel, self.attr(rel, rrwt, 0)?, "the transformation operator")?;
        let (kind, t) = self.simple(idt, rel)?;
        if kind != "ITEM_DEFINED_TRANSFORMATION" {
            return Err(self.err_at(idt, "an ITEM_DEFINED_TRANSFORMATION is expected"));
        }
        let f1 = self.placement(self.reference(idt, self.attr(idt, t, 2)?, "transform_item_1")?, idt)?;
        let f2 = self.placement(self.reference(idt, self.attr(idt, t, 3)?, "transform_item_2")?, idt)?;
        // the child is rep_1 unless rep_1 is not the child's and rep_2 is
        let rep2 = self.reference(rel, self.attr(rel, rr, 3)?, "rep_2")?;
        let child_first = child_reps.contains(&rep1) || !child_reps.contains(&rep2);
        Ok(Some(if child_first { f2.then_in(&f1.inverse()) } else { f1.then_in(&f2.inverse()) }))
    }

    /// The placed copies of every shell (module docs).
    pub(super) fn instances(&self) -> Result<Vec<ShellInstance>, StepError> {
        let shells: HashMap<u64, usize> = self.brep.shells.iter().enumerate().map(|(k, s)| (s.id, k)).collect();
        let s = Structure::read(self);
        let children: BTreeSet<u64> = s.uses.iter().map(|u| u.2).collect();
        let mut by_parent: BTreeMap<u64, Vec<(u64, u64)>> = BTreeMap::new();
        for &(id, p, c) in &s.uses {
            by_parent.entry(p).or_default().push((id, c));
        }
        let name = |id: u64| -> String {
            let label = |a: &[Attribute], k: usize| match a.get(k) {
                Some(Attribute::String(x)) if !x.is_empty() => Some(x.clone()),
                _ => None,
            };
            // a use: its name or id; a product definition: its product's name
            let own = match self.g.get(id) {
                Some(RawEntity::Simple { name, attributes, .. }) if name == "NEXT_ASSEMBLY_USAGE_OCCURRENCE" => {
                    label(attributes, 1).or_else(|| label(attributes, 0))
                }
                Some(RawEntity::Simple { attributes, .. }) => reference(attributes.get(2))
                    .and_then(|f| match self.g.get(f) {
                        Some(RawEntity::Simple { attributes, .. }) => reference(attributes.get(2)),
                        _ => None,
                    })
                    .and_then(|p| match self.g.get(p) {
                        Some(RawEntity::Simple { attributes, .. }) => {
                            label(attributes, 1).or_else(|| label(attributes, 0))
                        }
                        _ => None,
                    }),
                _ => None,
            };
            match own {
                Some(n) => format!("{n} (#{id})"),
                None => format!("#{id}"),
            }
        };
        let mut out: Vec<ShellInstance> = Vec::new();
        let mut reached = vec![false; self.brep.shells.len()];
        // (product definition, its motion, path)
        let mut todo: Vec<(u64, Frame, Vec<String>)> = s
            .products
            .iter()
            .filter(|pd| !children.contains(pd))
            .rev()
            .map(|&pd| (pd, Frame::WORLD, vec![name(pd)]))
            .collect();
        let mut visits = 0;
        // each product's representations, found once (a part used many times is reached
        // as often)
        let mut reps_of: HashMap<u64, BTreeSet<u64>> = HashMap::new();
        let mut reps = |pd: u64| reps_of.entry(pd).or_insert_with(|| s.reps(pd)).clone();
        while let Some((pd, at, path)) = todo.pop() {
            if path.len() > MAX_DEPTH {
                return Err(self.err_at(pd, format!("assemblies nested deeper than {MAX_DEPTH} (a cycle of uses?)")));
            }
            visits += 1;
            if visits > MAX_VISITS {
                return Err(
                    self.err_at(pd, format!("the assembly's structure takes more than {MAX_VISITS} steps to walk"))
                );
            }
            let mut placed = Vec::new();
            for rep in reps(pd) {
                for item in self.rep_items(rep) {
                    self.item_shells(item, &at, 0, &shells, &mut placed, &mut visits)?;
                }
            }
            // the same shell through two representations of the product (a shape
            // representation and the B-rep's own) is one copy
            let mut seen: HashSet<(usize, [u64; 12])> = HashSet::new();
            for (k, f) in placed {
                let (o, x, y, z) = (f.o, f.x, f.y, f.z);
                let key = [o.x, o.y, o.z, x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z].map(f64::to_bits);
                if !seen.insert((k, key)) {
                    continue;
                }
                reached[k] = true;
                out.push(ShellInstance { shell: k, placement: f, path: path.clone() });
                if out.len() > MAX_INSTANCES {
                    return Err(
                        self.err_at(pd, format!("the assembly places more than {MAX_INSTANCES} copies of shells"))
                    );
                }
            }
            for &(use_id, child) in by_parent.get(&pd).into_iter().flatten().rev() {
                let child_reps = reps(child);
                let mut motion = None;
                for &shape in s.shape_of.get(&use_id).into_iter().flatten() {
                    if let Some(m) = self.use_motion(&s, shape, &child_reps)? {
                        motion = Some(m);
                        break;
                    }
                }
                // a use no motion places is drawn by mapped items of the parent, if at all
                let Some(m) = motion else { continue };
                let mut p = path.clone();
                p.push(name(use_id));
                todo.push((child, at.then_in(&m), p));
            }
        }
        for (k, r) in reached.iter().enumerate() {
            if !r {
                out.push(ShellInstance { shell: k, placement: Frame::WORLD, path: Vec::new() });
            }
        }
        Ok(out)
    }
}
