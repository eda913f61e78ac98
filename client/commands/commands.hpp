// levelsetctl's subcommands: each add_* function registers one command group on the CLI11 app;
// the callbacks throw ClientError, which main turns into "levelsetctl: CODE: MESSAGE" and
// its exit code.
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lib/api.hpp"
#include "lib/progress_view.hpp"

namespace levelset::client {

struct Globals {
  std::string server = "http://127.0.0.1:8080";
  std::string token;
  Api api() const { return Api(server, token); }
};

void add_upload_command(CLI::App& app, Globals& g);
void add_download_commands(CLI::App& app, Globals& g);
void add_session_commands(CLI::App& app, Globals& g);
void add_job_commands(CLI::App& app, Globals& g);
void add_run_command(CLI::App& app, Globals& g);

// Helpers shared by the commands.
void print_json(const nlohmann::json& j);  // pretty, to stdout
// Applies "a.b=value" to a request body (nested objects for dotted keys; the value as JSON when
// it parses: numbers, true, [1, 2]; else as a string). ClientError{Usage} when malformed.
void apply_param(nlohmann::json& body, const std::string& assignment);
// Follows a job to its end, progress on stderr (and its log lines when `logs`); returns the
// final description; ClientError unless it succeeded.
nlohmann::json wait_for_job(const Api& api, const std::string& job_id, bool logs,
                            ProgressView::Mode mode = ProgressView::Mode::Auto);

}  // namespace levelset::client
