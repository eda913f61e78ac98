// JobContext: what one application's job mapping (jobs/*_job.cpp) gets from the runner.
//
// Typed reads of the job tree with the place of every error ("job.conf:12:5: ..."), the
// shared input section (a built-in shape, a mesh, or an .lsg -> a NarrowBand), the output
// writers (OUTDIR/STEM.lsg, OUTDIR/STEM.ply, ...) and the stats / log the runner saves.
//
// Sections every job may have (besides `job = NAME` and its application's own set):
//   input  { shape = knot | mesh = FILE | lsg = FILE  ... }   what the level set starts from
//   raster { resolution = 128  band = 3 }   or  raster { depth = 7 }  (the thesis's: 2^depth)
//            or voxel_size = H: the grid of a level set built from a shape or a mesh
//   output { mesh = ply|obj|off|stl|none  lsg = yes|no  method = mc|nets }
// File names are words or quoted strings; relative ones resolve against the job file's
// directory; "cgal:meshes/knot.off" names CGAL's sample data ($LEVELSET_CGAL_DATA, or
// /usr/local/share/levelset/cgal-data/data). With JobOptions::confine_inputs (the daemon),
// inputs must stay inside the base directory after resolving "..": Error{InvalidArgument}.
// Threading: one job per context; the applications parallelise inside.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config_file.hpp"
#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"
#include "jobs/measures_json.hpp"
#include "surface/mesh_measures.hpp"
#include "surface/surface_result.hpp"

namespace levelset::jobs {

struct JobOptions {
  std::string output_dir = "out";
  std::string base_dir = ".";          // relative input paths resolve here
  std::string name = "job";            // errors say "NAME:LINE:COL"; also the output stem
  bool confine_inputs = false;         // inputs must resolve inside base_dir (server use)
  std::function<void(std::string_view line)> log;  // progress lines (also to OUTDIR/STEM.log)
  ProgressHook progress;  // cancel, and stop (evolution-like jobs end at a step boundary)

  // In-memory use (the daemon's sessions). input_band: the level set an input set with none of
  // shape / mesh / lsg starts from. band_sink: receives every band the job writes as
  // STEM<suffix>.lsg (also when output { lsg = no } leaves the file out). on_step: called after each step of the evolve job,
  // from the calling thread (previews, checkpoints).
  std::shared_ptr<const NarrowBand> input_band;
  std::uint64_t max_domain_voxels = 0;  // shapes and meshes: the grid box's voxel budget (0: the builders')
  std::function<void(const NarrowBand& band, std::string_view suffix)> band_sink;
  std::function<void(const evolve::StepInfo& step)> on_step;
  // Fields for speed formulas (jobs/speed_fields.hpp) when the job file names none: the
  // session's point cloud (dist, dgx..) and region of influence (roi).
  std::shared_ptr<const PointCloud> points;
  std::shared_ptr<const NarrowBand> roi;
};

class JobContext {
 public:
  JobContext(const config::Set& root, const JobOptions& options);

  const config::Set& root() const { return root_; }
  const JobOptions& options() const { return options_; }

  // The set `key` of the root (empty when absent); its keys are checked against `allowed`.
  const config::Set& section(std::string_view key, const std::vector<std::string>& allowed) const;
  bool has(const config::Set& set, std::string_view key) const { return set.find(key) != nullptr; }

  // Typed values of `set`'s entry `key` (fallback when absent), range-checked with the place.
  double number(const config::Set& set, std::string_view key, double fallback, double lo, double hi) const;
  int integer(const config::Set& set, std::string_view key, int fallback, int lo, int hi) const;
  bool flag(const config::Set& set, std::string_view key, bool fallback) const;  // yes/no/true/false/1/0
  std::string word(const config::Set& set, std::string_view key, std::string fallback,
                   const std::vector<std::string>& choices = {}) const;
  std::string text(const config::Set& set, std::string_view key, std::string fallback) const;  // formulas
  Vec3d vec3(const config::Set& set, std::string_view key, Vec3d fallback) const;
  std::vector<Vec3d> points(const config::Set& set, std::string_view key) const;  // ((x,y,z),...) or one tuple of 3n
  // An input file named by `key` (required): resolved as described above; must exist.
  std::string input_path(const config::Set& set, std::string_view key) const;
  // "NAME:LINE:COL" of an entry, for errors the mapping raises itself.
  std::string place(const config::Set& set, std::string_view key) const;

  // The raster section: voxels along the longest side (default `fallback`) and band half-width.
  struct Raster {
    int resolution = 128;
    double voxel_size = 0;  // > 0 overrides resolution
    double band = 3;
  };
  Raster raster(int fallback_resolution = 128, double fallback_band = 3) const;

  // The level set of an input set: `shape` (built-in analytic), `mesh` (closest point
  // transform of a triangle mesh) or `lsg` (a saved band), on the raster's grid; shapes and
  // meshes may be placed with `scale = s` and `translate = (x, y, z)` (x -> s x + t).
  // The input set's keys are the caller's to check (input_keys() lists these).
  NarrowBand input_band(const config::Set& input) const;
  static std::vector<std::string> input_keys() { return {"shape", "mesh", "lsg", "scale", "translate"}; }

  // Outputs (paths recorded in outputs(); the mesh measures go to stats()["mesh"]).
  void write_band(const NarrowBand& band, std::string_view suffix = "");
  MeshMeasures write_surface(const NarrowBand& band, std::string_view suffix = "");
  void write_mesh(const TriangleMesh& mesh, std::string_view suffix = "");
  // The surface of a band by the output's method, and its measures (nothing written).
  SurfaceResult surface_of(const NarrowBand& band) const;
  MeshMeasures measure_band(const NarrowBand& band) const;
  std::string output_path(std::string_view file_name) const;  // OUTDIR/file_name

  // Before any work (run_job calls it): the output section's values are valid, and no file the
  // job names is one this job could write (OUTDIR/STEM*.lsg|.ply|...|.log|.json, compared by
  // directory identity): Error{InvalidArgument | IoError} at the entry's place.
  void check_outputs() const;

  void log(const std::string& line) const;
  nlohmann::json& stats() { return stats_; }
  const std::vector<std::string>& outputs() const { return outputs_; }
  void add_output(const std::string& path) { outputs_.push_back(path); }

 private:
  const config::Entry& entry(const config::Set& set, std::string_view key) const;
  const config::Set& output_section() const;  // output { mesh lsg method }, keys checked

  const config::Set& root_;
  JobOptions options_;
  nlohmann::json stats_ = nlohmann::json::object();
  std::vector<std::string> outputs_;
};

// The output stem of a job name: its file name without ".conf" ("job" when empty).
std::string stem(std::string_view job_name);

}  // namespace levelset::jobs
