// levelsetd serve [--host ADDR] [--port N] [--data DIR] [--token-file FILE] [--config FILE] ...:
// the daemon. Settings come from one table (service/service_config.hpp): config file <
// LEVELSET_* environment < flags. Prints "levelsetd listening on http://HOST:PORT" once bound.
// SIGINT / SIGTERM: stop taking work, stop running jobs at a step boundary (checkpointed,
// resumable), answer 503 meanwhile, exit 0 within the shutdown deadline.
#include <pthread.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <thread>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "api/http_server.hpp"
#include "commands/command.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "service/service.hpp"
#include "service/service_config.hpp"

namespace levelset::cli {

namespace {

struct ServeArgs {
  std::string config;
  std::map<std::string, std::string> values;
  std::map<std::string, CLI::Option*> options;
  bool insecure = false;
};

int serve(ServeArgs& a) {
  // Signals go to one waiting thread: block them before any other thread exists.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  // A file-size limit (ulimit -f) makes writes fail with EFBIG (a 507 for the job), not kill us.
  std::signal(SIGXFSZ, SIG_IGN);
  // A long-running daemon keeps no list of the files it touched (the batch CLI's guard).
  enable_output_guard(false);

  service::ServiceConfig config;
  const char* env_config = std::getenv("LEVELSET_CONFIG");
  if (!a.config.empty()) service::apply_config_file(config, a.config);
  else if (env_config != nullptr && *env_config != 0) service::apply_config_file(config, env_config);
  service::apply_environment(config);
  for (const service::ServiceOption& o : service::service_options()) {
    CLI::Option* opt = a.options[o.key];
    if (opt == nullptr || opt->count() == 0) continue;
    try {
      o.set(config, a.values[o.key]);
    } catch (const Error& e) {
      throw Error(ErrorCode::InvalidArgument, service::flag_name(o.key), e.reason());
    }
  }
  if (a.insecure) config.insecure_no_auth = true;
  service::finalize(config);

  auto logger = spdlog::stderr_logger_mt("levelsetd");
  logger->set_pattern(config.log_format == "json" ? "%v" : "[%Y-%m-%d %H:%M:%S.%e] %v");
  spdlog::set_default_logger(logger);

  service::Service service(config);
  for (const std::string& p : service.startup_problems()) spdlog::warn("not loaded: {}", p);
  api::HttpServer http(service);
  const int port = http.bind();
  spdlog::info("data {} ; {} sessions ; {} job workers", config.data_dir, service.sessions().count(), config.max_jobs);
  spdlog::info("render: {}", service.render_status());
  std::printf("levelsetd listening on http%s://%s:%d\n", config.tls_cert.empty() ? "" : "s", config.host.c_str(), port);
  std::fflush(stdout);

  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    spdlog::info("signal {}: stopping jobs at a step boundary, then exiting", sig);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                 std::chrono::duration<double>(config.shutdown_deadline * 0.8));
    service.shutdown(deadline);
    http.stop();
  });
  http.listen();
  // listen() also returns when the socket fails: make the waiter return too.
  pthread_kill(waiter.native_handle(), SIGTERM);
  waiter.join();
  spdlog::info("stopped");
  return 0;
}

}  // namespace

Command add_serve_command(CLI::App& app, int& threads) {
  (void)threads;
  auto a = std::make_shared<ServeArgs>();
  CLI::App* sub = app.add_subcommand(
      "serve", "Run the daemon: sessions, jobs and results over HTTP (settings: --config FILE < LEVELSET_* < flags)");
  sub->add_option("--config", a->config, "Settings file in the project's format (configs/server.conf documents every key)");
  for (const service::ServiceOption& o : service::service_options()) {
    if (o.key == "insecure_no_auth") {
      a->options[o.key] = sub->add_flag("--insecure-no-auth", a->insecure, o.help + " [" + service::env_name(o.key) + "]");
      continue;
    }
    a->options[o.key] = sub->add_option(service::flag_name(o.key), a->values[o.key], o.help + " [" + service::env_name(o.key) + "]");
  }
  return {sub, [a]() { return serve(*a); }};
}

}  // namespace levelset::cli
