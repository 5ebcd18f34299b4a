// The WebGL2 context of the editor's canvas and its shader programs: the surface views
// (shading, fields, zebra, isophotes), flat lines and points, seam colours.

const $ = (id) => document.getElementById(id);
export const canvas = $("gl");
export const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: true });
if (!gl) { $("error").style.display = "block"; $("error").textContent = "WebGL2 is not available in this browser."; }
function shader(type, src) {
  const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
export function program(vs, fs) {
  const p = gl.createProgram();
  gl.attachShader(p, shader(gl.VERTEX_SHADER, vs)); gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}
// Surface views (the same models as `pdeshape render --view`, see render/view.rs): mode 0 the
// patch colour, 1 a field min…max (sequential), 2 a field on the diverging scale ±range.y,
// 3 zebra: the view ray reflected about the interpolated exact normal picks one of
// `stripes` black and white light tubes along `axis` (screen plane): band ⌊φ·n/π⌋,
// φ = atan2(r·(w × a), r·w); 4 isophotes: bands of acos(n·l), l the head light.
export const surf = program(`#version 300 es
layout(location=0) in vec3 pos; layout(location=1) in vec3 nor; layout(location=2) in float fld;
uniform mat4 view, proj; out vec3 vn; out vec3 vp; out float vf;
void main() { vn = mat3(view) * nor; vec4 q = view * vec4(pos, 1.0); vp = q.xyz; vf = fld; gl_Position = proj * q; }`,
`#version 300 es
precision highp float; in vec3 vn; in vec3 vp; in float vf; uniform vec3 color; uniform int mode;
uniform vec2 range; uniform float stripes; uniform vec2 axis; out vec4 o;
const float PI = 3.14159265358979;
vec3 cmap(float t) { t = clamp(t, 0.0, 1.0);
  return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0); }
vec3 diverging(float x) {
  vec3 c[5] = vec3[5](vec3(0.230, 0.299, 0.754), vec3(0.552, 0.690, 0.996), vec3(0.865, 0.865, 0.865),
                      vec3(0.958, 0.604, 0.482), vec3(0.706, 0.016, 0.150));
  float t = (clamp(x, -1.0, 1.0) + 1.0) * 2.0; int i = min(int(floor(t)), 3);
  return mix(c[i], c[i + 1], t - float(i)); }
void main() {
  vec3 n = normalize(vn); vec3 v = normalize(-vp); if (dot(n, v) < 0.0) n = -n;
  if (mode == 3) {
    vec3 r = reflect(-v, n); vec3 w = vec3(0.0, 0.0, 1.0); vec3 a = vec3(axis, 0.0);
    float band = floor(atan(dot(r, cross(w, a)), dot(r, w)) / PI * stripes);
    o = vec4(mod(band, 2.0) < 0.5 ? vec3(0.07, 0.07, 0.09) : vec3(0.96), 1.0); return;
  }
  vec3 base = mode == 1 ? cmap((vf - range.x) / max(range.y - range.x, 1e-30))
            : mode == 2 ? diverging(vf / max(range.y, 1e-300)) : color;
  float d = max(dot(n, v), 0.0); float s = pow(max(dot(reflect(-v, n), v), 0.0), 40.0);
  vec3 c = base * (0.25 + 0.75 * d) + vec3(0.25 * s);
  if (mode == 4 && mod(floor(acos(clamp(dot(n, v), -1.0, 1.0)) / PI * 2.0 * stripes), 2.0) > 0.5) c *= 0.55;
  o = vec4(c, 1.0); }`);
export const flat = program(`#version 300 es
layout(location=0) in vec3 pos; uniform mat4 view, proj; uniform float size;
void main() { gl_Position = proj * view * vec4(pos, 1.0); gl_Position.z -= 0.0005 * gl_Position.w; gl_PointSize = size; }`,
`#version 300 es
precision highp float; uniform vec4 color; out vec4 o; void main() { o = color; }`);
export const seamProg = program(`#version 300 es
layout(location=0) in vec3 pos; layout(location=1) in vec3 col; uniform mat4 view, proj; uniform float size; out vec3 vc;
void main() { gl_Position = proj * view * vec4(pos, 1.0); gl_Position.z -= 0.001 * gl_Position.w; gl_PointSize = size; vc = col; }`,
`#version 300 es
precision highp float; in vec3 vc; out vec4 o; void main() { o = vec4(vc, 1.0); }`);
