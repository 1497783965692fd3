#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/errors.h"

namespace cslam {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(AtomicFile, WritesAndCreatesFolders) {
  const fs::path dir = fs::temp_directory_path() / "cslam_atomic_test";
  fs::remove_all(dir);
  const fs::path file = dir / "a" / "b.txt";
  WriteFileAtomically(file.string(), [](std::ostream& o) { o << "hello"; });
  EXPECT_EQ(Slurp(file), "hello");
  EXPECT_FALSE(fs::exists(TemporaryPathFor(file.string())));
  fs::remove_all(dir);
}

TEST(AtomicFile, AFailingWriterLeavesTheOldFileIntact) {
  const fs::path dir = fs::temp_directory_path() / "cslam_atomic_test2";
  fs::remove_all(dir);
  const fs::path file = dir / "t.txt";
  WriteFileAtomically(file.string(), [](std::ostream& o) { o << "old"; });
  EXPECT_ANY_THROW(WriteFileAtomically(file.string(), [](std::ostream& o) {
    o << "partial";
    throw std::runtime_error("interrupted");
  }));
  EXPECT_EQ(Slurp(file), "old");
  fs::remove_all(dir);
}

TEST(AtomicFile, UnwritableFolderIsAnOutputError) {
  if (::geteuid() == 0) {
    // root ignores permissions; a path under a regular file is unwritable for everyone.
  }
  const fs::path blocker = fs::temp_directory_path() / "cslam_atomic_blocker";
  { std::ofstream(blocker) << "x"; }
  EXPECT_THROW(WriteFileAtomically((blocker / "sub" / "f.txt").string(), [](std::ostream&) {}),
               OutputError);
  fs::remove(blocker);
}

}  // namespace
}  // namespace cslam
