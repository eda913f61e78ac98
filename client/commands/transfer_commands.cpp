// upload FILE [--format F]; download mesh SESSION -o FILE [--iso V] [--method mc|nets];
// download band SESSION -o FILE.lsg; download roi SESSION -o FILE.lsg; download points SESSION -o FILE.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands/commands.hpp"
#include "lib/client_error.hpp"
#include "lib/job_inputs.hpp"

namespace levelset::client {

namespace fs = std::filesystem;

namespace {

struct UploadArgs {
  std::string file, format;
  bool json = false;
};

struct DownloadArgs {
  std::string session, output, method = "mc";
  double iso = 0;
  bool iso_given = false;
};

std::string lower_extension(const std::string& file) {
  std::string ext = fs::path(file).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext.empty() ? ext : ext.substr(1);
}

}  // namespace

void add_upload_command(CLI::App& app, Globals& g) {
  auto a = std::make_shared<UploadArgs>();
  CLI::App* sub = app.add_subcommand("upload", "Upload a file (mesh, points, image or .lsg); prints its upload id");
  sub->add_option("file", a->file, "The file (streamed as the request body)")->required();
  sub->add_option("--format", a->format, "off ply obj stl tria xyz xyzn pwn inr nrrd lsg (default: from the extension)");
  sub->add_flag("--json", a->json, "Print the server's description of the upload instead of its id");
  sub->callback([a, &g] {
    const std::string format = a->format.empty() ? upload_format_of(a->file) : a->format;
    const nlohmann::json r = g.api().upload(a->file, format);
    if (a->json) {
      print_json(r);
    } else {
      std::printf("%s\n", r.value("id", "").c_str());
    }
  });
}

void add_download_commands(CLI::App& app, Globals& g) {
  CLI::App* dl = app.add_subcommand("download", "Download a session's surface, band, region of influence or points");
  dl->require_subcommand(1);
  auto m = std::make_shared<DownloadArgs>();
  CLI::App* mesh = dl->add_subcommand("mesh", "The surface as a mesh; the format from -o's extension (ply obj off stl)");
  mesh->add_option("session", m->session, "Session id")->required();
  mesh->add_option("-o,--output", m->output, "Output file (.ply .obj .off .stl)")->required();
  mesh->add_option("--iso", m->iso, "Iso value (world units; default 0)");
  mesh->add_option("--method", m->method, "mc (marching cubes) or nets (surface nets)")
      ->check(CLI::IsMember({"mc", "nets"}));
  mesh->callback([m, &g] {
    const std::string format = lower_extension(m->output);
    if (format != "ply" && format != "obj" && format != "off" && format != "stl")
      throw ClientError(ClientError::Kind::Usage, "unknown_format",
                        "cannot tell the mesh format of '" + m->output + "': use .ply, .obj, .off or .stl");
    char iso[64];
    std::snprintf(iso, sizeof iso, "%.17g", m->iso);
    g.api().download("/api/v1/sessions/" + Api::encode(m->session) + "/mesh?format=" + format + "&method=" +
                         Api::encode(m->method) + "&iso=" + Api::encode(iso),
                     m->output);
  });
  // download band | roi | points SESSION -o FILE: a session's file as the API gives it; the
  // bands are .lsg.
  struct FileRoute {
    const char *name, *route, *help, *output_help;
    bool lsg;
  };
  for (const FileRoute& f : {FileRoute{"band", "band", "The committed band as an .lsg file", "Output file (.lsg)", true},
                             FileRoute{"roi", "roi", "The region of influence as an .lsg file", "Output file (.lsg)", true},
                             FileRoute{"points", "points", "The session's point cloud, as uploaded (sessions show: points.format)",
                                       "Output file", false}}) {
    auto args = std::make_shared<DownloadArgs>();
    CLI::App* sub = dl->add_subcommand(f.name, f.help);
    sub->add_option("session", args->session, "Session id")->required();
    sub->add_option("-o,--output", args->output, f.output_help)->required();
    sub->callback([args, f, &g] {
      if (f.lsg && lower_extension(args->output) != "lsg")
        throw ClientError(ClientError::Kind::Usage, "unknown_format",
                          "a band is written as .lsg, not '" + args->output + "'");
      g.api().download("/api/v1/sessions/" + Api::encode(args->session) + "/" + f.route, args->output);
    });
  }
}

}  // namespace levelset::client
