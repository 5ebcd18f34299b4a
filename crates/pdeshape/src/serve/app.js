// pdeshape editor: WebGL2 view (shading, zebra, isophotes, curvature maps, seams), parameter
// sliders, handles, trim editor, diagnostics.
// State exposed for tests as window.pdeshape. An ES module (strict); the wire format is
// read by wire.js.
import * as wire from "/wire.js";
import { cam, sub, add, scl, dot, crs, nrm, eye, basis, matrices, mul4, project } from "/camera.js";
import { canvas, gl, program, surf, flat, seamProg } from "/views.js";

const S = window.pdeshape = {
  frames: 0, vertexCount: 0, lastError: null, diagnostics: null,
  lastDownload: null, requests: 0, header: null,
  // the hash of the buffers as received, computed when first asked for
  data: null, dataHash: null,
  get meshHash() { return this.data ? (this.dataHash ??= wire.bytesHash(this.data)) : ""; },
};
const $ = (id) => document.getElementById(id);
let scene = { name: "scene", text: "" };
let params = {};          // name -> value
let time = null;
let model = null;         // { header, gl buffers per patch }
let pending = false, inflight = false, wantDiag = false;
// after a 503 (time limit) or 429 (queue full) the next request waits: 1 s, doubling to
// 30 s, cleared by the next answer; a slow scene then cannot be re-sent in a loop
let backoff = 0;
S.busy = () => inflight || pending;
S.backoff = () => backoff;

function upload(header, bytes) {
  const f32 = (r) => wire.f32(bytes, r);
  const u32 = (r) => wire.u32(bytes, r);
  const patches = header.patches.map((p) => {
    const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
    const buf = (data, loc, size) => {
      const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0); return b;
    };
    buf(f32(p.positions), 0, 3); buf(f32(p.normals), 1, 3);
    const fieldBuf = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, fieldBuf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(p.vertices), gl.DYNAMIC_DRAW);
    gl.enableVertexAttribArray(2); gl.vertexAttribPointer(2, 1, gl.FLOAT, false, 0, 0);
    const ib = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, u32(p.indices), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    const lvao = gl.createVertexArray(); gl.bindVertexArray(lvao);
    buf(f32(p.positions), 0, 3);
    const lb = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, lb); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, u32(p.lines), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    const curves = p.curves.map((c) => {
      const v = gl.createVertexArray(); gl.bindVertexArray(v); buf(f32(c), 0, 3); gl.bindVertexArray(null);
      return { vao: v, n: c.count / 3 };
    });
    const fields = {};
    for (const fl of p.fields) fields[fl.name] = f32(fl);
    return { vao, lvao, fieldBuf, n: p.indices.count, nl: p.lines.count, curves, fields, meta: p,
      pos: f32(p.positions).slice() };
  });
  return patches;
}
// the imported models' faces (drawn in a neutral colour around the patches) and holes
// (orange loops; a click on one adds a fill of it to the scene)
function uploadContext(header, bytes) {
  const f32 = (r) => wire.f32(bytes, r), u32 = (r) => wire.u32(bytes, r);
  const buf = (data, loc, size) => {
    const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
  };
  const faces = (header.context || []).map((m) => {
    const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
    buf(f32(m.positions), 0, 3); buf(f32(m.normals), 1, 3); buf(new Float32Array(m.vertices), 2, 1);
    const ib = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, u32(m.indices), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    return { vao, n: m.indices.count, meta: m, pos: f32(m.positions).slice(), idx: u32(m.indices).slice() };
  });
  const holes = (header.holes || []).map((h) => {
    const vao = gl.createVertexArray(); gl.bindVertexArray(vao); buf(f32(h.points), 0, 3); gl.bindVertexArray(null);
    return { vao, n: h.points.count / 3, name: h.name, pos: f32(h.points).slice() };
  });
  return { faces, holes };
}
function bounds(patches) {
  let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const p of patches) for (let i = 0; i < p.pos.length; i += 3)
    for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p.pos[i + k]); hi[k] = Math.max(hi[k], p.pos[i + k]); }
  return { lo, hi };
}
let handleVao = null, handleCount = 0;
function uploadHandles() {
  const h = model ? model.header.editables.handles : [];
  const data = new Float32Array(h.flatMap((x) => x.position));
  if (!handleVao) handleVao = gl.createVertexArray();
  gl.bindVertexArray(handleVao);
  const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
  gl.bindVertexArray(null); handleCount = h.length;
}
const PALETTE = [[0.36, 0.55, 0.85], [0.86, 0.55, 0.3], [0.45, 0.72, 0.45], [0.75, 0.45, 0.72], [0.8, 0.75, 0.35]];
function draw() {
  const w = canvas.clientWidth * devicePixelRatio, h = canvas.clientHeight * devicePixelRatio;
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  gl.viewport(0, 0, w, h); gl.clearColor(0.93, 0.95, 0.98, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  if (!model) return;
  const { view, proj } = matrices(w, h);
  const field = $("field").value, scale = colourScale();
  gl.useProgram(surf);
  gl.uniformMatrix4fv(gl.getUniformLocation(surf, "view"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(surf, "proj"), false, proj);
  const ang = parseFloat($("stripeangle").value) * Math.PI / 180;
  gl.uniform1f(gl.getUniformLocation(surf, "stripes"), parseFloat($("stripes").value));
  gl.uniform2f(gl.getUniformLocation(surf, "axis"), Math.cos(ang), Math.sin(ang));
  for (const f of model.context.faces) {
    gl.uniform3fv(gl.getUniformLocation(surf, "color"), [0.74, 0.74, 0.72]);
    gl.uniform1i(gl.getUniformLocation(surf, "mode"), field === "zebra" ? 3 : field === "isophotes" ? 4 : 0);
    gl.bindVertexArray(f.vao); gl.drawElements(gl.TRIANGLES, f.n, gl.UNSIGNED_INT, 0);
  }
  model.patches.forEach((p, i) => {
    const c = p.meta.color || PALETTE[i % PALETTE.length];
    gl.uniform3fv(gl.getUniformLocation(surf, "color"), c);
    const fv = scale && p.fields[field];
    const mode = field === "zebra" ? 3 : field === "isophotes" ? 4 : !fv ? 0 : scale.diverging ? 2 : 1;
    gl.uniform1i(gl.getUniformLocation(surf, "mode"), mode);
    if (fv) {
      gl.uniform2f(gl.getUniformLocation(surf, "range"), scale.lo, scale.hi);
      gl.bindBuffer(gl.ARRAY_BUFFER, p.fieldBuf); gl.bufferData(gl.ARRAY_BUFFER, fv, gl.DYNAMIC_DRAW);
    }
    gl.bindVertexArray(p.vao); gl.drawElements(gl.TRIANGLES, p.n, gl.UNSIGNED_INT, 0);
  });
  drawSeams(view, proj);
  drawCurves(view, proj);
  gl.useProgram(flat);
  gl.uniformMatrix4fv(gl.getUniformLocation(flat, "view"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(flat, "proj"), false, proj);
  if ($("wire").checked) {
    gl.uniform4f(gl.getUniformLocation(flat, "color"), 0.1, 0.15, 0.25, 0.6);
    for (const p of model.patches) { gl.bindVertexArray(p.lvao); gl.drawElements(gl.LINES, p.nl, gl.UNSIGNED_INT, 0); }
  }
  gl.uniform4f(gl.getUniformLocation(flat, "color"), 0.8, 0.1, 0.1, 1);
  for (const p of model.patches) for (const c of p.curves) { gl.bindVertexArray(c.vao); gl.drawArrays(gl.LINE_STRIP, 0, c.n); }
  gl.uniform4f(gl.getUniformLocation(flat, "color"), 0.95, 0.55, 0.05, 1);
  for (const h of model.context.holes) { gl.bindVertexArray(h.vao); gl.drawArrays(gl.LINE_STRIP, 0, h.n); }
  if ($("handles").checked && handleCount) {
    gl.disable(gl.DEPTH_TEST);
    gl.uniform1f(gl.getUniformLocation(flat, "size"), 9 * devicePixelRatio);
    gl.uniform4f(gl.getUniformLocation(flat, "color"), 0.95, 0.6, 0.05, 1);
    gl.bindVertexArray(handleVao); gl.drawArrays(gl.POINTS, 0, handleCount);
  }
  gl.bindVertexArray(null);
  S.frames++;
  S.view = field || "shading";
}
let drawQueued = false;
function redraw() { if (!drawQueued) { drawQueued = true; requestAnimationFrame(() => { drawQueued = false; draw(); }); } }

// ---------------- analysis: colour scales, legend, seams ----------------
const CURVATURES = { gaussian_curvature: "Gaussian curvature K", mean_curvature: "mean curvature H",
  k1: "principal curvature k1 (min)", k2: "principal curvature k2 (max)" };
const VIEW_LABELS = { zebra: "zebra (reflection lines)", isophotes: "isophotes", ...CURVATURES };
// the q-quantile of |x| over the finite values of some arrays (NaN when there are none)
function absQuantile(arrays, q) {
  const a = [];
  for (const xs of arrays) for (const x of xs) if (Number.isFinite(x)) a.push(Math.abs(x));
  if (!a.length) return NaN;
  a.sort((x, y) => x - y);
  return a[Math.round((a.length - 1) * q)];
}
// The colour scale of the chosen field: curvatures on a diverging scale ±L (L the 95th
// percentile of |value| over every patch, or the user's), other fields min…max.
let scaleCache = null;
function colourScale() {
  const field = $("field").value;
  if (!model || !field || field === "zebra" || field === "isophotes") return null;
  const arrays = model.patches.map((p) => p.fields[field]).filter((x) => x);
  if (!arrays.length) return null;
  const key = `${field}|${S.meshHash}|${$("cauto").checked}|${$("climit").value}`;
  if (scaleCache && scaleCache.key === key) return scaleCache.scale;
  let scale;
  if (CURVATURES[field]) {
    let L = parseFloat($("climit").value);
    if ($("cauto").checked || !(L > 0)) {
      L = absQuantile(arrays, 0.95);
      if (!(L > 0)) L = 1;
      $("climit").value = Number(L.toPrecision(4));
    }
    scale = { diverging: true, lo: -L, hi: L };
  } else {
    let lo = Infinity, hi = -Infinity;
    for (const xs of arrays) for (const x of xs) if (Number.isFinite(x)) { lo = Math.min(lo, x); hi = Math.max(hi, x); }
    scale = { diverging: false, lo, hi };
  }
  scaleCache = { key, scale };
  return scale;
}
function fmt(x) { return Number.isFinite(x) ? (x === 0 ? "0" : x.toExponential(3)) : String(x); }
function updateLegend() {
  const field = $("field").value, scale = colourScale(), lg = $("legend");
  $("stripebox").style.display = field === "zebra" || field === "isophotes" ? "block" : "none";
  $("scalebox").style.display = CURVATURES[field] ? "block" : "none";
  $("stripesval").textContent = $("stripes").value; $("angleval").textContent = `${$("stripeangle").value}°`;
  if (!scale) { lg.style.display = "none"; S.legend = null; return; }
  lg.style.display = "block";
  $("legendtitle").textContent = CURVATURES[field] || field;
  const stops = scale.diverging
    ? ["#3b4cc0", "#8db0fe", "#dddddd", "#f49a7b", "#b40426"]
    : ["#000080", "#0000ff", "#00ffff", "#ffff00", "#ff0000", "#800000"];
  $("legendbar").style.background = `linear-gradient(to right, ${stops.join(", ")})`;
  const mid = scale.diverging ? 0 : (scale.lo + scale.hi) / 2;
  $("legendlo").textContent = fmt(scale.lo); $("legendmid").textContent = fmt(mid); $("legendhi").textContent = fmt(scale.hi);
  S.legend = { title: $("legendtitle").textContent, lo: scale.lo, mid, hi: scale.hi };
}
// Seams: the rows of the seam ends the server lists (both trimlines of a blend, the ends of
// a patch attached to another's trim curve), coloured by a
// continuity field (green at round-off, 1e-12, through yellow to red at 1e-1 and above,
// on a log scale); the worst place per patch from check's diagnostics, marked and listed.
const SEAM_KEYS = { g1_angle: ["g1_radians", "G1 angle", " rad"], c0_gap: ["c0", "C0 gap", ""],
  c1_gap: ["c1", "C1 gap", ""], c2_gap: ["c2", "C2 gap", ""], g2_gap: ["g2", "G2 gap", ""] };
function seamColour(x) {
  const t = Math.min(1, Math.max(0, (Math.log10(Math.max(x, 1e-300)) + 12) / 11));
  return t < 0.5 ? [2 * t, 0.75, 0.1] : [1, 0.75 * (2 - 2 * t), 0.1];
}
let seamVaos = [], markerVao = null, markerCount = 0;
function buildSeams() {
  for (const s of seamVaos) gl.deleteVertexArray(s.vao);
  seamVaos = [];
  const key = $("seam").value;
  S.seams = [];
  if (!model || !key) { buildMarkers(); return; }
  for (const p of model.patches) {
    const f = p.fields[key], g = p.meta.grid;
    if (!f || !g) continue;
    const [nu, nv] = g;
    for (const i of (p.meta.seams || []).map((u) => Math.round(u * (nu - 1)))) {
      const pos = new Float32Array(nv * 3), col = new Float32Array(nv * 3);
      let worst = -Infinity;
      for (let j = 0; j < nv; j++) {
        const k = i * nv + j;
        pos.set(p.pos.subarray(3 * k, 3 * k + 3), 3 * j);
        col.set(seamColour(f[k]), 3 * j);
        worst = Math.max(worst, f[k]);
      }
      const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
      for (const [data, loc] of [[pos, 0], [col, 1]]) {
        const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
        gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      }
      gl.bindVertexArray(null);
      seamVaos.push({ vao, n: nv });
      S.seams.push({ patch: p.meta.name, u: i / (nu - 1), field: key, max: worst });
    }
  }
  buildMarkers();
}
function buildMarkers() {
  const key = $("seam").value, box = $("seams");
  box.innerHTML = ""; S.seamMarkers = [];
  const d = S.diagnostics;
  if (model && key && d && d.patches) {
    const [dk, label, unit] = SEAM_KEYS[key];
    for (const p of d.patches) {
      const w = p.continuity && p.continuity.worst && p.continuity.worst[dk];
      if (!w) continue;
      const m = { patch: p.name, measure: dk, value: w.value, u: w.u, v: w.v, point: w.point };
      S.seamMarkers.push(m);
      const row = document.createElement("div");
      row.innerHTML = `<button data-seam="${S.seamMarkers.length - 1}">show</button> ${p.name}: worst ${label} ${fmt(w.value)}${unit} at u = ${w.u}, v = ${w.v.toFixed(4)}`;
      row.querySelector("button").onclick = () => flyTo(m.point);
      box.appendChild(row);
    }
  }
  $("seambox").style.display = S.seamMarkers.length || seamVaos.length ? "block" : "none";
  const data = new Float32Array(S.seamMarkers.flatMap((m) => m.point));
  const col = new Float32Array(S.seamMarkers.flatMap(() => [0.85, 0.1, 0.85]));
  if (!markerVao) markerVao = gl.createVertexArray();
  gl.bindVertexArray(markerVao);
  for (const [arr, loc] of [[data, 0], [col, 1]]) {
    const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, arr, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  }
  gl.bindVertexArray(null); markerCount = S.seamMarkers.length;
}
function drawSeams(view, proj) {
  if (!seamVaos.length && !markerCount) return;
  gl.useProgram(seamProg);
  gl.uniformMatrix4fv(gl.getUniformLocation(seamProg, "view"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(seamProg, "proj"), false, proj);
  gl.uniform1f(gl.getUniformLocation(seamProg, "size"), 4 * devicePixelRatio);
  for (const s of seamVaos) {
    gl.bindVertexArray(s.vao); gl.drawArrays(gl.LINE_STRIP, 0, s.n); gl.drawArrays(gl.POINTS, 0, s.n);
  }
  if (markerCount) {
    gl.disable(gl.DEPTH_TEST);
    gl.uniform1f(gl.getUniformLocation(seamProg, "size"), 13 * devicePixelRatio);
    gl.bindVertexArray(markerVao); gl.drawArrays(gl.POINTS, 0, markerCount);
    gl.enable(gl.DEPTH_TEST);
  }
}
// moves the camera's target to `p` and closes in, over ~0.4 s
function flyTo(p) {
  const b = bounds(model.patches.concat(model.context.faces));
  const dist = 0.45 * Math.hypot(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]);
  const from = { target: cam.target.slice(), dist: cam.dist }, t0 = performance.now();
  S.flying = true;
  const step = () => {
    const f = Math.min(1, (performance.now() - t0) / 400), e = f * f * (3 - 2 * f);
    cam.target = from.target.map((x, k) => x + (p[k] - x) * e);
    cam.dist = from.dist + (dist - from.dist) * e;
    draw();
    if (f < 1) requestAnimationFrame(step); else S.flying = false;
  };
  requestAnimationFrame(step);
}
S.cam = cam;
S.flyTo = flyTo;

// ---------------- curves: plane section and curvature combs ----------------
// The server computes them on the exact surface (points and curvature vectors, which point
// to the centre of curvature); the teeth of a comb are drawn away from it, p − s k, with s
// set so the 95th percentile of |k| gets `comb length` × a quarter of the model's size.
function curvesRequest() {
  const on = $("section").checked || $("combs").checked || $("isocomb").checked;
  if (!on || !model) return undefined;
  const b = bounds(model.patches.concat(model.context.faces)), k = "xyz".indexOf($("secaxis").value);
  const offset = b.lo[k] + parseFloat($("secpos").value) * (b.hi[k] - b.lo[k]);
  $("secval").textContent = offset.toFixed(3);
  return {
    section: $("section").checked ? { axis: $("secaxis").value, offset } : undefined,
    combs: $("combs").checked,
    iso_u: $("isocomb").checked ? parseFloat($("isou").value) : undefined,
  };
}
let curveVao = null, curveCount = 0;
function buildCurves() {
  const c = model && model.header.curves;
  S.curves = null;
  if (!c) { curveCount = 0; return; }
  const b = bounds(model.patches.concat(model.context.faces));
  const size = Math.hypot(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]);
  const norms = [];
  const kn = (k, i) => Math.hypot(k[i], k[i + 1], k[i + 2]);
  for (const p of c) {
    for (const s of p.section || []) for (const i of [3, 9]) if (s[i] !== null) norms.push(kn(s, i));
    for (const m of p.combs || []) for (let i = 0; i < m.curvature.length; i += 3) if (m.curvature[i] !== null) norms.push(kn(m.curvature, i));
  }
  const kref = absQuantile([norms], 0.95) || 1;
  const scale = parseFloat($("combscale").value) * 0.25 * size / kref;
  const pos = [], col = [];
  const line = (a, b, c) => { pos.push(...a, ...b); col.push(...c, ...c); };
  const tip = (p, k) => [p[0] - scale * k[0], p[1] - scale * k[1], p[2] - scale * k[2]];
  const heat = (k) => { const t = Math.min(1, Math.hypot(...k) / kref); return [0.1 + 0.9 * t, 0.25, 1 - 0.8 * t]; };
  let segments = 0, teeth = 0, combs = 0;
  for (const p of c) {
    for (const s of p.section || []) {
      const [a, ka, q, kq] = [s.slice(0, 3), s.slice(3, 6), s.slice(6, 9), s.slice(9, 12)];
      const ok = ka[0] !== null && kq[0] !== null;
      line(a, q, ok ? heat(ka) : [0.5, 0.5, 0.5]); segments++;
      if (ok) { line(a, tip(a, ka), [0.35, 0.35, 0.45]); teeth++; }
    }
    for (const m of p.combs || []) {
      combs++;
      let prevTip = null;
      for (let i = 0; i + 3 <= m.points.length; i += 3) {
        const a = m.points.slice(i, i + 3), k = m.curvature.slice(i, i + 3);
        if (i + 6 <= m.points.length) line(a, m.points.slice(i + 3, i + 6), [0.1, 0.1, 0.1]);
        if (k[0] === null) { prevTip = null; continue; }
        const t = tip(a, k);
        if ((i / 3) % 2 === 0) { line(a, t, [0.2, 0.45, 0.85]); teeth++; }
        if (prevTip) line(prevTip, t, [0.85, 0.3, 0.1]);
        prevTip = t;
      }
    }
  }
  if (!curveVao) curveVao = gl.createVertexArray();
  gl.bindVertexArray(curveVao);
  for (const [arr, loc] of [[new Float32Array(pos), 0], [new Float32Array(col), 1]]) {
    const buf = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf); gl.bufferData(gl.ARRAY_BUFFER, arr, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  }
  gl.bindVertexArray(null);
  curveCount = pos.length / 3;
  S.curves = { segments, teeth, combs, kref };
}
function drawCurves(view, proj) {
  if (!curveCount) return;
  gl.useProgram(seamProg);
  gl.uniformMatrix4fv(gl.getUniformLocation(seamProg, "view"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(seamProg, "proj"), false, proj);
  gl.disable(gl.DEPTH_TEST);
  gl.bindVertexArray(curveVao); gl.drawArrays(gl.LINES, 0, curveCount);
  gl.enable(gl.DEPTH_TEST);
}
for (const id of ["section", "secaxis", "secpos", "combs", "isocomb", "isou"]) {
  $(id).addEventListener(id === "secpos" || id === "isou" ? "input" : "change", () => {
    $("isouval").textContent = $("isou").value; changed();
  });
}
$("combscale").addEventListener("input", () => { buildCurves(); redraw(); });

// ---------------- server ----------------
let edits = [];            // edits not yet folded into scene.text
function showError(msg) {
  S.lastError = msg; const e = $("error");
  e.style.display = msg ? "block" : "none"; e.textContent = msg || "";
}
async function solve(diagnostics) {
  if (inflight) { pending = true; wantDiag ||= diagnostics; return; }
  inflight = true;
  const body = { text: scene.text, name: scene.name, params, edits, time, diagnostics, curves: curvesRequest() };
  const sent = edits; S.requests++;
  const t0 = performance.now();
  try {
    const r = await fetch("/api/model", { method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body) });
    if (!r.ok) {
      if (r.status === 503 || r.status === 429) backoff = Math.min(30000, Math.max(1000, 2 * backoff));
      const e = await r.json().catch(() => ({ error: r.statusText }));
      showError(e.error);   // the edit is kept in the editor and shown as invalid, the model is not replaced
    } else {
      backoff = 0;
      const { header, data } = wire.decode(await r.arrayBuffer());
      const first = !model;
      if (edits === sent) { scene.text = header.text; edits = []; }
      if (model) for (const f of model.context.faces) gl.deleteVertexArray(f.vao);
      model = { header, patches: upload(header, data), context: uploadContext(header, data) };
      S.contextFaces = model.context.faces.map((f) => f.meta.name);
      S.holes = model.context.holes.map((h) => h.name);
      S.header = header; S.data = data; S.dataHash = null;
      S.vertexCount = header.patches.reduce((a, p) => a + p.vertices, 0);
      // the diagnostics (and the seam markers from them) belong to the model they came with
      S.diagnostics = header.diagnostics || null;
      if (header.diagnostics) $("diag").textContent = summary(header.diagnostics);
      showError(null);
      if (first) { fit(); buildPanel(header); }
      syncPanel(header); uploadHandles(); drawTrim(); buildSeams(); buildCurves(); updateLegend(); redraw();
      S.updates = (S.updates || 0) + 1;
      // request to drawn-buffers time and the server's share, for the live-update figure
      (S.timings ||= []).push({ total: performance.now() - t0, server: header.solve_ms });
      $("status").textContent = `${header.title || header.name}: ${S.vertexCount} vertices, solved in ${header.solve_ms.toFixed(1)} ms, hash ${header.hash}`;
    }
  } catch (e) { showError(String(e)); }
  inflight = false;
  if (pending) {
    pending = false; const d = wantDiag; wantDiag = false;
    if (backoff) { inflight = true; setTimeout(() => { inflight = false; solve(d); }, backoff); }
    else solve(d);
  }
}
function summary(d) {
  const lines = [];
  for (const p of d.patches) {
    lines.push(`${p.name} (${p.kind}, ${p.solver}): max condition error ${Number(p.condition_error?.max_rel).toExponential(2)} rel`);
    if (p.continuity) lines.push(`  continuity ${p.continuity.class}`);
    if (p.trim) lines.push(`  trim: folds ${p.trim.folds_before} → ${p.trim.folds_after}, angles ${p.trim.min_angle_deg.toFixed(1)}–${p.trim.max_angle_deg.toFixed(1)}°, area ratio ${p.trim.area_ratio.toFixed(4)}`);
    for (const w of p.warnings || []) lines.push(`  warning: ${w}`);
  }
  return lines.join("\n") + "\n\n" + JSON.stringify(d, null, 1);
}
let diagTimer = null;
function changed() { solve(false); clearTimeout(diagTimer); diagTimer = setTimeout(() => solve(true), 400); }
function fit() {
  const b = bounds(model.patches.concat(model.context.faces));
  cam.target = scl(add(b.lo, b.hi), 0.5);
  const v = model.header.view;
  if (v) { cam.az = v.azimuth * Math.PI / 180; cam.el = v.elevation * Math.PI / 180; }
  cam.dist = 1.6 * Math.max(1e-3, Math.hypot(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]));
}

// ---------------- panel ----------------
function buildPanel(h) {
  const box = $("params"); box.innerHTML = "";
  for (const p of h.params) {
    if (p.derived) continue;
    const lo = p.min ?? (p.value === 0 ? -1 : Math.min(0, 2 * p.value)), hi = p.max ?? (p.value === 0 ? 1 : Math.max(0, 2 * p.value));
    const row = document.createElement("div"); row.className = "param"; row.title = p.description || "";
    row.innerHTML = `<span>${p.name}</span><input type="range" data-param="${p.name}" min="${lo}" max="${hi}" step="${p.step ?? (hi - lo) / 500}" value="${p.value}"><input type="number" data-num="${p.name}" value="${p.value}" step="any">`;
    box.appendChild(row);
  }
  box.querySelectorAll("input").forEach((el) => el.addEventListener("input", () => {
    const name = el.dataset.param || el.dataset.num, v = parseFloat(el.value);
    if (!Number.isFinite(v)) return;
    params[name] = v;
    box.querySelectorAll(`[data-param="${name}"],[data-num="${name}"]`).forEach((o) => { if (o !== el) o.value = v; });
    changed();
  }));
  const fs = $("field"); fs.innerHTML = `<option value="">shading</option>`;
  const names = new Set(h.patches.flatMap((p) => p.fields.map((f) => f.name)));
  const order = ["zebra", "isophotes", ...Object.keys(CURVATURES).filter((n) => names.has(n)),
    ...[...names].filter((n) => !CURVATURES[n])];
  for (const n of order) fs.innerHTML += `<option value="${n}">${VIEW_LABELS[n] || n}</option>`;
  if (h.time_range) {
    $("timebox").style.display = "block";
    const t = $("time"); t.min = h.time_range[0]; t.max = h.time_range[1]; t.step = (h.time_range[1] - h.time_range[0]) / 200;
    t.value = h.time_range[0]; time = h.time_range[0];
  } else { $("timebox").style.display = "none"; time = null; }
  $("trimbox").style.display = h.patches.some((p) => p.trim) ? "block" : "none";
  const dl = $("downloads"); dl.innerHTML = "";
  for (const f of ["obj", "ply", "stl", "glb", "vtu", "step"]) {
    const b = document.createElement("button"); b.textContent = f.toUpperCase(); b.dataset.format = f;
    b.onclick = () => download(f); dl.appendChild(b);
  }
  const sb = document.createElement("button"); sb.textContent = "scene .toml"; sb.dataset.format = "toml";
  sb.onclick = () => { const t = model ? model.header.text : scene.text; save(new Blob([t], { type: "text/plain" }), `${scene.name}.toml`, t.length); };
  dl.appendChild(sb);
}
function syncPanel(h) { $("title").textContent = h.title || h.name; }
function save(blob, name, bytes) {
  const a = document.createElement("a"); a.href = URL.createObjectURL(blob); a.download = name; a.click();
  S.lastDownload = { name, bytes };
}
async function download(format) {
  // the current model: the last text the server accepted (an invalid edit is not in it)
  const body = { text: model ? model.header.text : scene.text, name: scene.name, params, edits: [], time };
  const r = await fetch(`/api/export?format=${format}`, { method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body) });
  if (!r.ok) { showError((await r.json()).error); return; }
  const b = await r.blob();
  S.lastDownloadText = format === "obj" ? (await b.text()).slice(0, 200) : null;
  save(b, `${scene.name}.${format}`, b.size);
}
$("wire").onchange = redraw; $("handles").onchange = redraw;
$("field").onchange = () => { updateLegend(); redraw(); };
for (const id of ["stripes", "stripeangle"]) $(id).addEventListener("input", () => { updateLegend(); redraw(); });
$("climit").addEventListener("input", () => { $("cauto").checked = false; updateLegend(); redraw(); });
$("cauto").onchange = () => { updateLegend(); redraw(); };
$("seam").onchange = () => { buildSeams(); redraw(); };
$("time").addEventListener("input", () => { time = parseFloat($("time").value); changed(); });
let playing = null;
$("play").onclick = () => {
  if (playing) { clearInterval(playing); playing = null; $("play").textContent = "play"; return; }
  $("play").textContent = "pause";
  playing = setInterval(() => {
    const t = $("time"); let v = parseFloat(t.value) + parseFloat(t.step);
    if (v > parseFloat(t.max)) v = parseFloat(t.min);
    t.value = v; time = v; if (!inflight) solve(false);
  }, 50);
};

// ---------------- 3D interaction ----------------
let drag = null;
function pickHandle(x, y) {
  if (!$("handles").checked || !model) return null;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  let best = null, bd = 12;
  model.header.editables.handles.forEach((hd, i) => {
    const [sx, sy, ww] = project(hd.position, w, h);
    const d = Math.hypot(sx - x, sy - y);
    if (ww > 0 && d < bd) { bd = d; best = i; }
  });
  return best;
}
S.handleScreenPos = (i) => {
  const r = canvas.getBoundingClientRect();
  const [x, y] = project(model.header.editables.handles[i].position, canvas.clientWidth, canvas.clientHeight);
  return [r.left + x, r.top + y];
};
canvas.addEventListener("contextmenu", (e) => e.preventDefault());
canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  const h = pickHandle(e.offsetX, e.offsetY);
  if (h !== null) {
    const hd = model.header.editables.handles[h];
    drag = { kind: "handle", index: h, x: e.offsetX, y: e.offsetY, start: hd.position.slice(), path: hd.path };
  } else drag = { kind: e.shiftKey || e.button === 2 ? "pan" : "orbit", x: e.offsetX, y: e.offsetY };
  drag.x0 = e.offsetX; drag.y0 = e.offsetY;
});
canvas.addEventListener("pointermove", (e) => {
  if (!drag) return;
  const dx = e.offsetX - drag.x, dy = e.offsetY - drag.y;
  const px = 2 * cam.dist * Math.tan(cam.fov / 2) / canvas.clientHeight;
  const { r, u } = basis();
  if (drag.kind === "orbit") {
    cam.az -= dx * 0.01; cam.el = Math.max(-1.55, Math.min(1.55, cam.el + dy * 0.01)); drag.x = e.offsetX; drag.y = e.offsetY; redraw();
  } else if (drag.kind === "pan") {
    cam.target = add(cam.target, add(scl(r, -dx * px), scl(u, dy * px))); drag.x = e.offsetX; drag.y = e.offsetY; redraw();
  } else {
    let move = add(scl(r, dx * px), scl(u, -dy * px));
    const axis = $("axis").value;
    if (axis) {
      // move along the world axis by the screen drag projected onto the axis' screen direction
      const a = [0, 0, 0]; a[" xyz".indexOf(axis) - 1] = 1;
      const sx = dot(a, r), sy = -dot(a, u), s2 = Math.max(sx * sx + sy * sy, 1e-6);
      move = scl(a, (dx * sx + dy * sy) * px / s2);
    }
    const p = add(drag.start, move).map((v) => Math.round(v * 1e6) / 1e6);
    model.header.editables.handles[drag.index].position = p;
    edits = edits.filter((ed) => JSON.stringify(ed.path) !== JSON.stringify(drag.path));
    edits.push({ op: "set", path: drag.path, value: p });
    uploadHandles(); redraw(); changed();
  }
});
// the hole whose loop passes within 10 px of (x, y), if any
function pickHole(x, y) {
  if (!model) return null;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  let best = null, bd = 10;
  for (const hl of model.context.holes) {
    for (let i = 0; i < hl.pos.length; i += 3) {
      const [sx, sy, ww] = project([hl.pos[i], hl.pos[i + 1], hl.pos[i + 2]], w, h);
      const d = Math.hypot(sx - x, sy - y);
      if (ww > 0 && d < bd) { bd = d; best = hl.name; }
    }
  }
  return best;
}
// the imported face under (x, y): the nearest of the triangles whose screen image holds it
function pickFace(x, y) {
  if (!model) return null;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  const { view, proj } = matrices(w, h), m = mul4(proj, view);
  let best = null, bz = Infinity;
  for (const f of model.context.faces) {
    const p = f.pos, n = p.length / 3, sx = new Float32Array(n), sy = new Float32Array(n), sw = new Float32Array(n);
    for (let i = 0; i < n; i++) {
      const a = p[3 * i], b = p[3 * i + 1], c = p[3 * i + 2];
      const ww = m[3] * a + m[7] * b + m[11] * c + m[15];
      sx[i] = ((m[0] * a + m[4] * b + m[8] * c + m[12]) / ww * 0.5 + 0.5) * w;
      sy[i] = (1 - ((m[1] * a + m[5] * b + m[9] * c + m[13]) / ww * 0.5 + 0.5)) * h;
      sw[i] = ww;
    }
    for (let t = 0; t < f.idx.length; t += 3) {
      const i = f.idx[t], j = f.idx[t + 1], k = f.idx[t + 2];
      if (sw[i] <= 0 || sw[j] <= 0 || sw[k] <= 0) continue;
      const d = (sx[j] - sx[i]) * (sy[k] - sy[i]) - (sx[k] - sx[i]) * (sy[j] - sy[i]);
      if (d === 0) continue;
      const u = ((x - sx[i]) * (sy[k] - sy[i]) - (sx[k] - sx[i]) * (y - sy[i])) / d;
      const v = ((sx[j] - sx[i]) * (y - sy[i]) - (x - sx[i]) * (sy[j] - sy[i])) / d;
      if (u < 0 || v < 0 || u + v > 1) continue;
      const z = sw[i] + u * (sw[j] - sw[i]) + v * (sw[k] - sw[i]);
      if (z < bz) { bz = z; best = f.meta.name; }
    }
  }
  return best;
}
// the name under the mouse (a hole's loop before the face behind it), shown beside it
const tip = document.createElement("div");
tip.id = "hovername";
tip.style.cssText = "position:absolute;pointer-events:none;background:#223;color:#fff;font:12px sans-serif;padding:2px 6px;border-radius:3px;display:none";
canvas.parentElement.appendChild(tip);
let hoverQueued = null;
canvas.addEventListener("pointermove", (e) => {
  if (drag || !model || !model.context.faces.length && !model.context.holes.length) return;
  const first = !hoverQueued;
  hoverQueued = [e.offsetX, e.offsetY];
  if (!first) return;
  requestAnimationFrame(() => {
    const [x, y] = hoverQueued; hoverQueued = null;
    const name = pickHole(x, y) || pickFace(x, y);
    S.hoverName = name;
    tip.textContent = name || ""; tip.style.display = name ? "block" : "none";
    tip.style.left = `${x + 14}px`; tip.style.top = `${y + 10}px`;
  });
});
S.faceScreenPos = (name) => {
  const f = model.context.faces.find((x) => x.meta.name === name), r = canvas.getBoundingClientRect();
  const t = 3 * Math.floor(f.idx.length / 6), c = [0, 1, 2].map((k) => (f.pos[3 * f.idx[t] + k] + f.pos[3 * f.idx[t + 1] + k] + f.pos[3 * f.idx[t + 2] + k]) / 3);
  const [x, y] = project(c, canvas.clientWidth, canvas.clientHeight);
  return [r.left + x, r.top + y];
};
S.holeScreenPos = (name) => {
  const hl = model.context.holes.find((x) => x.name === name), r = canvas.getBoundingClientRect();
  const [x, y] = project([hl.pos[0], hl.pos[1], hl.pos[2]], canvas.clientWidth, canvas.clientHeight);
  return [r.left + x, r.top + y];
};
// a click (no drag) on a hole's loop fills it: a `kind = "fill"` patch of order 6 is added
// to the scene text (the server's `fill` edit), unless a patch already fills it
canvas.addEventListener("pointerup", (e) => {
  const click = drag && drag.kind !== "handle" && Math.hypot(e.offsetX - drag.x0, e.offsetY - drag.y0) < 3;
  drag = null;
  if (!click) return;
  const hole = pickHole(e.offsetX, e.offsetY);
  if (!hole) return;
  const name = "fill_" + hole.replace(/[^A-Za-z0-9_]/g, "_");
  if (edits.some((ed) => ed.op === "fill" && ed.value === hole) || (scene.text || "").includes(`"${hole}"`)) return;
  edits.push({ op: "fill", path: ["patches", name], value: hole });
  S.lastFill = hole; changed();
});
canvas.addEventListener("wheel", (e) => { e.preventDefault(); cam.dist *= Math.exp(e.deltaY * 0.001); redraw(); }, { passive: false });
window.addEventListener("resize", redraw);

// ---------------- trim editor (parameter space) ----------------
const t2 = $("trim2d"), c2 = t2.getContext("2d");
let tdrag = null;
function trimPatch() { return model && model.header.patches.find((p) => p.trim); }
function trimMap() {
  const p = trimPatch(); if (!p) return null;
  const [[u0, v0], [u1, v1]] = p.trim.domain, pad = 10, W = t2.width - 2 * pad, H = t2.height - 2 * pad;
  return { p, to: (q) => [pad + (q[0] - u0) / (u1 - u0) * W, pad + (1 - (q[1] - v0) / (v1 - v0)) * H],
    from: (x, y) => [u0 + (x - pad) / W * (u1 - u0), v0 + (1 - (y - pad) / H) * (v1 - v0)] };
}
function trimItems() { const p = trimPatch(); return p ? model.header.editables.trims.filter((t) => t.patch === p.name) : []; }
function drawTrim() {
  const m = trimMap(); c2.clearRect(0, 0, t2.width, t2.height); if (!m) return;
  const line = (pts, col, w, close) => {
    c2.strokeStyle = col; c2.lineWidth = w; c2.beginPath();
    pts.forEach((q, i) => { const [x, y] = m.to(q); i ? c2.lineTo(x, y) : c2.moveTo(x, y); });
    if (close) c2.closePath(); c2.stroke();
  };
  const t = m.p.trim;
  for (const s of t.spokes) line(s, "#e3a0a0", 1);
  for (const r of t.rings) line(r, "#a0b0e0", 1);
  line([t.domain[0], [t.domain[1][0], t.domain[0][1]], t.domain[1], [t.domain[0][0], t.domain[1][1]]], "#333", 2, true);
  line(t.loop, "#000", 2);
  for (const it of trimItems()) {
    if (it.kind !== "circle") line(it.points, "#f0a020", 1, true);
    for (const q of it.points) { const [x, y] = m.to(q); c2.fillStyle = "#f08c00"; c2.fillRect(x - 4, y - 4, 8, 8); }
  }
}
function trimHit(x, y) {
  const m = trimMap(); if (!m) return null;
  for (const it of trimItems()) for (let i = 0; i < it.points.length; i++) {
    const [px, py] = m.to(it.points[i]); if (Math.hypot(px - x, py - y) < 7) return { it, i };
  }
  return null;
}
S.trimPointScreenPos = (k, i) => {
  const m = trimMap(), r = t2.getBoundingClientRect(), [x, y] = m.to(trimItems()[k].points[i]);
  return [r.left + x, r.top + y];
};
function trimEdit(e) { edits.push(e); changed(); drawTrim(); }
t2.addEventListener("contextmenu", (e) => {
  e.preventDefault(); const h = trimHit(e.offsetX, e.offsetY);
  if (h && h.it.kind !== "circle") { h.it.points.splice(h.i, 1); trimEdit({ op: "delete", path: [...h.it.path, h.i] }); }
});
t2.addEventListener("dblclick", (e) => {
  const m = trimMap(); if (!m) return; const q = m.from(e.offsetX, e.offsetY);
  let best = null, bd = Infinity;
  for (const it of trimItems()) {
    if (it.kind === "circle") continue;
    it.points.forEach((a, i) => {
      const b = it.points[(i + 1) % it.points.length], mid = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
      const d = Math.hypot(mid[0] - q[0], mid[1] - q[1]); if (d < bd) { bd = d; best = { it, i: i + 1 }; }
    });
  }
  if (best) { best.it.points.splice(best.i, 0, q); trimEdit({ op: "insert", path: [...best.it.path, best.i], value: q }); }
});
t2.addEventListener("pointerdown", (e) => { const h = trimHit(e.offsetX, e.offsetY); if (h && e.button === 0) { tdrag = h; t2.setPointerCapture(e.pointerId); } });
t2.addEventListener("pointermove", (e) => {
  if (!tdrag) return; const m = trimMap(); const q = m.from(e.offsetX, e.offsetY).map((v) => Math.round(v * 1e6) / 1e6);
  tdrag.it.points[tdrag.i] = q;
  const path = tdrag.it.kind === "circle" ? tdrag.it.path : [...tdrag.it.path, tdrag.i];
  edits = edits.filter((ed) => JSON.stringify(ed.path) !== JSON.stringify(path) || ed.op !== "set");
  edits.push({ op: "set", path, value: q }); changed(); drawTrim();
});
t2.addEventListener("pointerup", () => { tdrag = null; });

// ---------------- start ----------------
async function open(name, text) {
  scene = { name, text }; params = {}; edits = []; model = null; solve(true);
}
(async () => {
  const ex = await (await fetch("/api/examples")).json();
  const sel = $("examples");
  sel.innerHTML = `<option value="">— examples —</option>` + ex.map((n) => `<option>${n}</option>`).join("");
  sel.onchange = async () => { if (!sel.value) return; const e = await (await fetch(`/api/example/${sel.value}`)).json(); open(e.name, e.text); };
  const init = await (await fetch("/api/initial")).json();
  if (init) open(init.name, init.text);
  else { const e = await (await fetch(`/api/example/${ex[0]}`)).json(); sel.value = ex[0]; open(e.name, e.text); }
})();
