//! A z-buffer software rasterizer with smooth shading, wireframe and highlighted curves.

use super::{Image, colormap, diverging};
use pdeshape_core::Vec3;
use pdeshape_core::mesh::Mesh;

/// What to draw of one mesh.
#[derive(Clone, Debug)]
pub struct RenderItem<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Base colour (linear 0…1).
    pub color: [f32; 3],
    /// How the surface is painted.
    pub paint: Paint,
    /// Draw the mesh edges.
    pub wireframe: bool,
}

/// How a surface is painted (the zebra and isophote models are documented at [`super::View`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Paint {
    /// The item's colour, shaded.
    Color,
    /// A per-vertex field, its min…max through the sequential colour map, shaded.
    Field(String),
    /// A per-vertex field on the diverging scale `[−limit, limit]` (0 neutral), shaded.
    Diverging {
        /// The field.
        field: String,
        /// The symmetric limit (> 0).
        limit: f64,
    },
    /// Reflection lines: `stripes` black and `stripes` white tubes around the view,
    /// along the screen direction at `angle` degrees from horizontal.
    Zebra {
        /// Number of black (and of white) stripes over a half turn.
        stripes: f64,
        /// Stripe direction in the screen plane, degrees.
        angle: f64,
    },
    /// Bands of equal illumination, `2 · stripes` over the half turn of `n·l`.
    Isophotes {
        /// Number of dark (and of light) bands.
        stripes: f64,
    },
}

/// An orthographic camera looking at the centre of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Azimuth in degrees, about +z from +x.
    pub azimuth: f64,
    /// Elevation in degrees above the xy plane.
    pub elevation: f64,
    /// Zoom (> 1 zooms in).
    pub zoom: f64,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

struct View {
    center: Vec3,
    right: Vec3,
    up: Vec3,
    toward: Vec3,
    scale: f64,
    w: usize,
    h: usize,
}

impl View {
    fn project(&self, p: Vec3) -> (f64, f64, f64) {
        let d = p - self.center;
        (
            self.w as f64 / 2.0 + d.dot(self.right) * self.scale,
            self.h as f64 / 2.0 - d.dot(self.up) * self.scale,
            d.dot(self.toward),
        )
    }
}

const SS: u32 = 2;

/// Renders meshes to an image (2× supersampled). Back faces are shaded like front faces
/// (two-sided lighting), so open surfaces look right from both sides.
pub fn render(items: &[RenderItem], cam: &Camera) -> Image {
    let (w, h) = ((cam.width * SS) as usize, (cam.height * SS) as usize);
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    for it in items {
        if let Some((a, b)) = it.mesh.bounds() {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        for c in &it.mesh.curves {
            for p in c {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
    }
    if !lo.is_finite() {
        lo = Vec3::ZERO;
        hi = Vec3::new(1.0, 1.0, 1.0);
    }
    let center = (lo + hi) * 0.5;
    let (az, el) = (cam.azimuth.to_radians(), cam.elevation.to_radians());
    let toward = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let right = Vec3::new(0.0, 0.0, 1.0).cross(toward).normalized().unwrap_or(Vec3::new(0.0, 1.0, 0.0));
    let up = toward.cross(right);
    // Fit the projected bounding box.
    let mut ext: f64 = 1e-12;
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        ) - center;
        ext = ext.max((c.dot(right).abs() / w as f64).max(c.dot(up).abs() / h as f64));
    }
    let scale = 0.46 / ext * cam.zoom;
    let view = View { center, right, up, toward, scale, w, h };

    let mut color = vec![[0f32; 3]; w * h];
    for y in 0..h {
        let t = y as f32 / h as f32;
        let c = [0.97 - 0.10 * t, 0.975 - 0.08 * t, 0.98 - 0.05 * t];
        color[y * w..(y + 1) * w].fill(c);
    }
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    let light = (toward * 0.7 + up * 0.6 + right * -0.35).normalized().unwrap_or(toward);
    let fill = (toward * 0.6 + right * 0.7 - up * 0.2).normalized().unwrap_or(toward);

    for it in items {
        let m = it.mesh;
        let proj: Vec<(f64, f64, f64)> = m.positions.iter().map(|p| view.project(*p)).collect();
        let field = match &it.paint {
            Paint::Field(n) => m.field(n).map(|f| {
                let (a, b) =
                    f.values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
                (&f.values, a, if b > a { b - a } else { 1.0 }, false)
            }),
            Paint::Diverging { field, limit } => m.field(field).map(|f| (&f.values, 0.0, *limit, true)),
            _ => None,
        };
        let vcol: Vec<[f32; 3]> = (0..m.positions.len())
            .map(|i| match &field {
                Some((f, _, l, true)) => diverging(f[i] / l),
                Some((f, a, r, false)) => colormap((f[i] - a) / r),
                None => it.color,
            })
            .collect();
        let (ang_c, ang_s) = match it.paint {
            Paint::Zebra { angle, .. } => (angle.to_radians().cos(), angle.to_radians().sin()),
            _ => (1.0, 0.0),
        };
        let axis = right * ang_c + up * ang_s;
        let across = toward.cross(axis);
        for t in m.all_triangles() {
            let [a, b, c] = t.map(|i| i as usize);
            raster_triangle(&view, &mut color, &mut depth, [proj[a], proj[b], proj[c]], |l0, l1, l2| {
                let n = if m.normals.is_empty() {
                    (m.positions[b] - m.positions[a]).cross(m.positions[c] - m.positions[a])
                } else {
                    m.normals[a] * l0 + m.normals[b] * l1 + m.normals[c] * l2
                };
                let mut n = n.normalized().unwrap_or(toward);
                if n.dot(toward) < 0.0 {
                    n = -n;
                }
                let base: [f32; 3] =
                    std::array::from_fn(|k| vcol[a][k] * l0 as f32 + vcol[b][k] * l1 as f32 + vcol[c][k] * l2 as f32);
                match it.paint {
                    Paint::Zebra { stripes, .. } => {
                        // the view ray d = −toward reflected about n
                        let r = -toward + n * (2.0 * n.dot(toward));
                        let phi = r.dot(across).atan2(r.dot(toward));
                        let band = (phi / std::f64::consts::PI * stripes).floor() as i64;
                        if band.rem_euclid(2) == 0 { [0.07, 0.07, 0.09] } else { [0.96, 0.96, 0.96] }
                    }
                    Paint::Isophotes { stripes } => {
                        let angle = n.dot(light).clamp(-1.0, 1.0).acos();
                        let band = (angle / std::f64::consts::PI * 2.0 * stripes).floor() as i64;
                        let s = shade(base, n, light, fill, toward);
                        if band.rem_euclid(2) == 0 { s } else { s.map(|x| x * 0.55) }
                    }
                    _ => shade(base, n, light, fill, toward),
                }
            });
        }
        if it.wireframe {
            let edge = [0.15f32, 0.18, 0.25];
            let mut draw = |i: u32, j: u32| {
                line(&mut color, &depth, w, h, proj[i as usize], proj[j as usize], edge, 0.45, 1.0);
            };
            for q in &m.quads {
                draw(q[0], q[1]);
                draw(q[1], q[2]);
                draw(q[2], q[3]);
                draw(q[3], q[0]);
            }
            for t in &m.triangles {
                draw(t[0], t[1]);
                draw(t[1], t[2]);
                draw(t[2], t[0]);
            }
        }
        for curve in &m.curves {
            let pts: Vec<(f64, f64, f64)> = curve.iter().map(|p| view.project(*p)).collect();
            for s in pts.windows(2) {
                line(&mut color, &depth, w, h, s[0], s[1], [0.70, 0.10, 0.10], 1.0, 2.2 * SS as f64);
            }
        }
    }
    downsample(&color, w, h, cam.width, cam.height)
}

fn shade(base: [f32; 3], n: Vec3, light: Vec3, fill: Vec3, toward: Vec3) -> [f32; 3] {
    let d1 = n.dot(light).max(0.0) as f32;
    let d2 = n.dot(fill).max(0.0) as f32;
    let half = (light + toward).normalized().unwrap_or(toward);
    let spec = (n.dot(half).max(0.0) as f32).powf(40.0) * 0.35;
    std::array::from_fn(|k| (base[k] * (0.28 + 0.62 * d1 + 0.22 * d2) + spec).min(1.0))
}

fn raster_triangle(
    v: &View,
    color: &mut [[f32; 3]],
    depth: &mut [f64],
    p: [(f64, f64, f64); 3],
    shade: impl Fn(f64, f64, f64) -> [f32; 3],
) {
    let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    let xmin = p.iter().map(|q| q.0).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
    let xmax = p.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max).ceil().min(v.w as f64 - 1.0);
    let ymin = p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
    let ymax = p.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max).ceil().min(v.h as f64 - 1.0);
    if xmax < 0.0 || ymax < 0.0 {
        return;
    }
    for y in ymin..=ymax as usize {
        for x in xmin..=xmax as usize {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let w0 = ((p[1].0 - px) * (p[2].1 - py) - (p[2].0 - px) * (p[1].1 - py)) / area;
            let w1 = ((p[2].0 - px) * (p[0].1 - py) - (p[0].0 - px) * (p[2].1 - py)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9 {
                continue;
            }
            let z = w0 * p[0].2 + w1 * p[1].2 + w2 * p[2].2;
            let k = y * v.w + x;
            if z > depth[k] {
                depth[k] = z;
                color[k] = shade(w0, w1, w2);
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn line(
    color: &mut [[f32; 3]],
    depth: &[f64],
    w: usize,
    h: usize,
    a: (f64, f64, f64),
    b: (f64, f64, f64),
    rgb: [f32; 3],
    alpha: f32,
    width: f64,
) {
    let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let steps = (len * 1.5).ceil().max(1.0) as usize;
    if steps > 100_000 {
        return;
    }
    let r = (width / 2.0).max(0.5);
    // depth tolerance: lines on the surface win against their own faces
    let tol = 1e-3 * (1.0 + a.2.abs().max(b.2.abs()));
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (x, y, z) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, a.2 + (b.2 - a.2) * t);
        let (x0, x1) = ((x - r).floor() as i64, (x + r).ceil() as i64);
        let (y0, y1) = ((y - r).floor() as i64, (y + r).ceil() as i64);
        for py in y0..=y1 {
            for px in x0..=x1 {
                if px < 0 || py < 0 || px as usize >= w || py as usize >= h {
                    continue;
                }
                let d = ((px as f64 + 0.5 - x).powi(2) + (py as f64 + 0.5 - y).powi(2)).sqrt();
                if d > r {
                    continue;
                }
                let k = py as usize * w + px as usize;
                if z + tol * (1.0 + width) >= depth[k] {
                    for c in 0..3 {
                        color[k][c] += (rgb[c] - color[k][c]) * alpha;
                    }
                }
            }
        }
    }
}

fn downsample(c: &[[f32; 3]], w: usize, _h: usize, ow: u32, oh: u32) -> Image {
    let mut img = Image::new(ow, oh, [255, 255, 255]);
    let s = SS as usize;
    for y in 0..oh as usize {
        for x in 0..ow as usize {
            let mut acc = [0f32; 3];
            for dy in 0..s {
                for dx in 0..s {
                    let p = c[(y * s + dy) * w + x * s + dx];
                    for (a, q) in acc.iter_mut().zip(p) {
                        *a += q;
                    }
                }
            }
            let i = (y * ow as usize + x) * 4;
            for (d, a) in img.data[i..i + 3].iter_mut().zip(acc) {
                *d = (a / (s * s) as f32 * 255.0).round().clamp(0.0, 255.0) as u8;
            }
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the y–z plane (facing the camera at azimuth 0, elevation 0: the view
    /// direction is −x, right = +y, up = +z) whose normals are all `n`.
    fn square(n: Vec3) -> Mesh {
        let positions = vec![
            Vec3::new(0.0, -1.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(0.0, -1.0, 1.0),
        ];
        Mesh { positions, normals: vec![n; 4], quads: vec![[0, 1, 2, 3]], ..Default::default() }
    }

    fn centre(m: &Mesh, paint: Paint) -> [u8; 3] {
        let cam = Camera { azimuth: 0.0, elevation: 0.0, zoom: 1.0, width: 32, height: 32 };
        let img = render(&[RenderItem { mesh: m, color: [0.5, 0.5, 0.5], paint, wireframe: false }], &cam);
        let i = (16 * 32 + 16) * 4;
        [img.data[i], img.data[i + 1], img.data[i + 2]]
    }

    /// The zebra model (see `View`): a normal tilted by β about the stripes' axis turns the
    /// reflected ray by 2β, so the pixel shows tube ⌊2β · n/π⌋ (even black, odd white); a
    /// tilt about the perpendicular axis leaves the tube unchanged.
    #[test]
    fn zebra_stripes_follow_the_reflected_angle() {
        let (black, white) = ([18, 18, 23], [245, 245, 245]);
        let zebra = |angle: f64| Paint::Zebra { stripes: 8.0, angle };
        for (beta, want) in [(0.0f64, black), (0.1, black), (0.25, white), (0.45, black), (0.6, white)] {
            // horizontal tubes (axis = right = +y): tilt the normal up, about +y
            let n = Vec3::new(beta.cos(), 0.0, beta.sin());
            let band = (2.0 * beta / std::f64::consts::PI * 8.0).floor();
            assert_eq!(band as i64 % 2 == 0, want == black, "the table above is the formula");
            assert_eq!(centre(&square(n), zebra(0.0)), want, "β = {beta}");
            // the same tilt about the vertical axis does not change the tube of horizontal
            // stripes, but it does for vertical ones (angle 90°)
            let n = Vec3::new(beta.cos(), beta.sin(), 0.0);
            assert_eq!(centre(&square(n), zebra(0.0)), black, "β = {beta} about z");
            // (for vertical tubes, axis = up, the angle is measured towards w × up = −right)
            let n = Vec3::new(beta.cos(), -beta.sin(), 0.0);
            assert_eq!(centre(&square(n), zebra(90.0)), want, "β = {beta} about z, vertical stripes");
        }
    }

    #[test]
    fn diverging_paint_maps_the_field_symmetrically() {
        let mut m = square(Vec3::new(1.0, 0.0, 0.0));
        m.fields.push(crate::render::raster::tests::field("k", [2.0; 4]));
        let red = centre(&m, Paint::Diverging { field: "k".into(), limit: 2.0 });
        m.fields[0].values = vec![-2.0; 4];
        let blue = centre(&m, Paint::Diverging { field: "k".into(), limit: 2.0 });
        m.fields[0].values = vec![0.0; 4];
        let grey = centre(&m, Paint::Diverging { field: "k".into(), limit: 2.0 });
        assert!(red[0] > red[2] + 60, "{red:?}");
        assert!(blue[2] > blue[0] + 60, "{blue:?}");
        assert!(grey[0].abs_diff(grey[2]) < 4 && grey[0] > 150, "{grey:?}");
    }

    fn field(name: &str, v: [f64; 4]) -> pdeshape_core::mesh::ScalarField {
        pdeshape_core::mesh::ScalarField { name: name.into(), values: v.to_vec() }
    }
}
