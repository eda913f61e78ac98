// The applications a job can run (jobs/job.hpp): each maps its set of the job file to its
// library function (common/apps/) and writes its outputs through the JobContext. One file
// each: jobs/<name>_job.cpp.
#pragma once

#include <string_view>
#include <vector>

#include "evolve/evolution.hpp"
#include "jobs/job_context.hpp"

namespace levelset::jobs {

using Application = void (*)(JobContext&);

struct ApplicationEntry {
  std::string_view name;     // `job = NAME`, and the name of its own set in the file
  Application run;
  std::string_view summary;  // one line for --help and errors
};

// All applications, in the order the README lists them.
const std::vector<ApplicationEntry>& applications();

void run_reconstruct_job(JobContext& context);
void run_evolve_job(JobContext& context);
void run_offset_job(JobContext& context);
void run_fair_job(JobContext& context);
void run_minmax_job(JobContext& context);
void run_csg_job(JobContext& context);
void run_segment_job(JobContext& context);
void run_path_job(JobContext& context);
void run_voronoi_job(JobContext& context);

// For the jobs that drive the evolution engine: the options from a set with the keys of the
// evolve job (speed, c, eps, constants, steps | time, scheme, rk, cfl, redistance_every,
// drift_tolerance, extension, report_every), and the result as JSON.
evolve::EvolutionOptions evolution_options_from(JobContext& context, const config::Set& set);
nlohmann::json evolution_json(const evolve::EvolutionResult& result);

}  // namespace levelset::jobs
