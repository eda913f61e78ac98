// The command line of levelset-gui.
#pragma once

#include <string>

namespace levelset::gui {

struct Options {
  std::string server;           // "": the saved server, else the embedded daemon
  std::string token;
  bool embedded = false;        // --embedded: always start a local daemon
  std::string levelsetd;        // the daemon binary for the embedded default ("": find it)
  std::string data_dir;         // the embedded daemon's --data ("": its default)
  std::string script;           // --script FILE
  std::string screenshot;       // --screenshot PATH
  std::string dump;             // --dump-state PATH (JSON, when the window closes)
  std::string settings;         // the settings file ("": $XDG_CONFIG_HOME/levelset/gui.json)
  int width = 0, height = 0;    // 0: the saved size
  double fps_limit = 60;
};

// Parses argv; exits (0 for --help, 2 with the reason) when it cannot.
Options parse_options(int argc, char** argv);

}  // namespace levelset::gui
