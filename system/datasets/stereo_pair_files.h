#pragma once
// Pieces shared by the image-folder readers: matched left/right file lists and pair decoding.
#include <filesystem>
#include <string>
#include <vector>

#include "core/stereo_camera.h"
#include "system/datasets/stereo_source.h"

namespace cslam {

/// `dir` without a trailing separator, so filename() is the folder's name.
std::filesystem::path NormalizedFolder(const std::string& dir);

/// Lists the PNGs of both folders and checks that they pair up one to one by file name.
/// Throws InputError naming the folder on missing/empty folders or unequal lists.
void ListStereoPairs(const std::string& left_dir, const std::string& right_dir,
                     std::vector<std::string>* left_files, std::vector<std::string>* right_files);

/// Decodes pair `index`, both images checked against the camera's size. Throws InputError on
/// a missing or corrupt image or a size mismatch, and
/// std::out_of_range for an index outside [0, size).
StereoFrame LoadStereoPair(const std::vector<std::string>& left_files,
                           const std::vector<std::string>& right_files,
                           const std::vector<double>& timestamps, const StereoCamera& camera,
                           int index);

}  // namespace cslam
