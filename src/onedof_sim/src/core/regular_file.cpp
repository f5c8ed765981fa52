#include "regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace onedof_sim {
namespace core {

namespace fs = std::filesystem;

FileCheck checkRegularFile(const fs::path& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  FileCheck check;
  if (status.type() == fs::file_type::not_found) return check;
  if (error) {
    check.code = FileCheck::Code::Unreadable;
    return check;
  }
  if (!fs::is_regular_file(status)) {
    check.code = FileCheck::Code::NotRegular;
    check.type = status.type();
    return check;
  }
  check.code = ::access(path.c_str(), R_OK) == 0 ? FileCheck::Code::Readable
                                                 : FileCheck::Code::Unreadable;
  return check;
}

std::string fileTypeName(fs::file_type type) {
  switch (type) {
    case fs::file_type::regular: return "regular file";
    case fs::file_type::directory: return "directory";
    case fs::file_type::fifo: return "FIFO";
    case fs::file_type::character: return "character device";
    case fs::file_type::block: return "block device";
    case fs::file_type::socket: return "socket";
    default: return "special file";
  }
}

FileRead readRegularFile(const std::string& path, size_t max_bytes, std::string* bytes,
                         uintmax_t* size) {
  *size = 0;
  if (!checkRegularFile(path).readable()) return FileRead::Unreadable;
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return FileRead::Unreadable;
  struct stat info {};
  FileRead result = FileRead::Ok;
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) result = FileRead::Unreadable;
  *size = result == FileRead::Ok ? uintmax_t(info.st_size) : 0;
  if (result == FileRead::Ok && *size > max_bytes) result = FileRead::TooLarge;
  if (result == FileRead::Ok) {
    bytes->resize(size_t(*size));
    size_t done = 0;
    while (done < bytes->size()) {
      const ssize_t n = ::read(fd, &(*bytes)[done], bytes->size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += size_t(n);
    }
    bytes->resize(done);  // a file that shrank as it was read: what it held
  }
  ::close(fd);
  return result;
}

}  // namespace core
}  // namespace onedof_sim
