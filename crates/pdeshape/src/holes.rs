//! `holes` and `fill-holes`: a model's free boundary listed, and filled with the new
//! faces sewn in. The input's kind is decided by its extension.

use crate::usage::Usage;
use anyhow::{Result, anyhow};
use pdeshape_core::brep::holes;
use pdeshape_core::limits::Limits;
use pdeshape_core::trimesh::{MeshLoop, boundary};
use pdeshape_io::holes::{FillHolesOptions, FilledHole, fill_holes, holes_report, write_filled};
use pdeshape_io::import::mesh::{MeshFile, MeshFormat, read_mesh};
use pdeshape_io::import::step::{StepModel, read_step_without};
use pdeshape_io::mesh_holes::{fill_mesh_holes, mesh_holes_report, mesh_view, render_trimesh, write_trimesh};
use std::path::Path;

fn is_step(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("step") || e.eq_ignore_ascii_case("stp"))
}

/// The STEP model at `path` without the faces `replace` (by `#id`).
fn load(path: &Path, replace: &[u64], limits: &Limits) -> Result<StepModel> {
    Ok(read_step_without(path, replace, limits)?)
}

/// `--replace-faces` names faces of a STEP model: a mesh has none.
fn no_faces_to_replace(path: &Path, replace: &[u64]) -> Result<()> {
    if replace.is_empty() {
        return Ok(());
    }
    Err(Usage(format!("{}: --replace-faces takes faces of a STEP model; a triangle mesh has none", path.display()))
        .into())
}

/// The kind of a model file, from its extension.
fn kind(path: &Path) -> Result<Option<MeshFormat>> {
    if is_step(path) {
        return Ok(None);
    }
    match MeshFormat::from_path(path) {
        Some(f) => Ok(Some(f)),
        None => Err(Usage(format!(
            "{}: the model must be a STEP file (.step, .stp) or a triangle mesh (.obj, .ply, .stl)",
            path.display()
        ))
        .into()),
    }
}

/// `pdeshape holes MODEL [--json] [--replace-faces ID,…]`.
pub fn list(path: &Path, json: bool, replace: &[u64], limits: &Limits) -> Result<()> {
    if kind(path)?.is_some() {
        no_faces_to_replace(path, replace)?;
        return list_mesh(path, json, limits);
    }
    let m = load(path, replace, limits)?;
    let hs = holes(&m.brep);
    let r = holes_report(&m, &hs);
    if json {
        outln!("{}", serde_json::to_string_pretty(&r)?);
        return Ok(());
    }
    outln!(
        "{}: {} shell(s), {} faces, {} edges; lengths in {}; {} loop(s) of free edges",
        r.file,
        r.shells,
        r.faces,
        r.edges,
        r.unit,
        r.holes.len()
    );
    for u in &r.unsupported {
        outln!("  not read (written back as it is): {u}");
    }
    let assembly = r.instances.len() > r.shells || r.instances.iter().any(|i| i.path.len() > 1);
    if assembly {
        outln!("an assembly: {} placed copies of the {} shell(s)", r.instances.len(), r.shells);
        for i in &r.instances {
            outln!("  shell #{} at {}: vertices in {}", i.shell, i.path.join(" / "), boxed(&i.vertex_bbox));
        }
    }
    for h in &r.holes {
        let edges: Vec<String> = h.edges.iter().map(|e| format!("#{e}")).collect();
        let faces: Vec<String> = h.faces.iter().map(|e| format!("#{e}")).collect();
        let worst = h.corners.iter().fold(0.0, |a: f64, c| pdeshape_core::num::max_nan(a, c.1));
        outln!(
            "hole {}: {}, {} edge(s) [{}], faces [{}], length {:.6}, box {}, corners {} (largest angle {:.3e} rad)",
            h.index,
            h.kind,
            h.edges.len(),
            edges.join(" "),
            faces.join(" "),
            h.length,
            boxed(&h.bbox),
            if h.g1_corners { "G1" } else { "not all G1" },
            worst
        );
        if assembly {
            for p in &h.placed {
                outln!("  in the copy at {}: box {}", r.instances[p.instance].path.join(" / "), boxed(&p.bbox));
            }
        }
    }
    Ok(())
}

/// A box as `holes` prints it: `[x, y, z] – [x, y, z]`, six decimals.
fn boxed([lo, hi]: &[[f64; 3]; 2]) -> String {
    format!("[{:.6}, {:.6}, {:.6}] – [{:.6}, {:.6}, {:.6}]", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2])
}

/// `pdeshape fill-holes MODEL -o OUT [--order 4|6] [--holes I,J | --max-edges N]
/// [--replace-faces ID,…]`.
pub fn fill(
    path: &Path,
    out: &Path,
    o: &FillHolesOptions,
    replace: &[u64],
    limits: &Limits,
    quiet: bool,
) -> Result<()> {
    if kind(path)?.is_some() {
        no_faces_to_replace(path, replace)?;
        return fill_mesh(path, out, o, limits, quiet);
    }
    if !is_step(out) {
        return Err(Usage(format!("{}: the output must be a STEP file (.step or .stp)", out.display())).into());
    }
    let m = load(path, replace, limits)?;
    let hs = holes(&m.brep);
    let filled = fill_holes(&m, &hs, o).map_err(|e| anyhow!("{}: {e}", m.file))?;
    if filled.is_empty() {
        return Err(anyhow!("{}: no hole to fill (`pdeshape holes` lists the loops)", m.file));
    }
    write_filled(&m, &hs, &filled, out).map_err(|e| anyhow!(e))?;
    if !quiet {
        // loops not asked for, or not simple holes, stay open: say so
        let r = holes_report(&m, &hs);
        for h in r.holes.iter().filter(|h| !filled.iter().any(|f| f.index == h.index)) {
            eprintln!("hole {}: left open ({}, {} edge(s))", h.index, h.kind, h.edges.len());
        }
        for line in filled_lines(&filled) {
            eprintln!("{line}");
        }
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

/// A line per filled hole: its fit and the seam measured on the written face.
pub fn filled_lines(filled: &[FilledHole]) -> Vec<String> {
    filled
        .iter()
        .map(|f| {
            let s = &f.seam;
            let g2 = if f.order == 6 {
                format!(", curvature gap {:.3e} (relative {:.3e})", s.curvature_gap, s.relative_curvature_gap)
            } else {
                String::new()
            };
            format!(
                "hole {}: order {}, {} × {} control points, measured deviation {:.3e}; seam gap {:.3e}, G1 {:.3e} rad{g2} ({} points)",
                f.index, f.order, f.fit.points.0, f.fit.points.1, f.fit.max_deviation, s.gap, s.angle, s.samples
            )
        })
        .collect()
}

fn read_checked(path: &Path, limits: &Limits) -> Result<(MeshFile, Vec<MeshLoop>)> {
    let mf = read_mesh(path, limits)?;
    let loops = boundary(&mf.mesh).map_err(|e| anyhow!("{}: {e}", mf.file))?;
    Ok((mf, loops))
}

/// `holes` on a triangle mesh.
fn list_mesh(path: &Path, json: bool, limits: &Limits) -> Result<()> {
    let (mf, loops) = read_checked(path, limits)?;
    let r = mesh_holes_report(&mf, &loops);
    if json {
        outln!("{}", serde_json::to_string_pretty(&r)?);
        return Ok(());
    }
    outln!(
        "{}: {} mesh, {} vertices, {} triangles{}; dihedral angles' 99th percentile {:.3e} rad; {} boundary loop(s)",
        r.file,
        r.format,
        r.vertices,
        r.triangles,
        if r.polygons_split > 0 { format!(" ({} polygons split)", r.polygons_split) } else { String::new() },
        r.dihedral_p99,
        r.holes.len()
    );
    for h in &r.holes {
        outln!(
            "hole {}: {} (facing {:+.2}), {} edges from vertex {}, length {:.6}, box [{:.6}, {:.6}, {:.6}] – [{:.6}, {:.6}, {:.6}]",
            h.index,
            h.kind,
            h.facing,
            h.edges,
            h.first_vertex,
            h.length,
            h.bbox[0][0],
            h.bbox[0][1],
            h.bbox[0][2],
            h.bbox[1][0],
            h.bbox[1][1],
            h.bbox[1][2]
        );
    }
    Ok(())
}

/// `fill-holes` on a triangle mesh.
fn fill_mesh(path: &Path, out: &Path, o: &FillHolesOptions, limits: &Limits, quiet: bool) -> Result<()> {
    if MeshFormat::from_path(out).is_none() {
        return Err(Usage(format!("{}: the output of a mesh must be .obj, .ply or .stl", out.display())).into());
    }
    let (mf, loops) = read_checked(path, limits)?;
    let (filled, reports) = fill_mesh_holes(&mf, &loops, o, limits).map_err(|e| anyhow!("{}: {e}", mf.file))?;
    if reports.is_empty() {
        return Err(anyhow!("{}: no hole to fill (`pdeshape holes` lists the loops)", mf.file));
    }
    write_trimesh(out, &filled).map_err(|e| anyhow!(e))?;
    if !quiet {
        let r = mesh_holes_report(&mf, &loops);
        for h in r.holes.iter().filter(|h| !reports.iter().any(|f| f.index == h.index)) {
            eprintln!("hole {}: left open ({}, {} edges)", h.index, h.kind, h.edges);
        }
        for f in &reports {
            let g2 = if o.order == 6 { format!(", curvature gap {:.3e}", f.g2) } else { String::new() };
            let shape = match (f.mu, f.height) {
                (Some(mu), _) => format!("disc fill, fullness {:.3}, μ {mu:.3}", f.fullness),
                (_, Some(h)) => format!("strip fill, fullness {:.3}, pole height {h:.3}", f.fullness),
                _ => String::new(),
            };
            eprintln!(
                "hole {}: order {}, {} new vertices, {} new triangles; collar fit rms {:.3e}, max {:.3e} ({} vertices, smoothing {:.1e}, {:.1} effective unknowns); fill to collar G1 {:.3e} rad, gap {:.3e}{g2}; {shape} (Willmore energy {:.4e}); seam dihedral {:.3e} rad (the mesh's 99th percentile {:.3e}); new edges {:.2}–{:.2} × the local median",
                f.index,
                o.order,
                f.new_vertices,
                f.new_triangles,
                f.collar_rms,
                f.collar_max,
                f.collar_points,
                f.collar_smoothing,
                f.collar_dof,
                f.g1,
                f.gap,
                f.willmore,
                f.seam_dihedral,
                r.dihedral_p99,
                f.edge_ratio.0,
                f.edge_ratio.1
            );
        }
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

/// `render` on a triangle mesh file.
pub fn render_mesh(
    path: &Path,
    r: &pdeshape_io::scene::RenderSettings,
    limits: &Limits,
) -> Result<pdeshape_io::render::Image> {
    // a usage error, before the file is read
    mesh_view(r.view).map_err(|e| Usage(format!("{}: {e}", path.display())))?;
    let mf = read_mesh(path, limits)?;
    render_trimesh(&mf.mesh, r).map_err(|e| anyhow!("{}: {e}", mf.file))
}
