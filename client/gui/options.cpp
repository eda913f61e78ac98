#include "options.hpp"

#include <CLI/CLI.hpp>

namespace levelset::gui {

Options parse_options(int argc, char** argv) {
  Options o;
  CLI::App app{"levelset-gui: the desktop client of levelsetd (thesis table 4.1 control panel)"};
  app.add_option("--server", o.server, "levelsetd URL (http://HOST:PORT); default: the saved one, else a local daemon");
  app.add_option("--token", o.token, "bearer token for the server");
  app.add_flag("--embedded", o.embedded, "start a local `levelsetd serve --port 0` even when a server was saved");
  app.add_option("--levelsetd", o.levelsetd, "the levelsetd binary for the local daemon (default: beside this one)");
  app.add_option("--data", o.data_dir, "the local daemon's data directory (default: levelsetd's)");
  app.add_option("--script", o.script, "run the UI actions in FILE (client/gui/README.md lists them), then quit");
  app.add_option("--screenshot", o.screenshot, "write a PNG of the window when the script ends (or once the surface shows)");
  app.add_option("--dump-state", o.dump, "write the window's state as JSON when it closes");
  app.add_option("--settings", o.settings, "settings file (default: $XDG_CONFIG_HOME/levelset/gui.json)");
  app.add_option("--width", o.width, "window width")->check(CLI::Range(320, 8192));
  app.add_option("--height", o.height, "window height")->check(CLI::Range(240, 8192));
  app.add_option("--fps", o.fps_limit, "frame rate limit (0: none)")->check(CLI::Range(0.0, 1000.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e) == 0 ? 0 : 2);
  }
  return o;
}

}  // namespace levelset::gui
