// sessions list | create (--primitive NAME | --upload ID [--param k=v ...]) [--resolution N] [--name N] [--wait]
//          | show ID | delete ID | snapshot ID [--name N]
//          | roi ID [--from-session S | --snapshot N | --clear]  (the region of influence formulas read as roi)
#include <cstdio>
#include <memory>

#include "commands/commands.hpp"
#include "lib/client_error.hpp"

namespace levelset::client {

using nlohmann::json;

namespace {

struct SessionArgs {
  std::string id, primitive, upload, name, from_session, snapshot;
  std::vector<std::string> params;
  int resolution = 0;
  bool json = false, wait = false, clear = false;
};

std::string text_of(const json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return "-";
  return j[key].is_string() ? j[key].get<std::string>() : j[key].dump();
}

std::string session_path(const std::string& id) { return "/api/v1/sessions/" + Api::encode(id); }

}  // namespace

void add_session_commands(CLI::App& app, Globals& g) {
  CLI::App* s = app.add_subcommand("sessions", "List, create, show, delete and snapshot sessions");
  s->require_subcommand(1);
  auto a = std::make_shared<SessionArgs>();

  CLI::App* list = s->add_subcommand("list", "One line per session: id, version, name");
  list->add_flag("--json", a->json, "Print the server's JSON");
  list->callback([a, &g] {
    const json r = g.api().get("/api/v1/sessions");
    if (a->json) return print_json(r);
    for (const json& x : r.value("sessions", json::array()))
      std::printf("%s\tv%s\t%s\n", text_of(x, "id").c_str(), text_of(x, "version").c_str(), text_of(x, "name").c_str());
  });

  CLI::App* create = s->add_subcommand("create", "Create a session from a built-in shape or an upload; prints its id");
  auto* prim = create->add_option("--primitive", a->primitive, "Built-in shape (sphere box torus dumbbell knot)");
  create->add_option("--resolution", a->resolution, "Voxels along the longest side (raster.resolution)")
      ->check(CLI::Range(8, 4096));
  auto* up = create->add_option("--upload", a->upload, "Upload id (a mesh, points, an image or an .lsg)");
  prim->excludes(up);
  create->add_option("--param", a->params, "With --upload: a parameter of the job that makes the session, key=value")
      ->allow_extra_args(false);
  create->add_option("--name", a->name, "Session name");
  create->add_flag("--wait", a->wait, "When a job creates the session (uploads of meshes), wait for it");
  create->callback([a, &g] {
    if (a->primitive.empty() == a->upload.empty())
      throw ClientError(ClientError::Kind::Usage, "usage", "sessions create needs --primitive NAME or --upload ID");
    json body = json::object();
    if (!a->primitive.empty()) {
      body["primitive"] = a->primitive;
      if (!a->params.empty())
        throw ClientError(ClientError::Kind::Usage, "usage", "--param goes with --upload (a primitive takes --resolution)");
    } else {
      body["upload"] = a->upload;
      for (const std::string& p : a->params) apply_param(body, p);
    }
    if (a->resolution > 0) body["raster"]["resolution"] = a->resolution;
    if (!a->name.empty()) body["name"] = a->name;
    const Api api = g.api();
    int status = 0;
    const json r = api.post("/api/v1/sessions", body, &status);
    if (status != 202) {
      std::printf("%s\n", r.value("id", "").c_str());
      return;
    }
    const std::string job = r.value("id", "");
    if (!a->wait) {
      std::fprintf(stderr, "job %s creates the session (levelsetctl jobs wait %s)\n", job.c_str(), job.c_str());
      std::printf("%s\n", job.c_str());
      return;
    }
    const json done = wait_for_job(api, job, false);
    std::printf("%s\n", done["result"].value("session", "").c_str());
  });

  CLI::App* show = s->add_subcommand("show", "A session as JSON");
  show->add_option("id", a->id, "Session id")->required();
  show->callback([a, &g] { print_json(g.api().get(session_path(a->id))); });

  CLI::App* del = s->add_subcommand("delete", "Delete a session and its files");
  del->add_option("id", a->id, "Session id")->required();
  del->callback([a, &g] { g.api().del(session_path(a->id)); });

  CLI::App* snap = s->add_subcommand("snapshot", "Snapshot the current version; prints the snapshot as JSON");
  snap->add_option("id", a->id, "Session id")->required();
  snap->add_option("--name", a->name, "Snapshot name");
  snap->callback([a, &g] {
    json body = json::object();
    if (!a->name.empty()) body["name"] = a->name;
    print_json(g.api().post(session_path(a->id) + "/snapshots", body));
  });

  CLI::App* roi = s->add_subcommand("roi", "Store the session's region of influence (formulas read it as roi): its "
                                           "committed band, a snapshot's or another session's; prints the session");
  roi->add_option("id", a->id, "Session id")->required();
  auto* from = roi->add_option("--from-session", a->from_session, "Another session whose committed band it becomes");
  auto* snapshot = roi->add_option("--snapshot", a->snapshot, "A snapshot of this session whose band it becomes");
  auto* clear = roi->add_flag("--clear", a->clear, "Remove the region of influence");
  from->excludes(snapshot)->excludes(clear);
  snapshot->excludes(clear);
  roi->callback([a, &g] {
    const Api api = g.api();
    if (a->clear) {
      api.del(session_path(a->id) + "/roi");
      return print_json(api.get(session_path(a->id)));
    }
    json body = json::object();
    if (!a->from_session.empty()) body["session"] = a->from_session;
    if (!a->snapshot.empty()) body["snapshot"] = a->snapshot;
    print_json(api.put(session_path(a->id) + "/roi", body));
  });
}

}  // namespace levelset::client
