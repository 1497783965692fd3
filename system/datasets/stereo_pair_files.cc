#include "system/datasets/stereo_pair_files.h"

#include <stdexcept>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

fs::path NormalizedFolder(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty() && p.has_parent_path()) p = p.parent_path();
  return p;
}

void ListStereoPairs(const std::string& left_dir, const std::string& right_dir,
                     std::vector<std::string>* left_files, std::vector<std::string>* right_files) {
  *left_files = ListPngFiles(left_dir);
  *right_files = ListPngFiles(right_dir);
  if (left_files->size() != right_files->size())
    throw InputError(right_dir, "expected as many right images as left images in " + left_dir +
                                    " (" + std::to_string(left_files->size()) + "), got " +
                                    std::to_string(right_files->size()));
  for (size_t i = 0; i < left_files->size(); ++i) {
    const fs::path l = fs::path((*left_files)[i]).filename(), r = fs::path((*right_files)[i]).filename();
    if (l != r)
      throw InputError((*right_files)[i], "expected the right image " + l.string() +
                                              " to pair with " + (*left_files)[i]);
  }
}

StereoFrame LoadStereoPair(const std::vector<std::string>& left_files,
                           const std::vector<std::string>& right_files,
                           const std::vector<double>& timestamps, const StereoCamera& camera,
                           int index) {
  if (index < 0 || index >= static_cast<int>(left_files.size()))
    throw std::out_of_range("stereo frame " + std::to_string(index) + " is out of range [0, " +
                            std::to_string(left_files.size()) + ")");
  StereoFrame frame;
  frame.index = index;
  frame.timestamp = timestamps[static_cast<size_t>(index)];
  frame.left = LoadGreyImage(left_files[static_cast<size_t>(index)], camera.width, camera.height);
  frame.right = LoadGreyImage(right_files[static_cast<size_t>(index)], camera.width, camera.height);
  return frame;
}

}  // namespace cslam
