// The bench tools' command lines (--key value pairs) and their two ways of failing: a usage
// error, which the tool prints with its usage, and a refused world call, named by what it did.
#pragma once

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

namespace onedof_sim::tools {

struct UsageError {
  std::string what;
};

class Options {
 public:
  Options(int argc, char** argv, int first) {
    for (int i = first; i < argc; i += 2) {
      const std::string key = argv[i];
      if (key.rfind("--", 0) != 0 || i + 1 >= argc) throw UsageError{"bad option " + key};
      values_[key.substr(2)] = argv[i + 1];
    }
  }
  std::string text(const std::string& key) const {
    const auto found = values_.find(key);
    if (found == values_.end()) throw UsageError{"missing --" + key};
    return found->second;
  }
  double number(const std::string& key) const { return parse(text(key), key); }
  // A comma-separated list.
  std::vector<std::string> texts(const std::string& key) const {
    std::vector<std::string> out;
    std::stringstream list(text(key));
    for (std::string item; std::getline(list, item, ',');) out.push_back(item);
    return out;
  }
  std::vector<double> numbers(const std::string& key) const {
    std::vector<double> out;
    for (const std::string& item : texts(key)) out.push_back(parse(item, key));
    return out;
  }

 private:
  static double parse(const std::string& value, const std::string& key) {
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(number))
      throw UsageError{"--" + key + " wants finite numbers, got '" + value + "'"};
    return number;
  }
  std::map<std::string, std::string> values_;
};

inline std::string readFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw UsageError{"cannot read " + path};
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

inline void check(const onedof_sim::Status& status, const std::string& doing) {
  if (status.ok()) return;
  std::ostringstream why;
  why << doing << ": " << status;
  throw std::runtime_error(why.str());
}

// The world of the node's default world file: the ground plane model (F of --ground, the
// package's models/ground_plane/model.sdf) at the origin, placed first as that world places it.
inline void addGround(onedof_sim::World& world, const Options& options) {
  check(world.spawn("ground_plane", readFile(options.text("ground")), onedof_sim::ModelFormat::Sdf,
                    onedof_sim::Pose()),
        "spawn the ground plane");
}

// A tool's main: runs the mode its first argument names with the options after it. A usage error
// is printed with the usage (exit status 2), any other failure on its own (status 1).
using Mode = std::function<int(const Options&)>;
inline int runMode(int argc, char** argv, const std::string& tool, const std::string& usage,
                   const std::map<std::string, Mode>& modes) {
  try {
    const auto found = modes.find(argc > 1 ? argv[1] : "");
    if (found == modes.end()) {
      std::string names;
      for (const auto& entry : modes) names += (names.empty() ? "" : ", ") + entry.first;
      throw UsageError{"the first argument is the mode: " + names};
    }
    return found->second(Options(argc, argv, 2));
  } catch (const UsageError& error) {
    std::cerr << tool << ": " << error.what << "\n" << usage << std::endl;
    return 2;
  } catch (const std::exception& error) {
    std::cerr << tool << ": " << error.what() << std::endl;
    return 1;
  }
}

}  // namespace onedof_sim::tools
