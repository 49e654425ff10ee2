// WebGL2 renderer of geomip scene models — the desktop viewer's (stream_viewer/renderer.cpp) in the browser:
// each patch is drawn from one index buffer of triangles over the (2^k+1)² grid (each quad split along its
// shorter diagonal, rebuilt with each refinement) whose vertex shader fetches the positions from a float
// texture array (vertex texture fetch, no vertex attributes), so a refinement is a texture upload and an index
// buffer, not a new mesh; normal-map shading (the pack's normal maps, linearly filtered), hole
// discard (the hole mask, one texel per quad), seams that never crack (the codec's seam samples are
// bit-identical in the glued patches and every patch is drawn at the same level), morphs between two models
// of the same layout with per-band weights (linear, or the wavelet schedule of morph/scene_model.h).

const kMaxBands = 8;
export const kBackground = [26, 26, 31];

const kVertexShader = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2DArray;
uniform sampler2DArray geom_a;
uniform sampler2DArray geom_b;
uniform int grid_size;
uniform int stride;
uniform int layer_a;
uniform int layer_b;
uniform int bands;
uniform float w_a[8];
uniform float w_b[8];
uniform mat4 view_proj;
out vec3 v_pos;
out vec2 v_uv;
void main() {
  int i = gl_VertexID % grid_size;
  int j = gl_VertexID / grid_size;
  ivec2 texel = ivec2(i * stride, j * stride);
  vec3 p = vec3(0.0);
  for (int b = 0; b < 8; ++b) {
    if (b >= bands) break;
    p += w_a[b] * texelFetch(geom_a, ivec3(texel, layer_a + b), 0).xyz;
    p += w_b[b] * texelFetch(geom_b, ivec3(texel, layer_b + b), 0).xyz;
  }
  v_pos = p;
  v_uv = vec2(float(i), float(j)) / float(grid_size - 1);
  gl_Position = view_proj * vec4(p, 1.0);
}`;

const kFragmentShader = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2DArray;
precision highp usampler2DArray;
uniform sampler2DArray normal_a;
uniform sampler2DArray normal_b;
uniform usampler2DArray holes;
uniform int has_normals;
uniform int normal_size;
uniform int has_holes;
uniform int hole_res;
uniform int patch_index;
uniform float nw_a;
uniform float nw_b;
uniform vec3 eye;
in vec3 v_pos;
in vec2 v_uv;
out vec4 color;
void main() {
  if (has_holes != 0) {
    ivec2 q = clamp(ivec2(v_uv * float(hole_res)), ivec2(0), ivec2(hole_res - 1));
    if (texelFetch(holes, ivec3(q, patch_index), 0).r != 0u) discard;
  }
  vec3 ng = cross(dFdx(v_pos), dFdy(v_pos));
  vec3 n;
  if (has_normals != 0) {
    vec2 tc = (v_uv * float(normal_size - 1) + 0.5) / float(normal_size);
    vec3 na = texture(normal_a, vec3(tc, float(patch_index))).xyz;
    vec3 nb = texture(normal_b, vec3(tc, float(patch_index))).xyz;
    vec3 nmap = nw_a * na + nw_b * nb;
    float rest = 1.0 - nw_a - nw_b;
    if (rest > 1e-4) {
      vec3 g = normalize(ng);
      vec3 ref = (nw_a + nw_b < 1e-4) ? mix(na, nb, 0.5) : mix(na, nb, nw_b / max(nw_a + nw_b, 1e-6));
      if (dot(g, ref) < 0.0) g = -g;
      nmap += rest * g;
    }
    n = dot(nmap, nmap) < 1e-12 ? ng : nmap;
  } else {
    n = ng;
  }
  n = normalize(n);
  vec3 v = normalize(eye - v_pos);
  if (dot(n, v) < 0.0) n = -n;
  vec3 base = vec3(0.80, 0.72, 0.60);
  vec3 l = normalize(vec3(0.4, 0.8, 0.6) + v);
  vec3 h = normalize(l + v);
  float diff = max(dot(n, l), 0.0);
  float spec = pow(max(dot(n, h), 0.0), 48.0);
  color = vec4(base * (0.22 + 0.78 * diff) + vec3(0.25) * spec, 1.0);
}`;

/// Band weights of source and target at morph time t (morph::band_weights, morph/scene_model.cpp).
export function bandWeights(t, bands, schedule) {
  t = Math.min(Math.max(t, 0), 1);
  const source = [], target = [];
  for (let b = 0; b < bands; ++b) {
    if (schedule !== 'wavelet' || bands === 1) { source.push(1 - t); target.push(t); continue; }
    const f = b / (bands - 1);
    const span = 1 - 0.5 * f;
    source.push(Math.min(Math.max(1 - t / span, 0), 1));
    target.push(Math.min(Math.max((t - 0.5 * f) / span, 0), 1));
  }
  return { source, target };
}

/// Orbit camera about the origin (stream_viewer/camera.h): column-major projection · view.
export function viewProjection(camera, width, height) {
  const cp = Math.cos(camera.pitch);
  const eye = [camera.distance * cp * Math.sin(camera.yaw), camera.distance * Math.sin(camera.pitch),
    camera.distance * cp * Math.cos(camera.yaw)];
  const norm = (a) => { const l = Math.hypot(...a); return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const f = norm(eye.map((x) => -x));
  const s = norm(cross(f, [0, 1, 0]));
  const u = cross(s, f);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const view = [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
    -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
  const near = 0.05, far = 50, t = 1 / Math.tan(camera.fovYDeg * Math.PI / 360);
  const aspect = width / Math.max(height, 1);
  const proj = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1,
    0, 0, 2 * far * near / (near - far), 0];
  const out = new Float32Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r) {
      let v = 0;
      for (let k = 0; k < 4; ++k) v += proj[k * 4 + r] * view[c * 4 + k];
      out[c * 4 + r] = v;
    }
  return { matrix: out, eye };
}

/// The camera distance at which every scene model (its positions in the normalized frame, the sum of its
/// wavelet bands: the model itself, so both schedules frame alike), seen from `camera`'s yaw and pitch, spans
/// `fill` of a width×height viewport's height — or `maxWidthFill` of its width, whichever comes first
/// (stream_viewer/camera.h framing_distance: the same bisection over [0.3, 20] on at most ~20,000 points).
/// Returns camera.distance when there are no points.
export function framingDistance(camera, models, width, height, fill = 0.7, maxWidthFill = 0.9) {
  const xyz = [];
  for (const m of models) {
    const per = 3 * ((1 << m.level) + 1) ** 2;
    for (let p = 0; p < m.numPatches; ++p) {
      const patch = m.positions.slice(p * m.bands * per, p * m.bands * per + per);
      for (let b = 1; b < m.bands; ++b)
        for (let k = 0, at = (p * m.bands + b) * per; k < per; ++k) patch[k] += m.positions[at + k];
      xyz.push(patch);
    }
  }
  const points = xyz.reduce((n, a) => n + a.length / 3, 0);
  if (points === 0) return camera.distance;
  const stride = Math.max(1, Math.floor(points / 20000));
  const spanAt = (distance) => {
    const m = viewProjection({ ...camera, distance }, width, height).matrix;
    const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    let k = 0;
    for (const a of xyz)
      for (let i = 0; i < a.length; i += 3, ++k) {
        if (k % stride) continue;
        const w = m[3] * a[i] + m[7] * a[i + 1] + m[11] * a[i + 2] + m[15];
        if (!(w > 0.05)) return Infinity;
        for (let r = 0; r < 2; ++r) {
          const v = (m[r] * a[i] + m[4 + r] * a[i + 1] + m[8 + r] * a[i + 2] + m[12 + r]) / w;
          lo[r] = Math.min(lo[r], v);
          hi[r] = Math.max(hi[r], v);
        }
      }
    return Math.max((hi[1] - lo[1]) / (2 * fill), (hi[0] - lo[0]) / (2 * maxWidthFill));  // NDC spans 2
  };
  let near = 0.3, far = 20;  // the span decreases with the distance
  for (let it = 0; it < 40; ++it) {
    const mid = 0.5 * (near + far);
    if (spanAt(mid) > 1) near = mid; else far = mid;
  }
  return far;
}

export class Renderer {
  constructor(gl) {
    this.gl = gl;
    this.models = [];
    const compile = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(s)}`);
      return s;
    };
    this.program = gl.createProgram();
    gl.attachShader(this.program, compile(gl.VERTEX_SHADER, kVertexShader));
    gl.attachShader(this.program, compile(gl.FRAGMENT_SHADER, kFragmentShader));
    gl.linkProgram(this.program);
    if (!gl.getProgramParameter(this.program, gl.LINK_STATUS))
      throw new Error(`shader link: ${gl.getProgramInfoLog(this.program)}`);
    this.vao = gl.createVertexArray();
    this.uniforms = new Map();
  }

  uniform(name) {
    if (!this.uniforms.has(name)) this.uniforms.set(name, this.gl.getUniformLocation(this.program, name));
    return this.uniforms.get(name);
  }

  /// Model `m`'s triangles (grid-local vertex ids j·s + i, patch p's 6·4^level indices from p · 6·4^level):
  /// each quad split along its shorter diagonal as `geomip decode` and `geomip-view` split it (the four corner
  /// quads of a patch and ties along a–c when i + j + p is even, b–d otherwise), the bands summed.
  indexBuffer(m) {
    const gl = this.gl, n = 1 << m.level, s = n + 1, per = s * s * 3;
    const idx = new Uint32Array(m.numPatches * n * n * 6);
    const x = new Float32Array(per);
    let k = 0;
    for (let p = 0; p < m.numPatches; ++p) {
      x.fill(0);
      for (let b = 0; b < m.bands; ++b) {
        const base = (p * m.bands + b) * per;
        for (let q = 0; q < per; ++q) x[q] += m.positions[base + q];
      }
      const d2 = (u, v) => {
        const dx = x[3 * u] - x[3 * v], dy = x[3 * u + 1] - x[3 * v + 1], dz = x[3 * u + 2] - x[3 * v + 2];
        return dx * dx + dy * dy + dz * dz;
      };
      for (let j = 0; j < n; ++j)
        for (let i = 0; i < n; ++i) {
          const a = j * s + i, b = a + 1, c = a + s + 1, d = a + s;
          let ac = (i + j + p) % 2 === 0;
          if (!((i === 0 || i === n - 1) && (j === 0 || j === n - 1))) {
            const diff = d2(a, c) - d2(b, d);
            if (diff < 0) ac = true;
            if (diff > 0) ac = false;
          }
          if (ac) { idx[k++] = a; idx[k++] = b; idx[k++] = c; idx[k++] = a; idx[k++] = c; idx[k++] = d; }
          else { idx[k++] = a; idx[k++] = b; idx[k++] = d; idx[k++] = b; idx[k++] = c; idx[k++] = d; }
        }
    }
    gl.bindVertexArray(this.vao);
    const buffer = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, buffer);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    return { buffer, count: 6 * n * n };
  }

  texture(internal, format, type, size, layers, data, filter) {
    const gl = this.gl, tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, internal, size, size, layers, 0, format, type, data);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, filter);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, filter);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    return tex;
  }

  /// Replaces the models by `scene` (GeomipDecoder.scene().models): one texture upload per model.
  setModels(scene) {
    const gl = this.gl;
    for (const m of this.models) {
      for (const t of [m.geometry, m.normals, m.holes]) if (t) gl.deleteTexture(t);
      gl.deleteBuffer(m.index.buffer);
    }
    this.models = scene.map((m) => {
      const size = (1 << m.level) + 1;
      const g = { level: m.level, numPatches: m.numPatches, bands: m.bands, normals: null, holes: null };
      g.geometry = this.texture(gl.RGB32F, gl.RGB, gl.FLOAT, size, m.numPatches * m.bands, m.positions,
                                gl.NEAREST);
      g.index = this.indexBuffer(m);
      if (m.normalLevel >= 0) {  // RGB16F: filterable in WebGL2 without extensions
        g.normalSize = (1 << m.normalLevel) + 1;
        g.normals = this.texture(gl.RGB16F, gl.RGB, gl.FLOAT, g.normalSize, m.numPatches, m.normals, gl.LINEAR);
      }
      if (m.holeLevel >= 0) {
        g.holeLevel = m.holeLevel;
        g.holes = this.texture(gl.R8UI, gl.RED_INTEGER, gl.UNSIGNED_BYTE, 1 << m.holeLevel, m.numPatches, m.holes,
                               gl.NEAREST);
      }
      return g;
    });
  }

  /// Draws model `source` (morphing to `target` at time t when both have the same layout) into the
  /// current framebuffer of width × height.
  draw({ source = 0, target = -1, t = 0, schedule = 'linear', camera, width, height }) {
    const gl = this.gl;
    gl.viewport(0, 0, width, height);
    gl.clearColor(kBackground[0] / 255, kBackground[1] / 255, kBackground[2] / 255, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const a = this.models[source];
    if (!a) return;
    const bm = this.models[target];
    const morph = bm && bm !== a && bm.level === a.level && bm.numPatches === a.numPatches && bm.bands === a.bands;
    const b = morph ? bm : a;
    const w = bandWeights(morph ? t : 0, a.bands, schedule);
    if (!morph) w.target.fill(0);
    while (w.source.length < kMaxBands) { w.source.push(0); w.target.push(0); }
    // A morph is drawn with the split of the end it is nearer, so each end looks exactly as that model alone.
    const { buffer, count } = (morph && t >= 0.5 ? b : a).index;
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.CULL_FACE);
    gl.useProgram(this.program);
    gl.bindVertexArray(this.vao);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, buffer);
    const units = [a.geometry, b.geometry, a.normals, b.normals, a.holes];
    units.forEach((tex, u) => { gl.activeTexture(gl.TEXTURE0 + u); gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex); });
    ['geom_a', 'geom_b', 'normal_a', 'normal_b', 'holes'].forEach((n, u) => gl.uniform1i(this.uniform(n), u));
    const vp = viewProjection(camera, width, height);
    gl.uniformMatrix4fv(this.uniform('view_proj'), false, vp.matrix);
    gl.uniform3f(this.uniform('eye'), ...vp.eye);
    gl.uniform1i(this.uniform('grid_size'), (1 << a.level) + 1);
    gl.uniform1i(this.uniform('stride'), 1);
    gl.uniform1i(this.uniform('bands'), a.bands);
    gl.uniform1fv(this.uniform('w_a[0]'), w.source);
    gl.uniform1fv(this.uniform('w_b[0]'), w.target);
    const normals = a.normals && b.normals && a.normalSize === b.normalSize;
    gl.uniform1i(this.uniform('has_normals'), normals ? 1 : 0);
    gl.uniform1i(this.uniform('normal_size'), a.normalSize ?? 1);
    gl.uniform1i(this.uniform('has_holes'), a.holes ? 1 : 0);
    gl.uniform1i(this.uniform('hole_res'), 1 << (a.holeLevel ?? 0));
    gl.uniform1f(this.uniform('nw_a'), morph ? w.source[a.bands - 1] : 1);
    gl.uniform1f(this.uniform('nw_b'), morph ? w.target[a.bands - 1] : 0);
    for (let p = 0; p < a.numPatches; ++p) {
      gl.uniform1i(this.uniform('patch_index'), p);
      gl.uniform1i(this.uniform('layer_a'), p * a.bands);
      gl.uniform1i(this.uniform('layer_b'), p * b.bands);
      gl.drawElements(gl.TRIANGLES, count, gl.UNSIGNED_INT, p * count * 4);
    }
    gl.bindVertexArray(null);
  }
}
