#include "stream_viewer/renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

namespace geomip::viewer {
namespace {

constexpr int kMaxBands = 8;

const char* kVertexShader = R"(#version 330 core
uniform sampler2DArray geom_a;
uniform sampler2DArray geom_b;
uniform int grid_size;   // 2^k + 1
uniform int stride;      // 2^(n-k)
uniform int layer_a;     // patch · bands
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
  for (int b = 0; b < bands; ++b) {
    p += w_a[b] * texelFetch(geom_a, ivec3(texel, layer_a + b), 0).xyz;
    p += w_b[b] * texelFetch(geom_b, ivec3(texel, layer_b + b), 0).xyz;
  }
  v_pos = p;
  v_uv = vec2(i, j) / float(grid_size - 1);
  gl_Position = view_proj * vec4(p, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
uniform sampler2DArray normal_a;
uniform sampler2DArray normal_b;
uniform usampler2DArray holes;
uniform int has_normals;
uniform int normal_size;   // samples per side of the normal map
uniform int has_holes;
uniform int hole_res;      // 2^L quads per side of the hole mask
uniform int patch_index;
uniform float nw_a;        // normal-map weights (linear: 1-t, t; wavelet: the finest band's weights,
uniform float nw_b;        // the rest is the geometric normal of the blended surface)
uniform vec3 eye;
uniform int checker;
in vec3 v_pos;
in vec2 v_uv;
out vec4 color;
void main() {
  if (has_holes != 0) {
    ivec2 q = clamp(ivec2(v_uv * float(hole_res)), ivec2(0), ivec2(hole_res - 1));
    if (texelFetch(holes, ivec3(q, patch_index), 0).r != 0u) discard;
  }
  vec3 n;
  if (has_normals != 0) {
    vec2 tc = (v_uv * float(normal_size - 1) + 0.5) / float(normal_size);
    vec3 na = texture(normal_a, vec3(tc, patch_index)).xyz;
    vec3 nb = texture(normal_b, vec3(tc, patch_index)).xyz;
    vec3 nmap = nw_a * na + nw_b * nb;
    float rest = 1.0 - nw_a - nw_b;
    if (rest > 1e-4) {
      vec3 ng = normalize(cross(dFdx(v_pos), dFdy(v_pos)));
      vec3 ref = mix(na, nb, nw_b / max(nw_a + nw_b, 1e-6) );
      if (nw_a + nw_b < 1e-4) ref = mix(na, nb, 0.5);
      if (dot(ng, ref) < 0.0) ng = -ng;
      nmap += rest * ng;
    }
    n = nmap;
    if (dot(n, n) < 1e-12) n = cross(dFdx(v_pos), dFdy(v_pos));
  } else {
    n = cross(dFdx(v_pos), dFdy(v_pos));
  }
  n = normalize(n);
  vec3 v = normalize(eye - v_pos);
  if (dot(n, v) < 0.0) n = -n;   // two-sided
  vec3 base = vec3(0.80, 0.72, 0.60);
  if (checker != 0) {
    ivec2 c = ivec2(floor(v_uv * 16.0));
    float h = float(patch_index % 7) / 7.0;
    vec3 hue = clamp(abs(fract(h + vec3(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0, 0.0, 1.0);
    base = ((c.x + c.y) % 2 == 0) ? mix(hue, vec3(1.0), 0.3) : hue * 0.35 + 0.05;
  }
  vec3 l = normalize(vec3(0.4, 0.8, 0.6) + v);
  vec3 h = normalize(l + v);
  float diff = max(dot(n, l), 0.0);
  float spec = pow(max(dot(n, h), 0.0), 48.0);
  vec3 c = base * (0.22 + 0.78 * diff) + vec3(0.25) * spec;
  color = vec4(c, 1.0);
}
)";

unsigned compile(GLenum type, const char* src) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("geomip-view: shader compile failed: ") + log);
  }
  return s;
}

struct ModelGpu {
  int level = 0, num_patches = 0, bands = 1, normal_size = 0, hole_level = 0;
  bool has_normals = false, has_holes = false;
  GLuint geometry = 0, normals = 0, holes = 0;
  std::vector<float> full;  ///< the model as drawn unmorphed (its bands summed): [patch · size² + j·size + i] · 3
};

/// Triangles of `model`'s level-`level` grids (grid-local vertex ids j·s + i, s = 2^level + 1; patch p's
/// 6·4^level indices from p · 6·4^level): each quad split along its shorter diagonal, as `geomip decode` splits
/// them (gimage/uniform_remesh.h split_along_shorter_diagonals: the four corner quads of a patch and ties
/// along a–c when i + j + p is even, b–d otherwise).
std::vector<std::uint32_t> grid_triangles(const ModelGpu& model, int level) {
  const int intervals = 1 << level;
  const std::uint32_t s = static_cast<std::uint32_t>(intervals) + 1;
  const int size = (1 << model.level) + 1, stride = 1 << (model.level - level);
  std::vector<std::uint32_t> idx;
  idx.reserve(static_cast<std::size_t>(model.num_patches) * 6 * intervals * intervals);
  for (int p = 0; p < model.num_patches; ++p) {
    const float* x = model.full.data() + static_cast<std::size_t>(p) * size * size * 3;
    auto d2 = [&](int i0, int j0, int i1, int j1) {  // squared distance of two level-`level` samples
      const float* u = x + (static_cast<std::size_t>(j0 * stride) * size + static_cast<std::size_t>(i0 * stride)) * 3;
      const float* v = x + (static_cast<std::size_t>(j1 * stride) * size + static_cast<std::size_t>(i1 * stride)) * 3;
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += (static_cast<double>(u[k]) - v[k]) * (static_cast<double>(u[k]) - v[k]);
      return sum;
    };
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i) {
        const std::uint32_t a = static_cast<std::uint32_t>(j) * s + static_cast<std::uint32_t>(i), b = a + 1,
                            c = a + s + 1, d = a + s;
        bool along_ac = (i + j + p) % 2 == 0;
        const bool corner = (i == 0 || i == intervals - 1) && (j == 0 || j == intervals - 1);
        if (!corner) {
          const double ac_minus_bd = d2(i, j, i + 1, j + 1) - d2(i + 1, j, i, j + 1);
          if (ac_minus_bd < 0) along_ac = true;
          if (ac_minus_bd > 0) along_ac = false;
        }
        if (along_ac)
          idx.insert(idx.end(), {a, b, c, a, c, d});
        else
          idx.insert(idx.end(), {a, b, d, b, c, d});
      }
    }
  }
  return idx;
}

GLuint make_array(GLenum internal, GLenum format, GLenum type, int w, int layers, const void* data, GLenum filter) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D_ARRAY, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, static_cast<GLint>(internal), w, w, layers, 0, format, type, data);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

}  // namespace

struct Renderer::Impl {
  GLuint program = 0, vao = 0;
  std::vector<ModelGpu> models;
  /// (model, level) → (index buffer of every patch's triangles, indices per patch); rebuilt after
  /// set_models(), since the split follows the positions.
  std::map<std::pair<int, int>, std::pair<GLuint, GLsizei>> grids;
  std::map<std::string, GLint> uniforms;

  GLint uniform(const char* name) {
    auto it = uniforms.find(name);
    if (it != uniforms.end()) return it->second;
    return uniforms[name] = glGetUniformLocation(program, name);
  }

  void free_grids() {
    for (auto& [key, g] : grids) glDeleteBuffers(1, &g.first);
    grids.clear();
  }

  void free_models() {
    for (auto& m : models) {
      glDeleteTextures(1, &m.geometry);
      if (m.normals) glDeleteTextures(1, &m.normals);
      if (m.holes) glDeleteTextures(1, &m.holes);
    }
    models.clear();
    free_grids();
  }

  /// The triangles of model `m` at `level` (grid_triangles()).
  std::pair<GLuint, GLsizei> grid(int m, int level) {
    const std::pair<int, int> key{m, level};
    auto it = grids.find(key);
    if (it != grids.end()) return it->second;
    const std::vector<std::uint32_t> idx = grid_triangles(models[m], level);
    GLuint buf = 0;
    glGenBuffers(1, &buf);
    glBindVertexArray(vao);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buf);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(idx.size() * 4), idx.data(), GL_STATIC_DRAW);
    return grids[key] = {buf, static_cast<GLsizei>(idx.size() / static_cast<std::size_t>(models[m].num_patches))};
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  impl_->program = glCreateProgram();
  glAttachShader(impl_->program, vs);
  glAttachShader(impl_->program, fs);
  glLinkProgram(impl_->program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(impl_->program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(impl_->program, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("geomip-view: shader link failed: ") + log);
  }
  glGenVertexArrays(1, &impl_->vao);
}

Renderer::~Renderer() {
  impl_->free_models();
  glDeleteVertexArrays(1, &impl_->vao);
  glDeleteProgram(impl_->program);
}

int Renderer::model_count() const { return static_cast<int>(impl_->models.size()); }
int Renderer::model_level(int i) const {
  return i >= 0 && i < model_count() ? impl_->models[i].level : -1;
}

void Renderer::set_models(const std::vector<morph::SceneModel>& models) {
  impl_->free_models();
  for (const auto& m : models) {
    ModelGpu g;
    g.level = m.level;
    g.num_patches = m.num_patches;
    if (m.bands < 1 || m.bands > kMaxBands || m.num_patches < 1)
      throw std::invalid_argument("Renderer::set_models: 1 to 8 bands and at least one patch per model");
    g.bands = m.bands;
    g.geometry = make_array(GL_RGB32F, GL_RGB, GL_FLOAT, m.size(), m.num_patches * m.bands, m.positions.data(),
                            GL_NEAREST);
    const std::size_t per = static_cast<std::size_t>(m.size()) * m.size() * 3;
    g.full.assign(static_cast<std::size_t>(m.num_patches) * per, 0.0f);
    for (int p = 0; p < m.num_patches; ++p)
      for (int b = 0; b < m.bands; ++b)
        for (std::size_t k = 0; k < per; ++k)
          g.full[p * per + k] += m.positions[(static_cast<std::size_t>(p) * m.bands + b) * per + k];
    if (m.normal_level >= 0) {
      g.has_normals = true;
      g.normal_size = (1 << m.normal_level) + 1;
      g.normals = make_array(GL_RGB32F, GL_RGB, GL_FLOAT, g.normal_size, m.num_patches, m.normals.data(), GL_LINEAR);
    }
    if (!m.holes.empty()) {
      g.has_holes = true;
      g.hole_level = m.hole_level;
      g.holes = make_array(GL_R8UI, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1 << m.hole_level, m.num_patches, m.holes.data(),
                           GL_NEAREST);
    }
    impl_->models.push_back(g);
  }
}

void Renderer::draw(const RenderSettings& s) {
  Impl& im = *impl_;
  glViewport(0, 0, s.width, s.height);
  glClearColor(kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (s.source < 0 || s.source >= model_count()) return;
  const ModelGpu& a = im.models[s.source];
  const bool morph = s.target >= 0 && s.target < model_count() && im.models[s.target].level == a.level &&
                     im.models[s.target].num_patches == a.num_patches && im.models[s.target].bands == a.bands;
  const ModelGpu& b = morph ? im.models[s.target] : a;
  const float t = morph ? s.t : 0.0f;
  const int level = s.level < 0 ? a.level : std::clamp(s.level, 0, a.level);
  // A morph is drawn with the split of the end it is nearer (so each end looks exactly as that model alone;
  // the diagonals change once, at t = 0.5). `geomip morph` instead keeps one face list for all its frames.
  const auto [index_buffer, index_count] = im.grid(morph && t >= 0.5f ? s.target : s.source, level);

  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glPolygonMode(GL_FRONT_AND_BACK, s.wireframe ? GL_LINE : GL_FILL);
  glUseProgram(im.program);
  glBindVertexArray(im.vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer);

  const GLuint units[5] = {a.geometry, b.geometry, a.normals, b.normals, a.holes};
  const GLenum targets[5] = {GL_TEXTURE_2D_ARRAY, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_2D_ARRAY,
                             GL_TEXTURE_2D_ARRAY};
  for (int u = 0; u < 5; ++u) {
    glActiveTexture(GL_TEXTURE0 + u);
    glBindTexture(targets[u], units[u]);
  }
  glUniform1i(im.uniform("geom_a"), 0);
  glUniform1i(im.uniform("geom_b"), 1);
  glUniform1i(im.uniform("normal_a"), 2);
  glUniform1i(im.uniform("normal_b"), 3);
  glUniform1i(im.uniform("holes"), 4);

  const auto vp = view_projection(s.camera, s.width, s.height);
  glUniformMatrix4fv(im.uniform("view_proj"), 1, GL_FALSE, vp.data());
  const auto eye = eye_position(s.camera);
  glUniform3f(im.uniform("eye"), eye[0], eye[1], eye[2]);
  const int size = (1 << level) + 1;
  glUniform1i(im.uniform("grid_size"), size);
  glUniform1i(im.uniform("stride"), 1 << (a.level - level));
  glUniform1i(im.uniform("bands"), a.bands);
  auto w = morph::band_weights(t, a.bands, s.schedule);
  if (!morph) std::fill(w.target.begin(), w.target.end(), 0.0f);
  w.source.resize(kMaxBands, 0.0f);
  w.target.resize(kMaxBands, 0.0f);
  glUniform1fv(im.uniform("w_a"), kMaxBands, w.source.data());
  glUniform1fv(im.uniform("w_b"), kMaxBands, w.target.data());
  const bool normals = a.has_normals && b.has_normals && a.normal_size == b.normal_size;
  glUniform1i(im.uniform("has_normals"), normals ? 1 : 0);
  glUniform1i(im.uniform("normal_size"), a.normal_size);
  glUniform1i(im.uniform("has_holes"), a.has_holes ? 1 : 0);  // the source's filled holes
  glUniform1i(im.uniform("hole_res"), 1 << a.hole_level);
  glUniform1f(im.uniform("nw_a"), morph ? w.source[a.bands - 1] : 1.0f);
  glUniform1f(im.uniform("nw_b"), morph ? w.target[a.bands - 1] : 0.0f);
  glUniform1i(im.uniform("checker"), s.checker ? 1 : 0);

  for (int p = 0; p < a.num_patches; ++p) {
    glUniform1i(im.uniform("patch_index"), p);
    glUniform1i(im.uniform("layer_a"), p * a.bands);
    glUniform1i(im.uniform("layer_b"), p * b.bands);
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(p) * index_count * sizeof(std::uint32_t)));
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glBindVertexArray(0);
}

Offscreen::Offscreen(int width, int height) : width_(width), height_(height) {
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glGenRenderbuffers(1, &color_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("geomip-view: offscreen framebuffer incomplete");
}

Offscreen::~Offscreen() {
  glDeleteFramebuffers(1, &fbo_);
  glDeleteRenderbuffers(1, &color_);
  glDeleteRenderbuffers(1, &depth_);
}

void Offscreen::bind() const { glBindFramebuffer(GL_FRAMEBUFFER, fbo_); }

void Offscreen::blit_to_window(int window_w, int window_h) const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, window_w, window_h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
}

std::vector<std::uint8_t> Offscreen::read_rgb() const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width_) * height_ * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width_) * height_ * 3);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[(static_cast<std::size_t>(height_ - 1 - y) * width_ + x) * 3 + c] =
            rgba[(static_cast<std::size_t>(y) * width_ + x) * 4 + c];
  return rgb;
}

}  // namespace geomip::viewer
