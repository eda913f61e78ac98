// Analytic signed distance functions: the thesis's test shapes.
//
// distance(p) is the exact Euclidean signed distance to the surface (negative inside) for
// sphere, box, torus and dumbbell, and for the torus knot up to the curve refinement
// tolerance (~1e-12 of its size). All are 1-Lipschitz, which build_from_sdf relies on to
// skip empty regions. Units: world. Thread-safe (const, no shared state).
//
// - sphere:   center c, radius r
// - box:      center c, half extents e
// - torus:    center c, axis z, major radius R, minor radius r (genus 1)
// - dumbbell: two spheres of radius rs at c +- (d,0,0) joined by a bar of radius rb along x
//             (a surface of revolution; thesis fig. 3.1: pinches under mean curvature flow)
// - knot:     tube of radius a around the (p,q) torus knot on a torus (R, r) (genus 1)
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/bbox.hpp"
#include "core/vec3.hpp"

namespace levelset {

class AnalyticShape {
 public:
  virtual ~AnalyticShape() = default;
  virtual double distance(const Vec3d& p) const = 0;
  virtual BBox bounds() const = 0;
  virtual std::string name() const = 0;
  // Analytic enclosed volume and surface area where known (0 when not known in closed form).
  virtual double volume() const { return 0.0; }
  virtual double area() const { return 0.0; }
  virtual int genus() const = 0;
};

std::unique_ptr<AnalyticShape> make_sphere(const Vec3d& center, double radius);
std::unique_ptr<AnalyticShape> make_box(const Vec3d& center, const Vec3d& half_extents);
std::unique_ptr<AnalyticShape> make_torus(const Vec3d& center, double major, double minor);
std::unique_ptr<AnalyticShape> make_dumbbell(const Vec3d& center, double sphere_radius,
                                             double half_distance, double bar_radius);
std::unique_ptr<AnalyticShape> make_torus_knot(const Vec3d& center, int p, int q, double major,
                                               double minor, double tube_radius);

// Built-in defaults by name: sphere, box, torus, dumbbell, knot. Sizes are about 2-3 units.
// Throws Error{InvalidArgument} for an unknown name, listing the known ones.
std::unique_ptr<AnalyticShape> make_builtin_shape(std::string_view name);
const std::vector<std::string>& builtin_shape_names();

}  // namespace levelset
