// The editor's camera: an orbit (azimuth, elevation, distance) about a target, z up; its
// view and projection matrices (column-major, as WebGL takes them) and screen projection.
// Small 3-vectors as arrays.

export const cam = { az: 0.6, el: 0.45, dist: 10, target: [0, 0, 0], fov: 0.8 };
export function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
export function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
export function scl(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
export function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
export function crs(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
export function nrm(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return scl(a, 1 / l); }
export function eye() {
  const d = [Math.cos(cam.el) * Math.cos(cam.az), Math.cos(cam.el) * Math.sin(cam.az), Math.sin(cam.el)];
  return add(cam.target, scl(d, cam.dist));
}
export function basis() {
  const f = nrm(sub(cam.target, eye()));
  const r = nrm(crs(f, [0, 0, 1]));
  const u = crs(r, f);
  return { f, r, u };
}
export function matrices(w, h) {
  const e = eye(), { f, r, u } = basis();
  const view = [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
    -dot(r, e), -dot(u, e), dot(f, e), 1];
  const near = cam.dist / 100, far = cam.dist * 100, t = 1 / Math.tan(cam.fov / 2), a = w / h;
  const proj = [t / a, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, 2 * far * near / (near - far), 0];
  return { view, proj };
}
export function mul4(a, b) { // column-major a*b
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}
export function project(p, w, h) {
  const { view, proj } = matrices(w, h);
  const m = mul4(proj, view);
  const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
  const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
  const ww = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
  return [(x / ww * 0.5 + 0.5) * w, (1 - (y / ww * 0.5 + 0.5)) * h, ww];
}
