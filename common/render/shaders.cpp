#include "render/shaders.hpp"

#include <string>

#include "core/error.hpp"

namespace levelset::render {

namespace {

const char* kColorMap = R"(
vec3 diverging(float t) {
  t = clamp(t, -1.0, 1.0);
  vec3 white = vec3(0.92);
  return t < 0.0 ? mix(white, vec3(0.75, 0.12, 0.1), -t) : mix(white, vec3(0.15, 0.3, 0.8), t);
}
)";

const char* kSurfaceVertex = R"(
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in float scalar;
uniform mat4 mvp;
uniform mat4 model_view;
uniform float point_size;
out vec3 view_position;
out vec3 view_normal;
out float vertex_scalar;
void main() {
  gl_Position = mvp * vec4(position, 1.0);
  view_position = (model_view * vec4(position, 1.0)).xyz;
  view_normal = mat3(model_view) * normal;
  vertex_scalar = scalar;
  gl_PointSize = point_size;
})";

// mode 0: smooth (vertex normals), 1: flat (the face's normal from screen derivatives),
// 2: unlit. Two-sided: the normal faces the viewer. Light: a view-space direction.
const char* kSurfaceFragment = R"(
in vec3 view_position;
in vec3 view_normal;
in float vertex_scalar;
uniform int mode;
uniform vec3 color;
uniform vec3 light;
uniform float scalar_scale;  // 0: plain colour; else the diverging map of scalar / scale
out vec4 fragment;
void main() {
  vec3 base = scalar_scale > 0.0 ? diverging(vertex_scalar / scalar_scale) : color;
  if (mode == 2) { fragment = vec4(base, 1.0); return; }
  vec3 n = mode == 1 ? normalize(cross(dFdx(view_position), dFdy(view_position))) : normalize(view_normal);
  vec3 to_eye = normalize(-view_position);
  if (dot(n, to_eye) < 0.0) n = -n;
  float diffuse = max(dot(n, light), 0.0);
  float specular = pow(max(dot(reflect(-light, n), to_eye), 0.0), 32.0);
  fragment = vec4(base * (0.15 + 0.85 * diffuse) + vec3(0.25 * specular), 1.0);
})";

const char* kMarkersVertex = R"(
layout(location = 0) in vec3 position;
layout(location = 1) in float value;
uniform mat4 mvp;
uniform float point_size;
uniform float range_min;
uniform float range_max;
out float marker_value;
out float keep;
void main() {
  keep = value >= range_min && value <= range_max ? 1.0 : 0.0;
  // Out of range: beyond the far plane, clipped before rasterization.
  gl_Position = keep > 0.5 ? mvp * vec4(position, 1.0) : vec4(0.0, 0.0, 2.0, 1.0);
  gl_PointSize = point_size;
  marker_value = value;
})";

const char* kMarkersFragment = R"(
in float marker_value;
in float keep;
uniform float scale;  // 0: plain colour
uniform vec3 color;
out vec4 fragment;
void main() {
  if (keep < 0.5) discard;
  fragment = vec4(scale > 0.0 ? diverging(marker_value / scale) : color, 1.0);
})";

// The slice: a quad in the plane axis = position, corners from the texture box.
const char* kSliceVertex = R"(
uniform mat4 mvp;
uniform vec3 box_min;
uniform vec3 box_max;
uniform int axis;
uniform float position;  // 0..1 across the box
out vec3 texcoord;
void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  vec3 t = axis == 0 ? vec3(position, corner) : axis == 1 ? vec3(corner.x, position, corner.y) : vec3(corner, position);
  texcoord = t;
  gl_Position = mvp * vec4(mix(box_min, box_max, t), 1.0);
})";

const char* kSliceFragment = R"(
in vec3 texcoord;
uniform sampler3D volume;
uniform float scale;
out vec4 fragment;
void main() {
  float v = texture(volume, texcoord).r;
  float w = fwidth(v);
  vec3 c = diverging(v / scale);
  if (abs(v) < 1.0 * w) c = vec3(0.0);
  fragment = vec4(c, 1.0);
})";

const char* kVolumeVertex = R"(
out vec2 ndc;
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
  ndc = p;
  gl_Position = vec4(p, 0.0, 1.0);
})";

const char* kVolumeFragment = R"(
in vec2 ndc;
uniform mat4 inverse_mvp;
uniform vec3 eye;
uniform vec3 box_min;
uniform vec3 box_max;
uniform sampler3D volume;
uniform float step_length;  // world units
uniform float width;        // transfer function half-width, world units
uniform float opacity;      // peak opacity per step_length
uniform vec3 light;         // towards the light, world frame
uniform float scale;        // colour scale (world units)
out vec4 fragment;
float sample_at(vec3 p) { return texture(volume, (p - box_min) / (box_max - box_min)).r; }
void main() {
  vec4 far_point = inverse_mvp * vec4(ndc, 1.0, 1.0);
  vec3 dir = normalize(far_point.xyz / far_point.w - eye);
  vec3 inv = 1.0 / dir;
  vec3 t0 = (box_min - eye) * inv, t1 = (box_max - eye) * inv;
  vec3 lo = min(t0, t1), hi = max(t0, t1);
  float t = max(max(lo.x, lo.y), max(lo.z, 0.0));
  float t_end = min(min(hi.x, hi.y), hi.z);
  if (t_end <= t) discard;
  vec3 texel = (box_max - box_min) / vec3(textureSize(volume, 0));
  vec4 acc = vec4(0.0);
  for (int i = 0; i < 4096 && t < t_end && acc.a < 0.98; ++i) {
    vec3 p = eye + dir * t;
    float v = sample_at(p);
    float far_from_peak = abs(v) - 2.0 * width;
    if (far_from_peak > step_length) { t += far_from_peak; continue; }  // a distance: skip empty space
    float x = v / width;
    // A Gaussian bump on the value, cut to zero at |x| = 2 (the band's far values stay clear).
    float alpha = opacity * max(0.0, exp(-x * x) - 0.0183) / 0.9817;
    if (alpha > 0.001) {
      vec3 g = vec3(sample_at(p + vec3(texel.x, 0, 0)) - sample_at(p - vec3(texel.x, 0, 0)),
                    sample_at(p + vec3(0, texel.y, 0)) - sample_at(p - vec3(0, texel.y, 0)),
                    sample_at(p + vec3(0, 0, texel.z)) - sample_at(p - vec3(0, 0, texel.z)));
      vec3 n = length(g) > 0.0 ? normalize(g) : -dir;
      if (dot(n, dir) > 0.0) n = -n;
      float diffuse = max(dot(n, light), 0.0);
      float specular = pow(max(dot(reflect(-light, n), -dir), 0.0), 24.0);
      vec3 c = diverging(v / scale) * (0.2 + 0.8 * diffuse) + vec3(0.3 * specular);
      acc.rgb += (1.0 - acc.a) * alpha * c;
      acc.a += (1.0 - acc.a) * alpha;
    }
    t += step_length;
  }
  fragment = acc;
})";

unsigned compile(const GlFunctions& gl, GLenum type, const char* body, const char* name) {
  const std::string source = std::string("#version 330 core\n") + kColorMap + body;
  const char* text = source.c_str();
  const unsigned shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &text, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    gl.DeleteShader(shader);
    throw Error(ErrorCode::IoError, std::string("shader ") + name, log);
  }
  return shader;
}

}  // namespace

unsigned build_program(const GlFunctions& gl, Program program) {
  const char *vs = nullptr, *fs = nullptr, *name = nullptr;
  switch (program) {
    case Program::Surface: vs = kSurfaceVertex, fs = kSurfaceFragment, name = "surface"; break;
    case Program::Markers: vs = kMarkersVertex, fs = kMarkersFragment, name = "markers"; break;
    case Program::Slice: vs = kSliceVertex, fs = kSliceFragment, name = "slice"; break;
    case Program::Volume: vs = kVolumeVertex, fs = kVolumeFragment, name = "volume"; break;
  }
  const unsigned v = compile(gl, GL_VERTEX_SHADER, vs, name);
  const unsigned f = compile(gl, GL_FRAGMENT_SHADER, fs, name);
  const unsigned p = gl.CreateProgram();
  gl.AttachShader(p, v);
  gl.AttachShader(p, f);
  gl.LinkProgram(p);
  gl.DeleteShader(v);
  gl.DeleteShader(f);
  GLint ok = 0;
  gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetProgramInfoLog(p, sizeof log, nullptr, log);
    gl.DeleteProgram(p);
    throw Error(ErrorCode::IoError, std::string("shader ") + name, std::string("link: ") + log);
  }
  return p;
}

}  // namespace levelset::render
