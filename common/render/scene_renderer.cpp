#include "render/scene_renderer.hpp"

#include <cmath>
#include <cstdlib>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/error.hpp"
#include "core/text.hpp"

namespace levelset::render {

namespace {

constexpr double kFovDegrees = 40.0;

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 mvp;
uniform mat4 model_view;
out vec3 view_position;
out vec3 view_normal;
void main() {
  gl_Position = mvp * vec4(position, 1.0);
  view_position = (model_view * vec4(position, 1.0)).xyz;
  view_normal = mat3(model_view) * normal;
  gl_PointSize = 3.0;
})";

// mode 0: smooth (vertex normals), 1: flat (the face's normal from screen derivatives),
// 2: unlit colour (points, wireframe). A headlight with a little specular.
const char* kFragmentShader = R"(#version 330 core
in vec3 view_position;
in vec3 view_normal;
uniform int mode;
uniform vec3 color;
out vec4 fragment;
void main() {
  if (mode == 2) { fragment = vec4(color, 1.0); return; }
  vec3 n = mode == 1 ? normalize(cross(dFdx(view_position), dFdy(view_position))) : normalize(view_normal);
  vec3 to_eye = normalize(-view_position);
  if (dot(n, to_eye) < 0.0) n = -n;
  float diffuse = max(dot(n, to_eye), 0.0);
  float specular = pow(max(dot(reflect(-to_eye, n), to_eye), 0.0), 32.0);
  fragment = vec4(color * (0.15 + 0.85 * diffuse) + vec3(0.25 * specular), 1.0);
})";

unsigned compile(const GlFunctions& gl, GLenum type, const char* source) {
  const unsigned shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw Error(ErrorCode::IoError, "shader", log);
  }
  return shader;
}

double parse_finite(const std::string& key, const std::string& value, double lo, double hi) {
  char* end = nullptr;
  const double x = std::strtod(value.c_str(), &end);
  if (end == value.c_str() || *end != 0 || !std::isfinite(x) || x < lo || x > hi)
    throw Error(ErrorCode::InvalidArgument, "view." + key,
                "expected a number from " + format_number(lo) + " to " + format_number(hi) + ", found '" +
                    sanitize_utf8(value.substr(0, 40)) + "'");
  return x;
}

Shading parse_shading(const std::string& value) {
  if (value == "none") return Shading::None;
  if (value == "points") return Shading::Points;
  if (value == "wireframe") return Shading::Wireframe;
  if (value == "flat") return Shading::Flat;
  if (value == "smooth") return Shading::Smooth;
  throw Error(ErrorCode::InvalidArgument, "view.shading",
              "expected none, points, wireframe, flat or smooth, found '" + sanitize_utf8(value.substr(0, 40)) + "'");
}

std::string text_of(const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

}  // namespace

void apply_query(ViewSettings& view, const std::string& key, const std::string& value) {
  if (key == "yaw") view.yaw = parse_finite(key, value, -36000, 36000);
  else if (key == "pitch") view.pitch = parse_finite(key, value, -89.9, 89.9);
  else if (key == "zoom") view.zoom = parse_finite(key, value, -0.9, 100);
  else if (key == "shading") view.shading = parse_shading(value);
  else throw Error(ErrorCode::InvalidArgument, "view." + key.substr(0, 40), "unknown view setting (yaw, pitch, zoom, shading)");
}

void apply_json(ViewSettings& view, const nlohmann::json& settings) {
  if (!settings.is_object()) throw Error(ErrorCode::InvalidArgument, "view", "expected an object");
  for (const auto& [key, value] : settings.items()) {
    if (key == "camera") {
      if (!value.is_object()) throw Error(ErrorCode::InvalidArgument, "view.camera", "expected an object");
      for (const auto& [k, v] : value.items()) apply_query(view, k, text_of(v));
    } else if (key == "shading") {
      view.shading = parse_shading(text_of(value));
    } else if (key == "background" || key == "color") {
      if (!value.is_array() || value.size() != 3) throw Error(ErrorCode::InvalidArgument, "view." + key, "expected [r, g, b]");
      auto& rgb = key == "background" ? view.background : view.color;
      for (int i = 0; i < 3; ++i) rgb[i] = float(parse_finite(key, text_of(value[i]), 0, 1));
    }
    // Other keys belong to displays this renderer does not draw yet; they are kept, not refused.
  }
}

SceneRenderer::SceneRenderer(OffscreenContext& context) : context_(context) {
  const GlFunctions& gl = context_.gl();
  const unsigned vs = compile(gl, GL_VERTEX_SHADER, kVertexShader);
  const unsigned fs = compile(gl, GL_FRAGMENT_SHADER, kFragmentShader);
  program_ = gl.CreateProgram();
  gl.AttachShader(program_, vs);
  gl.AttachShader(program_, fs);
  gl.LinkProgram(program_);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  GLint ok = 0;
  gl.GetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) throw Error(ErrorCode::IoError, "shader", "the program does not link");
  gl.GenVertexArrays(1, &vao_);
  gl.GenBuffers(1, &positions_);
  gl.GenBuffers(1, &normals_);
  gl.GenBuffers(1, &indices_);
}

SceneRenderer::~SceneRenderer() {
  const GlFunctions& gl = context_.gl();
  gl.DeleteBuffers(1, &positions_);
  gl.DeleteBuffers(1, &normals_);
  gl.DeleteBuffers(1, &indices_);
  gl.DeleteVertexArrays(1, &vao_);
  gl.DeleteProgram(program_);
}

void SceneRenderer::set_mesh(const TriangleMesh& mesh) {
  const GlFunctions& gl = context_.gl();
  // Positions relative to the box centre in float; area-weighted vertex normals.
  const BBox box = mesh.bounds();
  const Vec3d c = box.empty() ? Vec3d{} : 0.5 * (box.min + box.max);
  center_ = {c.x, c.y, c.z};
  radius_ = box.empty() ? 1.0 : std::max(1e-9, 0.5 * length(box.max - box.min));
  std::vector<float> p(mesh.vertices.size() * 3), n(mesh.vertices.size() * 3, 0.0f);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3d q = mesh.vertices[i] - c;
    p[3 * i] = float(q.x), p[3 * i + 1] = float(q.y), p[3 * i + 2] = float(q.z);
  }
  std::vector<std::uint32_t> idx;
  idx.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    const Vec3d fn = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (std::uint32_t v : t) {
      n[3 * v] += float(fn.x), n[3 * v + 1] += float(fn.y), n[3 * v + 2] += float(fn.z);
      idx.push_back(v);
    }
  }
  gl.BindVertexArray(vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, positions_);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(p.size() * sizeof(float)), p.data(), GL_STATIC_DRAW);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(0);
  gl.BindBuffer(GL_ARRAY_BUFFER, normals_);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(n.size() * sizeof(float)), n.data(), GL_STATIC_DRAW);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(1);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices_);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx.size() * sizeof(std::uint32_t)), idx.data(), GL_STATIC_DRAW);
  index_count_ = int(idx.size());
  vertex_count_ = int(mesh.vertices.size());
}

Image SceneRenderer::render(const ViewSettings& view, int width, int height) {
  const GlFunctions& gl = context_.gl();
  context_.bind_framebuffer(width, height);
  gl.ClearColor(view.background[0], view.background[1], view.background[2], 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (view.shading != Shading::None && index_count_ > 0) {
    const double fov = glm::radians(kFovDegrees);
    const double distance = radius_ / std::sin(fov / 2) / (1.0 + view.zoom);
    const double yaw = glm::radians(view.yaw), pitch = glm::radians(view.pitch);
    const glm::vec3 eye(float(distance * std::cos(pitch) * std::sin(yaw)), float(distance * std::sin(pitch)),
                        float(distance * std::cos(pitch) * std::cos(yaw)));
    const glm::mat4 model_view = glm::lookAt(eye, glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
    const float near_plane = float(std::max(radius_ * 1e-3, distance - 1.1 * radius_));
    const glm::mat4 projection =
        glm::perspective(float(fov), float(width) / float(height), near_plane, float(distance + 1.1 * radius_));
    const glm::mat4 mvp = projection * model_view;
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Enable(GL_PROGRAM_POINT_SIZE);
    gl.UseProgram(program_);
    gl.UniformMatrix4fv(gl.GetUniformLocation(program_, "mvp"), 1, GL_FALSE, glm::value_ptr(mvp));
    gl.UniformMatrix4fv(gl.GetUniformLocation(program_, "model_view"), 1, GL_FALSE, glm::value_ptr(model_view));
    gl.Uniform3f(gl.GetUniformLocation(program_, "color"), view.color[0], view.color[1], view.color[2]);
    const int mode = view.shading == Shading::Smooth ? 0 : view.shading == Shading::Flat ? 1 : 2;
    gl.Uniform1i(gl.GetUniformLocation(program_, "mode"), mode);
    gl.BindVertexArray(vao_);
    if (view.shading == Shading::Points) {
      gl.DrawArrays(GL_POINTS, 0, vertex_count_);
    } else {
      gl.PolygonMode(GL_FRONT_AND_BACK, view.shading == Shading::Wireframe ? GL_LINE : GL_FILL);
      gl.DrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
      gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
  }
  gl.Finish();
  return {width, height, context_.read_rgb(width, height)};
}

}  // namespace levelset::render
