//! `pdeshape sample`: exact points of a patch (or a solid) at the parameters read from
//! stdin as CSV (`u,v` or `u,v,w`), written as CSV.

use crate::clip::clip;
use anyhow::{Context, Result, anyhow, bail};
use pdeshape_io::scene::Scene;
use std::io::{BufRead, Write};

/// Runs `sample` on a loaded scene: the named patch (or the first), at time `time`.
/// `surface-NAME` (the name of a primary surface's face in a STEP export) samples the drawn
/// part of the primary surface NAME in that face's parameters: `u ∈ [0, 1]` across its
/// `s_range`, `v` its own.
pub fn command(sc: &Scene, patch: Option<&str>, time: Option<f64>, quiet: bool) -> Result<()> {
    if let Some(name) = patch.and_then(|n| n.strip_prefix("surface-"))
        && sc.patch(patch.unwrap_or_default()).is_none()
        && let Some(s) = sc.surfaces.iter().find(|s| s.name == name)
    {
        let range = s.s_range.ok_or_else(|| {
            anyhow!("surface `{}` has no s_range: it is not drawn, so it has no face to sample", clip(name, 60))
        })?;
        let ps = pdeshape_core::patch::PrimarySurface::new(s.field.clone(), range, s.domain, time.unwrap_or(0.0));
        return sample(&ps);
    }
    let p = match patch {
        Some(n) => sc.patch(n).ok_or_else(|| {
            anyhow!(
                "no patch named `{}` in {} (patches: {})",
                clip(n, 60),
                sc.file,
                sc.patches.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
            )
        })?,
        None => sc.patches.first().ok_or_else(|| anyhow!("the scene {} has no patches", sc.file))?,
    };
    if let Some(t) = time
        && t != 0.0
        && p.dynamic.is_none()
        && !quiet
    {
        eprintln!("note: patch `{}` is not a dynamic blend: --time does not change it", p.name);
    }
    match (&p.dynamic, time, &p.solid) {
        (_, _, Some(sd)) => sample_solid(&sd.blend),
        (Some(d), Some(t), _) => {
            let f = d.blend.frame(t).map_err(|e| anyhow!("patch `{}` at t = {t}: {e}", p.name))?;
            sample(&f)
        }
        _ => sample(p.surface.as_ref()),
    }
}

/// Rows handed to the writer at once (the patch is evaluated a block at a time).
const BLOCK: usize = 1024;

/// Reads CSV rows of `N` finite numbers from stdin and writes `header` then one line per
/// row from `f`, which gets the rows in blocks of up to [`BLOCK`] with their line numbers
/// (the rows before a bad line are written before its error); errors name the line. Blank lines and `#` comments are skipped, and so is
/// a first line that is literally the column names (`u,v` or `u,v,w`, spaces allowed); a
/// UTF-8 byte-order mark is dropped. Any other line that is not `N` numbers is an error.
fn sample_rows<const N: usize>(
    header: &str,
    mut f: impl FnMut(&[(usize, [f64; N])], &mut dyn Write) -> Result<()>,
) -> Result<()> {
    let mut block: Vec<(usize, [f64; N])> = Vec::with_capacity(BLOCK);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let read = read_rows(header, &mut out, |row, out| {
        block.push(row);
        if block.len() == BLOCK {
            f(&block, out)?;
            block.clear();
        }
        Ok(())
    });
    // the rows read before an error are written, then the error
    f(&block, &mut out)?;
    read?;
    out.flush()?;
    Ok(())
}

/// The reading half of [`sample_rows`]: each valid row to `f`.
fn read_rows<const N: usize>(
    header: &str,
    out: &mut dyn Write,
    mut f: impl FnMut((usize, [f64; N]), &mut dyn Write) -> Result<()>,
) -> Result<()> {
    let names = header.split(',').take(N).collect::<Vec<_>>().join(",");
    let stdin = std::io::stdin();
    writeln!(out, "{header}")?;
    let mut first = true;
    for (ln, line) in stdin.lock().lines().enumerate() {
        let line = line.with_context(|| format!("cannot read stdin line {}", ln + 1))?;
        let l = if ln == 0 { line.trim_start_matches('\u{feff}') } else { &line }.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = l.split(',').map(|c| c.trim()).collect();
        if std::mem::take(&mut first) && cols.join(",") == names {
            continue; // the header
        }
        if cols.len() != N {
            bail!("stdin line {}: expected {N} columns `{names}`, got {}: {:?}", ln + 1, cols.len(), clip(l, 80));
        }
        let mut vals = [0.0f64; N];
        for (k, c) in cols.iter().enumerate() {
            vals[k] = c.parse().map_err(|_| anyhow!("stdin line {}: `{}` is not a number", ln + 1, clip(c, 40)))?;
            if !vals[k].is_finite() {
                bail!("stdin line {}: `{c}` is not finite", ln + 1);
            }
        }
        f((ln + 1, vals), out)?;
    }
    Ok(())
}

/// `u,v,w` from stdin to `u,v,w,x,y,z` for a solid blend.
fn sample_solid(s: &pdeshape_core::solid::SolidBlend) -> Result<()> {
    sample_rows("u,v,w,x,y,z", |rows, out| {
        for &(ln, [u, v, w]) in rows {
            for (name, x) in [("u", u), ("v", v), ("w", w)] {
                if !(0.0..=1.0).contains(&x) {
                    bail!("stdin line {ln}: {name} = {x} is outside [0, 1]");
                }
            }
            let x = s.point(u, v, w);
            if !x.is_finite() {
                bail!("stdin line {ln}: the solid is not finite at (u, v, w) = ({u}, {v}, {w})");
            }
            writeln!(out, "{u:.17e},{v:.17e},{w:.17e},{:.17e},{:.17e},{:.17e}", x.x, x.y, x.z)?;
        }
        Ok(())
    })
}

/// `u,v` from stdin to `u,v,x,y,z` for a patch.
fn sample(surface: &dyn pdeshape_core::patch::Surface) -> Result<()> {
    let dom = surface.v_domain();
    let mut pts = Vec::with_capacity(BLOCK);
    sample_rows("u,v,x,y,z", |rows, out| {
        // the rows up to the first out of range are evaluated in one batch (the call
        // `Patch.evaluate` makes, so the numbers are the same bit for bit)
        let bad = rows.iter().position(|&(_, [u, v])| {
            !(0.0..=1.0).contains(&u) || (!dom.periodic && !(dom.start..=dom.end).contains(&v))
        });
        let good = &rows[..bad.unwrap_or(rows.len())];
        let uv: Vec<[f64; 2]> = good.iter().map(|r| r.1).collect();
        pts.resize(uv.len(), pdeshape_core::Vec3::ZERO);
        surface.points_at(&uv, &mut pts);
        for (&(ln, [u, v]), x) in good.iter().zip(&pts) {
            if !x.is_finite() {
                bail!("stdin line {ln}: the patch is not finite at (u, v) = ({u}, {v})");
            }
            writeln!(out, "{u:.17e},{v:.17e},{:.17e},{:.17e},{:.17e}", x.x, x.y, x.z)?;
        }
        if let Some(&(ln, [u, v])) = bad.map(|k| &rows[k]) {
            if !(0.0..=1.0).contains(&u) {
                bail!("stdin line {ln}: u = {u} is outside [0, 1]");
            }
            bail!("stdin line {ln}: v = {v} is outside [{}, {}]", dom.start, dom.end);
        }
        Ok(())
    })
}
