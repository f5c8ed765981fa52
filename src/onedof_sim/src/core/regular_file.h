// The one check every reader of a file the simulator is given goes through (a world file, an
// <include>d model's file and its model.config, a mesh): the file must be a regular file this
// process may read. Told by its type before it is opened, so that a FIFO (whose open waits for a
// writer), a device (/dev/zero never ends) or a folder is refused instead of read. Private to the
// core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace onedof_sim {
namespace core {

struct FileCheck {
  enum class Code { Readable, Missing, NotRegular, Unreadable };
  Code code = Code::Missing;
  std::filesystem::file_type type = std::filesystem::file_type::none;  // NotRegular: what it is
  bool readable() const { return code == Code::Readable; }
};

// What is at `path` (symbolic links followed), never opening it.
FileCheck checkRegularFile(const std::filesystem::path& path);

// "directory", "FIFO", "character device", ... : what a file of `type` is, in words.
std::string fileTypeName(std::filesystem::file_type type);

enum class FileRead { Ok, Unreadable, TooLarge };

// The bytes of the regular file at `path`, at most max_bytes (*size: its size). Checked before it
// is opened (checkRegularFile), then opened without blocking and checked again on the open file,
// so that a FIFO or a device put in its place between the two is never read either.
FileRead readRegularFile(const std::string& path, size_t max_bytes, std::string* bytes,
                         uintmax_t* size);

}  // namespace core
}  // namespace onedof_sim
