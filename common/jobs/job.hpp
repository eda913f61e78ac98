// Jobs: one application of the thesis (chapter 3, 5.1) run end to end from a job file in the
// thesis's configuration format (4.8, A.3; config/config_file.hpp).
//
//   job = offset                 // the application (job_application_names())
//   input  { shape = knot }      // shared sections: see jobs/job_context.hpp
//   raster { resolution = 128  band = 3 }
//   offset { distance = 0.15 }   // the application's own set (its keys: see configs/jobs/)
//   output { mesh = ply }
//
// run_job: checks the keys (unknown ones are errors with "did you mean"), builds the input,
//   runs the application and writes into options.output_dir (created): STEM.lsg (the final
//   level set), STEM.ply (its surface, or what the application produces: a path, labels),
//   STEM.stats.json (the job, the application's measurements, timings, the outputs) and
//   STEM.log (the progress lines). STEM = options.name without directory and ".conf".
// run_job_file: reads the file, applies `overrides` ("a.b=value", the CLI's --set) and runs it
//   with base_dir = the file's directory and name = the file's name.
// Errors: config errors at FILE:LINE:COLUMN; those of the application and the readers;
//   Error{Cancelled} from options.progress. Outputs written before an error stay.
// Threading: the applications use TBB inside; one job per call.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config_file.hpp"
#include "jobs/job_context.hpp"

namespace levelset::jobs {

struct JobResult {
  std::string application;
  std::vector<std::string> outputs;  // files written, in order
  nlohmann::json stats;              // what STEM.stats.json holds
  double seconds = 0;
};

JobResult run_job(const config::Set& job, const JobOptions& options);
JobResult run_job_file(const std::string& path, const std::vector<std::string>& overrides, JobOptions options);

std::vector<std::string> job_application_names();

}  // namespace levelset::jobs
