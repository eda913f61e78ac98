// levelsetctl: the command-line client of levelsetd serve, for scripts and workflow systems.
//   levelsetctl [--server URL] [--token T] COMMAND ...
// Exit codes: 0 the request worked (for jobs: the job succeeded); 1 the server refused or the
// job failed; 2 usage (also a malformed job file for `run`); 3 cannot connect (or the
// connection broke for good); 4 a local file could not be read or written. Errors print one
// line on stderr: "levelsetctl: CODE: MESSAGE".
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <CLI/CLI.hpp>

#include "commands/commands.hpp"
#include "lib/client_error.hpp"

#ifndef LEVELSET_VERSION
#define LEVELSET_VERSION "0.0.0"
#endif

namespace levelset::client {

void print_json(const nlohmann::json& j) {
  std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
}

}  // namespace levelset::client

namespace {

int fail(const std::string& code, const std::string& message, int exit_code) {
  std::fflush(stdout);
  std::fprintf(stderr, "levelsetctl: %s: %s\n", code.c_str(), message.c_str());
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace levelset::client;
  // A server that answers and closes while a body is still being sent must give an error, not
  // kill the client with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app("levelsetctl: command-line client of levelsetd serve", "levelsetctl");
  app.set_version_flag("--version", "levelsetctl " LEVELSET_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  Globals g;
  if (const char* s = std::getenv("LEVELSET_SERVER"); s != nullptr && *s != 0) g.server = s;
  if (const char* t = std::getenv("LEVELSET_TOKEN"); t != nullptr) g.token = t;
  app.add_option("--server", g.server, "Server URL (default: $LEVELSET_SERVER or http://127.0.0.1:8080)");
  app.add_option("--token", g.token, "Bearer token (default: $LEVELSET_TOKEN)");
  add_upload_command(app, g);
  add_session_commands(app, g);
  add_job_commands(app, g);
  add_download_commands(app, g);
  add_run_command(app, g);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail("usage", std::string(e.what()) + " (levelsetctl --help)", 2);
  } catch (const ClientError& e) {
    return fail(e.code(), e.message(), e.exit_code());
  } catch (const std::bad_alloc&) {
    return fail("out_of_memory", "out of memory", 1);
  } catch (const std::exception& e) {
    return fail("internal", e.what(), 1);
  }
  return 0;
}
