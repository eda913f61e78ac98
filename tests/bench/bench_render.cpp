// bench_render: offscreen frames per second of levelset_render on this machine (Mesa llvmpipe
// through EGL surfaceless unless a GPU's EGL device is present), split into draw (up to
// glFinish), read-back and JPEG encoding (quality 85). Figures are printed, nothing is asserted
// on them (targets: >= 30 fps for the 100k-triangle mesh, >= 15 fps for the 1M-triangle mesh
// while moving, i.e. with its simplified copy).
//
// Scenes: a tube around the (2,3) torus knot meshed directly (exact triangle counts), and the
// knot's narrow band (build_from_sdf, resolution 256, half-width 3) for the volume rendering.
// Usage: bench_render [--quick] [--osmesa]   (--quick: small sizes and few frames, for ctest)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "render/offscreen_context.hpp"
#include "render/scene_renderer.hpp"
#include "surface/marching_cubes.hpp"

using namespace levelset;
using namespace levelset::render;

namespace {

using Clock = std::chrono::steady_clock;
Vec3d normalize(const Vec3d& v) { return v / length(v); }
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// A closed tube of radius a around the (2,3) torus knot (R = 1, r = 0.4): `around` x `along`
// quads, 2 * around * along triangles.
TriangleMesh knot_tube(int along, int around) {
  auto curve = [](double t) {
    const double r = 1.0 + 0.4 * std::cos(3 * t);
    return Vec3d{r * std::cos(2 * t), r * std::sin(2 * t), 0.4 * std::sin(3 * t)};
  };
  TriangleMesh m;
  const double a = 0.15;
  for (int i = 0; i < along; ++i) {
    const double t = 2 * M_PI * i / along, dt = 1e-4;
    const Vec3d p = curve(t), tangent = normalize(curve(t + dt) - curve(t - dt));
    const Vec3d side = normalize(cross(tangent, Vec3d{0, 0, 1})), up = cross(side, tangent);
    for (int j = 0; j < around; ++j) {
      const double s = 2 * M_PI * j / around;
      m.vertices.push_back(p + (side * std::cos(s) + up * std::sin(s)) * a);
    }
  }
  for (int i = 0; i < along; ++i)
    for (int j = 0; j < around; ++j) {
      const auto v = [&](int ii, int jj) { return std::uint32_t(((ii + along) % along) * around + (jj + around) % around); };
      m.triangles.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      m.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
  return m;
}

struct Figures {
  double draw = 0, read = 0, encode = 0, bytes = 0;
  int frames = 0;
};

// `frames` frames orbiting the scene (yaw steps), each encoded as JPEG; the first frame (shader
// warm-up, band sampling) is drawn before timing starts and reported separately.
Figures measure(SceneRenderer& renderer, ViewSettings view, int frames, double* first_ms) {
  const auto t0 = Clock::now();
  encode_jpeg(renderer.render(view), 85);
  if (first_ms) *first_ms = ms_since(t0);
  Figures f;
  for (int i = 0; i < frames; ++i) {
    view.camera.yaw += 3;
    FrameTiming timing;
    const Image image = renderer.render(view, &timing);
    const auto e = Clock::now();
    const std::string jpeg = encode_jpeg(image, 85);
    f.encode += ms_since(e);
    f.draw += timing.draw_ms;
    f.read += timing.read_ms;
    f.bytes += double(jpeg.size());
    ++f.frames;
  }
  return f;
}

void print(const char* what, const Figures& f, double first_ms, double target_fps) {
  const double n = f.frames, total = (f.draw + f.read + f.encode) / n;
  std::printf("  %-44s %6.1f fps  (draw %6.2f ms, read-back %5.2f ms, JPEG %5.2f ms, %5.1f KB; first frame %6.1f ms)%s\n",
              what, 1000.0 / total, f.draw / n, f.read / n, f.encode / n, f.bytes / n / 1024, first_ms,
              target_fps > 0 ? (1000.0 / total >= target_fps ? "  [target met]" : "  [below target]") : "");
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, osmesa = false;
  for (int i = 1; i < argc; ++i) {
    quick |= std::strcmp(argv[i], "--quick") == 0;
    osmesa |= std::strcmp(argv[i], "--osmesa") == 0;
  }
  try {
    auto context = create_offscreen_context(osmesa ? ContextKind::OsMesa : ContextKind::Egl);
    std::printf("bench_render: %s, %s%s\n", context->platform().c_str(), context->renderer_name().c_str(),
                quick ? " (--quick)" : "");
    const int frames = quick ? 3 : 30;
    ViewSettings view;  // 800x600, smooth
    bool ok = true;

    // 1. A 100k-triangle mesh, smooth shaded.
    {
      const auto t = Clock::now();
      SceneRenderer renderer(context->gl());
      renderer.set_scene(SceneData{knot_tube(quick ? 500 : 1000, 50), {}, nullptr, nullptr, nullptr});
      const double upload = ms_since(t);
      double first = 0;
      const Figures f = measure(renderer, view, frames, &first);
      std::printf("  mesh %zu triangles, upload %.0f ms\n", renderer.scene().mesh.triangles.size(), upload);
      print("800x600 JPEG, smooth", f, first, 30);
      ok &= f.frames == frames;
    }
    // 2. A 1M-triangle mesh: still, and moving (the simplified copy).
    {
      const auto t = Clock::now();
      SceneOptions options;  // the default budget (200k triangles); --quick: a quarter of the mesh
      if (quick) options.moving_triangle_budget = 50000;
      SceneRenderer renderer(context->gl(), options);
      renderer.set_scene(SceneData{knot_tube(quick ? 1000 : 5000, 100), {}, nullptr, nullptr, nullptr});
      const double upload = ms_since(t);
      std::printf("  mesh %zu triangles, upload + simplification %.0f ms, simplified copy %zu triangles\n",
                  renderer.scene().mesh.triangles.size(), upload, renderer.simplified_triangles());
      double first = 0;
      const Figures still = measure(renderer, view, quick ? 2 : 10, &first);
      print("800x600 JPEG, smooth, still", still, first, 0);
      ViewSettings moving = view;
      moving.moving = true;
      const Figures f = measure(renderer, moving, frames, &first);
      print("800x600 JPEG, smooth, moving (simplified)", f, first, 15);
      ok &= renderer.simplified_triangles() > 0;
    }
    // 3. Volume rendering of the knot's band.
    {
      const int resolution = quick ? 64 : 256;
      const auto shape = make_builtin_shape("knot");
      SdfBuildOptions options;
      options.frame = frame_for_resolution(shape->bounds(), resolution, 3.0);
      const auto t = Clock::now();
      auto band = std::make_shared<NarrowBand>(
          build_from_sdf([&](const Vec3d& p) { return shape->distance(p); }, shape->bounds(), options).band);
      std::printf("  knot band %d^3: %zu active voxels, built in %.0f ms\n", resolution, band->active_voxel_count(),
                  ms_since(t));
      SceneRenderer renderer(context->gl());
      renderer.set_scene(SceneData{marching_cubes(*band).mesh, {}, band, nullptr, nullptr});
      ViewSettings v = view;
      v.shading = Shading::None;
      v.volume = true;
      double first = 0;
      const Figures volume = measure(renderer, v, quick ? 2 : 10, &first);
      print("800x600 JPEG, volume rendering", volume, first, 0);
      v.volume = false;
      v.slice = SliceAxis::Z;
      v.shading = Shading::Smooth;
      const Figures slice = measure(renderer, v, quick ? 2 : 10, &first);
      print("800x600 JPEG, smooth + slice", slice, first, 0);
      v.slice = SliceAxis::None;
      v.field = true;
      v.range_min = -band->voxel_size(), v.range_max = band->voxel_size();
      const Figures field = measure(renderer, v, quick ? 2 : 10, &first);
      print("800x600 JPEG, smooth + field points |u| < h", field, first, 0);
    }
    return ok ? 0 : 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_render: %s\n", e.what());
    return 1;
  }
}
