#pragma once
// Outputs are written to a temporary file beside the target and renamed into place, so a
// crash or an interrupt never leaves a truncated file under the final name.
#include <functional>
#include <ostream>
#include <string>

namespace cslam {

/// Writes `path` through `write(stream)` into "path.tmp" and renames it over `path`.
/// Creates missing parent folders. Throws OutputError naming the file on any failure.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Renames an already-written temporary file into place (for writers that need a file name,
/// e.g. image encoders and PCL). Throws OutputError on failure.
void CommitTemporaryFile(const std::string& tmp_path, const std::string& path);

/// The temporary name WriteFileAtomically uses for `path` (keeps the extension last, so
/// format-sniffing writers still work): "dir/.name.tmp.ext".
std::string TemporaryPathFor(const std::string& path);

/// Creates the folder `path` is to be written in (and its parents); throws OutputError naming
/// `path` when it cannot.
void CreateParentFolder(const std::string& path);

}  // namespace cslam
