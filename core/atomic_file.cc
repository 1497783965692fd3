#include "core/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/errors.h"

namespace cslam {

namespace fs = std::filesystem;

std::string TemporaryPathFor(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / ("." + p.stem().string() + ".tmp" + p.extension().string())).string();
}

void CommitTemporaryFile(const std::string& tmp_path, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp_path, path, ec);
  if (ec) {
    fs::remove(tmp_path, ec);
    throw OutputError(path, "cannot move the finished file into place: " + ec.message());
  }
}

void CreateParentFolder(const std::string& path) {
  const fs::path p(path);
  std::error_code ec;
  if (p.has_parent_path()) {
    fs::create_directories(p.parent_path(), ec);
    if (ec) throw OutputError(path, "cannot create the folder: " + ec.message());
  }
}

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write) {
  CreateParentFolder(path);
  const std::string tmp = TemporaryPathFor(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError(path, "cannot open for writing (is the folder writable?)");
    write(out);
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw OutputError(path, "write failed (disk full?)");
    }
  }
  CommitTemporaryFile(tmp, path);
}

}  // namespace cslam
