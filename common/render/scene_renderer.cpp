#include "render/scene_renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/error.hpp"
#include "render/band_samples.hpp"
#include "render/camera.hpp"
#include "render/framebuffer.hpp"
#include "render/shaders.hpp"

namespace levelset::render {

namespace {

// A vertex array with its buffers (attribute location i in buffers[i]) and an element count.
struct Mesh {
  unsigned vao = 0, buffers[3] = {0, 0, 0}, indices = 0, simplified = 0;
  int count = 0, simplified_count = 0, vertices = 0;
};

void attribute(const GlFunctions& gl, Mesh& m, unsigned location, int components, const std::vector<float>& data) {
  if (m.buffers[location] == 0) gl.GenBuffers(1, &m.buffers[location]);
  gl.BindBuffer(GL_ARRAY_BUFFER, m.buffers[location]);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
  gl.VertexAttribPointer(location, components, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(location);
}

void elements(const GlFunctions& gl, unsigned& buffer, const std::vector<std::uint32_t>& data) {
  if (buffer == 0) gl.GenBuffers(1, &buffer);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffer);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(std::uint32_t)), data.data(), GL_STATIC_DRAW);
}

void release(const GlFunctions& gl, Mesh& m) {
  for (unsigned& b : m.buffers)
    if (b) gl.DeleteBuffers(1, &b);
  if (m.indices) gl.DeleteBuffers(1, &m.indices);
  if (m.simplified) gl.DeleteBuffers(1, &m.simplified);
  if (m.vao) gl.DeleteVertexArrays(1, &m.vao);
  m = Mesh{};
}

Mesh make_vao(const GlFunctions& gl) {
  Mesh m;
  gl.GenVertexArrays(1, &m.vao);
  gl.BindVertexArray(m.vao);
  return m;
}

std::vector<float> lines_of(const BandPoints& s, std::vector<float>& values) {
  std::vector<float> out;
  out.reserve(s.positions.size() * 2);
  values.clear();
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    out.insert(out.end(), s.positions.begin() + long(3 * i), s.positions.begin() + long(3 * i + 3));
    out.insert(out.end(), s.closest.begin() + long(3 * i), s.closest.begin() + long(3 * i + 3));
    values.push_back(s.values[i]);
    values.push_back(s.values[i]);
  }
  return out;
}

double milliseconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

struct SceneRenderer::State {
  const GlFunctions& gl;
  SceneOptions options;
  unsigned surface = 0, markers = 0, slice = 0, volume = 0, empty_vao = 0;
  Framebuffer framebuffer;
  SceneData scene;
  BBox box;
  Vec3d origin;
  Mesh mesh, cloud, field, vectors, boundary, roi;
  bool band_points_ready = false, curvature_ready = false, volume_ready = false, roi_ready = false;
  float curvature_scale = 1;
  unsigned texture = 0;
  DenseVolume dense;  // values released after upload

  State(const GlFunctions& g, SceneOptions o) : gl(g), options(o), framebuffer(g) {}

  void clear_scene() {
    for (Mesh* m : {&mesh, &cloud, &field, &vectors, &boundary, &roi}) release(gl, *m);
    if (texture) gl.DeleteTextures(1, &texture);
    texture = 0;
    band_points_ready = curvature_ready = volume_ready = roi_ready = false;
    dense = DenseVolume{};
  }

  // Voxel markers: position and value per band voxel.
  Mesh value_points(const BandPoints& s) {
    Mesh m = make_vao(gl);
    attribute(gl, m, 0, 3, s.positions);
    attribute(gl, m, 1, 1, s.values);
    m.vertices = int(s.values.size());
    return m;
  }

  void prepare_band_points() {
    if (band_points_ready || !scene.band) return;
    band_points_ready = true;
    const BandPoints s = sample_band_points(*scene.band, origin, options.max_band_points);
    field = value_points(s);
    std::vector<float> line_values;
    const std::vector<float> lines = lines_of(s, line_values);
    vectors = make_vao(gl);
    attribute(gl, vectors, 0, 3, lines);
    attribute(gl, vectors, 1, 1, line_values);
    vectors.vertices = int(line_values.size());
    boundary = make_vao(gl);
    attribute(gl, boundary, 0, 3, s.boundary);
    gl.DisableVertexAttribArray(1);
    boundary.vertices = int(s.boundary.size() / 3);
  }

  void prepare_roi_points() {
    if (roi_ready || !scene.roi) return;
    roi_ready = true;
    roi = value_points(sample_band_points(*scene.roi, origin, options.max_band_points));
  }

  void prepare_curvature() {
    if (curvature_ready || !scene.band || mesh.vao == 0) return;
    curvature_ready = true;
    const std::vector<float> h = vertex_curvature(scene.mesh, *scene.band);
    std::vector<float> magnitudes(h.size());
    std::transform(h.begin(), h.end(), magnitudes.begin(), [](float x) { return std::abs(x); });
    if (!magnitudes.empty()) {  // the colour scale: the 95th percentile of |H| (robust to spikes)
      auto at = magnitudes.begin() + long(0.95 * double(magnitudes.size() - 1));
      std::nth_element(magnitudes.begin(), at, magnitudes.end());
      curvature_scale = std::max(1e-6f, *at);
    }
    gl.BindVertexArray(mesh.vao);
    attribute(gl, mesh, 2, 1, h);
  }

  void prepare_volume() {
    if (volume_ready || !scene.band) return;
    volume_ready = true;
    dense = sample_dense_volume(*scene.band, options.max_volume_side);
    if (dense.values.empty()) return;
    gl.GenTextures(1, &texture);
    gl.BindTexture(GL_TEXTURE_3D, texture);
    gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
      gl.TexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, dense.nx, dense.ny, dense.nz, 0, GL_RED, GL_FLOAT, dense.values.data());
    dense.values = {};
  }

  void uniform(unsigned program, const char* name, float x) { gl.Uniform1f(gl.GetUniformLocation(program, name), x); }
  void uniform(unsigned program, const char* name, int x) { gl.Uniform1i(gl.GetUniformLocation(program, name), x); }
  void uniform(unsigned program, const char* name, const glm::vec3& v) {
    gl.Uniform3f(gl.GetUniformLocation(program, name), v.x, v.y, v.z);
  }
  void uniform(unsigned program, const char* name, const glm::mat4& m) {
    gl.UniformMatrix4fv(gl.GetUniformLocation(program, name), 1, GL_FALSE, glm::value_ptr(m));
  }

  // Markers: points or lines of band voxels; scale 0 draws `color`.
  void draw_markers(const Mesh& m, GLenum primitive, const glm::mat4& mvp, float size, float lo, float hi, float scale,
                    const glm::vec3& color) {
    if (m.vao == 0 || m.vertices == 0) return;
    gl.UseProgram(markers);
    uniform(markers, "mvp", mvp);
    uniform(markers, "point_size", size);
    uniform(markers, "range_min", lo);
    uniform(markers, "range_max", hi);
    uniform(markers, "scale", scale);
    uniform(markers, "color", color);
    gl.BindVertexArray(m.vao);
    gl.DrawArrays(primitive, 0, m.vertices);
  }

  void draw(const ViewSettings& view);
};

void SceneRenderer::State::draw(const ViewSettings& view) {
  const glm::vec3 background(view.background[0], view.background[1], view.background[2]);
  gl.ClearColor(background.x, background.y, background.z, 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.Disable(GL_BLEND);
  gl.Enable(GL_PROGRAM_POINT_SIZE);
  const CameraFrame cam = camera_frame(view, box, origin);
  const glm::mat4 mvp = cam.projection * cam.view;
  glm::vec3 light(view.light[0], view.light[1], view.light[2]);
  light = glm::normalize(light);
  const bool band = scene.band != nullptr;
  const float bg = band ? scene.band->background() : 1.0f;

  // The surface.
  if (view.shading != Shading::None && mesh.vao != 0 && mesh.count > 0) {
    const bool curvature = view.curvature && band;
    if (curvature) prepare_curvature();
    gl.UseProgram(surface);
    uniform(surface, "mvp", mvp);
    uniform(surface, "model_view", cam.view);
    uniform(surface, "color", glm::vec3(view.color[0], view.color[1], view.color[2]));
    uniform(surface, "light", light);
    uniform(surface, "point_size", 3.0f);
    uniform(surface, "scalar_scale", curvature && curvature_ready ? curvature_scale : 0.0f);
    uniform(surface, "mode", view.shading == Shading::Smooth ? 0 : view.shading == Shading::Flat ? 1 : 2);
    gl.BindVertexArray(mesh.vao);
    if (!(curvature && curvature_ready)) {
      gl.DisableVertexAttribArray(2);
      gl.VertexAttrib1f(2, 0.0f);
    } else {
      gl.EnableVertexAttribArray(2);
    }
    if (view.shading == Shading::Points) {
      gl.DrawArrays(GL_POINTS, 0, mesh.vertices);
    } else {
      const bool simple = view.moving && mesh.simplified_count > 0;
      gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, simple ? mesh.simplified : mesh.indices);
      gl.PolygonMode(GL_FRONT_AND_BACK, view.shading == Shading::Wireframe ? GL_LINE : GL_FILL);
      if (view.shading != Shading::Wireframe) {  // overlays on the surface stay visible
        gl.Enable(GL_POLYGON_OFFSET_FILL);
        gl.PolygonOffset(1.0f, 1.0f);
      }
      gl.DrawElements(GL_TRIANGLES, simple ? mesh.simplified_count : mesh.count, GL_UNSIGNED_INT, nullptr);
      gl.Disable(GL_POLYGON_OFFSET_FILL);
      gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
  }

  // The point cloud.
  constexpr float kAll = 3.0e38f;
  if (view.cloud)
    draw_markers(cloud, GL_POINTS, mvp, float(view.cloud_size), -kAll, kAll, 0.0f,
                 glm::vec3(view.cloud_color[0], view.cloud_color[1], view.cloud_color[2]));

  // The region of influence's points within the value range (its own colour scale).
  if (view.roi && scene.roi) {
    prepare_roi_points();
    const float roi_bg = scene.roi->background();
    const float lo = float(std::max(view.range_min, -3.0e38)), hi = float(std::min(view.range_max, 3.0e38));
    float scale = roi_bg;
    if (std::isfinite(view.range_min) && std::isfinite(view.range_max))
      scale = float(std::clamp(std::max(std::abs(view.range_min), std::abs(view.range_max)), 1e-9, double(roi_bg)));
    draw_markers(roi, GL_POINTS, mvp, 3.0f, lo, hi, scale, {});
  }

  // The band's overlays.
  if (band) {
    const float lo = float(std::max(view.range_min, -3.0e38)), hi = float(std::min(view.range_max, 3.0e38));
    float scale = bg;
    if (std::isfinite(view.range_min) && std::isfinite(view.range_max))
      scale = float(std::clamp(std::max(std::abs(view.range_min), std::abs(view.range_max)), 1e-9, double(bg)));
    if (view.field || view.vectors || view.boundary) prepare_band_points();
    if (view.field) draw_markers(field, GL_POINTS, mvp, 3.0f, lo, hi, scale, {});
    if (view.vectors) draw_markers(vectors, GL_LINES, mvp, 1.0f, lo, hi, scale, {});
    if (view.boundary) draw_markers(boundary, GL_POINTS, mvp, 2.0f, -kAll, kAll, 0.0f, glm::vec3(0.6f, 0.6f, 0.65f));
    if (view.slice != SliceAxis::None || view.volume) prepare_volume();
    if (texture != 0) {
      const Vec3d bmin = dense.box_min - origin, bmax = dense.box_max - origin;
      const glm::vec3 box_min(float(bmin.x), float(bmin.y), float(bmin.z)), box_max(float(bmax.x), float(bmax.y), float(bmax.z));
      gl.ActiveTexture(GL_TEXTURE0);
      gl.BindTexture(GL_TEXTURE_3D, texture);
      gl.BindVertexArray(empty_vao);
      if (view.slice != SliceAxis::None) {
        gl.UseProgram(slice);
        uniform(slice, "mvp", mvp);
        uniform(slice, "box_min", box_min);
        uniform(slice, "box_max", box_max);
        uniform(slice, "axis", view.slice == SliceAxis::X ? 0 : view.slice == SliceAxis::Y ? 1 : 2);
        uniform(slice, "position", float(view.slice_position));
        uniform(slice, "volume", 0);
        uniform(slice, "scale", bg);
        gl.DrawArrays(GL_TRIANGLE_STRIP, 0, 4);
      }
      if (view.volume) {
        const float h = float(dense.voxel_size);
        const float width = view.volume_width > 0 ? float(view.volume_width) : 1.5f * h;
        const glm::mat4 view_to_world = glm::inverse(cam.view);
        const glm::vec3 world_light = glm::normalize(glm::mat3(view_to_world) * light);
        const float texel = float((dense.box_max.x - dense.box_min.x) / std::max(1, dense.nx));
        gl.UseProgram(volume);
        uniform(volume, "inverse_mvp", glm::inverse(mvp));
        uniform(volume, "eye", cam.eye);
        uniform(volume, "box_min", box_min);
        uniform(volume, "box_max", box_max);
        uniform(volume, "volume", 0);
        uniform(volume, "step_length", 0.5f * texel);
        uniform(volume, "width", width);
        uniform(volume, "opacity", float(view.volume_opacity));
        uniform(volume, "light", world_light);
        uniform(volume, "scale", std::max(4.0f * width, 1e-9f));
        gl.Disable(GL_DEPTH_TEST);
        gl.Enable(GL_BLEND);
        gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);  // premultiplied, front to back done in the shader
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
        gl.Disable(GL_BLEND);
        gl.Enable(GL_DEPTH_TEST);
      }
    }
  }
}

SceneRenderer::SceneRenderer(const GlFunctions& gl, SceneOptions options)
    : state_(std::make_unique<State>(gl, options)) {
  State& s = *state_;
  s.surface = build_program(gl, Program::Surface);
  s.markers = build_program(gl, Program::Markers);
  s.slice = build_program(gl, Program::Slice);
  s.volume = build_program(gl, Program::Volume);
  gl.GenVertexArrays(1, &s.empty_vao);
}

SceneRenderer::~SceneRenderer() {
  State& s = *state_;
  s.clear_scene();
  for (unsigned p : {s.surface, s.markers, s.slice, s.volume}) s.gl.DeleteProgram(p);
  s.gl.DeleteVertexArrays(1, &s.empty_vao);
}

void SceneRenderer::set_scene(SceneData scene) {
  State& s = *state_;
  const GlFunctions& gl = s.gl;
  s.clear_scene();
  s.scene = std::move(scene);
  s.box = scene_bounds(s.scene);
  s.origin = s.box.empty() ? Vec3d{} : s.box.center();
  if (!s.scene.mesh.triangles.empty() || !s.scene.mesh.vertices.empty()) {
    const MeshArrays a = prepare_mesh(s.scene.mesh, s.origin, s.options, s.scene.simplified.get());
    s.mesh = make_vao(gl);
    attribute(gl, s.mesh, 0, 3, a.positions);
    attribute(gl, s.mesh, 1, 3, a.normals);
    elements(gl, s.mesh.indices, a.indices);
    s.mesh.count = int(a.indices.size());
    s.mesh.vertices = int(a.positions.size() / 3);
    if (!a.simplified.empty()) {
      elements(gl, s.mesh.simplified, a.simplified);
      s.mesh.simplified_count = int(a.simplified.size());
    }
  }
  if (!s.scene.points.points.empty()) {
    std::vector<float> p;
    p.reserve(s.scene.points.points.size() * 3);
    for (const Vec3d& q : s.scene.points.points) {
      const Vec3d r = q - s.origin;
      p.push_back(float(r.x)), p.push_back(float(r.y)), p.push_back(float(r.z));
    }
    s.cloud = make_vao(gl);
    attribute(gl, s.cloud, 0, 3, p);
    gl.DisableVertexAttribArray(1);
    s.cloud.vertices = int(s.scene.points.points.size());
  }
  gl.BindVertexArray(0);
}

const SceneData& SceneRenderer::scene() const { return state_->scene; }
BBox SceneRenderer::bounds() const { return state_->box; }
std::size_t SceneRenderer::simplified_triangles() const { return std::size_t(state_->mesh.simplified_count / 3); }

void SceneRenderer::draw(const ViewSettings& view) { state_->draw(view); }

Image SceneRenderer::render(const ViewSettings& view, FrameTiming* timing) {
  if (view.width < kMinSize || view.width > kMaxSize || view.height < kMinSize || view.height > kMaxSize)
    throw Error(ErrorCode::InvalidArgument, "view.width",
                "a frame is " + std::to_string(kMinSize) + " to " + std::to_string(kMaxSize) + " pixels on each side, not " +
                    std::to_string(view.width) + "x" + std::to_string(view.height));
  State& s = *state_;
  const auto start = std::chrono::steady_clock::now();
  s.framebuffer.bind(view.width, view.height);
  s.draw(view);
  s.gl.Finish();
  const auto drawn = std::chrono::steady_clock::now();
  Image image{view.width, view.height, s.framebuffer.read_rgb()};
  if (timing) {
    timing->draw_ms = std::chrono::duration<double, std::milli>(drawn - start).count();
    timing->read_ms = milliseconds_since(drawn);
  }
  return image;
}

}  // namespace levelset::render
