#include "package_uris.h"

#include <ros/package.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace onedof_sim {
namespace {

bool isPackageName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-' || c == '.';
  });
}

// The path after `package://PKG/` (up to the end of the attribute or element text) leaves the
// package's folder once normalised.
bool leavesPackage(const std::string& xml, size_t path_start) {
  const size_t end = xml.find_first_of("\"'<> \t\r\n", path_start);
  const std::filesystem::path path =
      std::filesystem::path(xml.substr(path_start, end - path_start)).lexically_normal();
  return path.is_absolute() || (!path.empty() && *path.begin() == "..");
}

}  // namespace

bool resolvePackageUris(std::string* xml, std::string* missing) {
  static const std::string kPrefix = "package://";
  size_t start = xml->find(kPrefix);
  while (start != std::string::npos) {
    const size_t name_start = start + kPrefix.size();
    const size_t slash = xml->find('/', name_start);
    if (slash == std::string::npos) break;
    const std::string package = xml->substr(name_start, slash - name_start);
    // One that leaves its package stays a package:// URI, which names no file.
    if (!isPackageName(package) || leavesPackage(*xml, slash + 1)) {
      start = xml->find(kPrefix, name_start);
      continue;
    }
    const std::string folder = ros::package::getPath(package);
    if (folder.empty()) {
      *missing = package;
      return false;
    }
    xml->replace(start, slash - start, folder);
    start = xml->find(kPrefix, start + folder.size());
  }
  return true;
}

}  // namespace onedof_sim
