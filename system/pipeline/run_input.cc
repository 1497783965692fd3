#include "system/pipeline/run_input.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/logging.h"
#include "system/datasets/dataset.h"
#include "system/datasets/kitti_odometry_reader.h"
#include "system/io/input_files.h"
#include "system/synthetic/synthetic_image_io.h"
#include "system/synthetic/synthetic_io.h"

namespace cslam {

namespace fs = std::filesystem;

void InputOptions::Check() const {
  CheckOption(max_frames >= 0, "max_frames", "must be >= 0 (0 = all frames)", max_frames);
}

void InputOptions::Load(OptionsReader& r) {
  r.Read("color", &color);
  r.Read("max_frames", &max_frames);
  r.Read("use_images", &use_images);
}

namespace {

// Limits a source to its first n frames without touching the files beyond them.
class TruncatedSource : public StereoSource {
 public:
  TruncatedSource(std::unique_ptr<StereoSource> inner, int n) : inner_(std::move(inner)), n_(n) {
    timestamps_.assign(inner_->timestamps().begin(), inner_->timestamps().begin() + n_);
  }
  std::string name() const override { return inner_->name(); }
  std::string kind() const override { return inner_->kind(); }
  const StereoCamera& camera() const override { return inner_->camera(); }
  int size() const override { return n_; }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  StereoFrame Load(int index) const override { return inner_->Load(index); }
  std::optional<std::vector<Pose>> GroundTruth() const override {
    auto gt = inner_->GroundTruth();
    if (gt && static_cast<int>(gt->size()) > n_) gt->resize(n_);
    return gt;
  }
  std::vector<std::vector<ObjectBox>> ObjectBoxes() const override {
    auto boxes = inner_->ObjectBoxes();
    if (static_cast<int>(boxes.size()) > n_) boxes.resize(n_);
    return boxes;
  }
  std::vector<std::pair<std::string, std::string>> DescriptionFiles() const override {
    return inner_->DescriptionFiles();
  }
  std::optional<GroundTruthCrossCheck> CrossCheck() const override {
    auto check = inner_->CrossCheck();
    if (check && static_cast<int>(check->positions.size()) > n_) check->positions.resize(n_);
    if (check && static_cast<int>(check->position_accuracy_m.size()) > n_)
      check->position_accuracy_m.resize(n_);
    return check;
  }

 private:
  std::unique_ptr<StereoSource> inner_;
  int n_;
  std::vector<double> timestamps_;
};

void TruncateSynthetic(SyntheticSequence* s, int n) {
  if (n <= 0 || n >= s->num_frames()) return;
  s->observations = s->observations.Slice({0, n});
  s->timestamps.resize(n);
  s->world_from_cam.resize(n);
  for (auto& traj : s->world_from_object) traj.resize(n);
}

// A raw rig re-recorded from a rendered synthetic sequence (cslam synth --rig) names the
// sequence in synthetic_truth.txt. Rectified back to the rendered camera (its
// opencv_rectified.yml), its images are the sequence's again: it is scored on the sequence's
// truth, objects included. Any other rectification has another camera: the rig's own ground
// truth (groundtruth_tum.txt via --gt) scores the camera only.
void UseSyntheticTruthOfARig(const std::string& path, int max_frames, RunInput* in) {
  const fs::path marker = fs::path(path) / "synthetic_truth.txt";
  std::error_code ec;
  if (!fs::is_regular_file(marker, ec)) return;
  std::ifstream f = OpenTextFile(marker.string(), "synthetic truth marker");
  std::string rel;
  std::getline(f, rel);
  fs::path dir_path = (fs::path(path) / rel).lexically_normal();
  if (dir_path.filename().empty()) dir_path = dir_path.parent_path();  // "rig/.." → "seq/" → "seq"
  const std::string dir = dir_path.string();
  SyntheticSequence seq = ReadSynthetic(dir);
  TruncateSynthetic(&seq, max_frames);
  const StereoCamera &a = in->camera, &b = seq.camera;
  const bool same = std::abs(a.fx - b.fx) < 1e-9 && std::abs(a.fy - b.fy) < 1e-9 && std::abs(a.cx - b.cx) < 1e-9 &&
                    std::abs(a.cy - b.cy) < 1e-9 && std::abs(a.baseline - b.baseline) < 1e-9 &&
                    a.width == b.width && a.height == b.height;
  if (!same || seq.num_frames() != in->num_frames()) {
    GetLogger("system")->info("{}: rectified to another camera than the rendered one of {}: scored on the "
                              "rig's own ground truth (--calib {}/opencv_rectified.yml scores objects too)",
                              path, dir, path);
    return;
  }
  in->kind = InputKind::kSyntheticImages;
  in->gt_world_from_cam = seq.world_from_cam;
  in->synthetic_dir = dir;
  in->synthetic = std::move(seq);
  GetLogger("system")->info("{}: rectified back to the rendered camera; scored on the synthetic truth of {}", path, dir);
}

bool HasImages(const fs::path& drive, const char* camera) {
  std::error_code ec;
  return fs::is_directory(drive / camera / "data", ec);
}

// Which pair of a KITTI raw drive to read: the one asked for, else the other when it is the
// only one there (a drive downloaded as colour only).
bool ChooseKittiRawPair(const std::string& path, bool color, std::vector<std::string>* notes) {
  const fs::path drive(path);
  const bool grey_pair = HasImages(drive, "image_00") && HasImages(drive, "image_01");
  const bool color_pair = HasImages(drive, "image_02") && HasImages(drive, "image_03");
  if (!grey_pair && !color_pair)
    throw InputError(path, "has no complete stereo pair: expected image_00/data and "
                           "image_01/data (grey) or image_02/data and image_03/data (colour)");
  if (color && !color_pair)
    throw InputError((drive / "image_02").string() + ", " + (drive / "image_03").string(),
                     "the colour pair was asked for (--cameras color or input.color) but is "
                     "missing; the drive has the grey pair image_00/01 (--cameras grey)");
  if (!color && !grey_pair) {
    notes->push_back(path + ": no grey pair (image_00/01); running on the colour pair "
                            "image_02/03, converted to grey");
    return true;
  }
  return color;
}

}  // namespace

RunInput OpenRunInput(const std::string& path, const InputOptions& options) {
  options.Check();
  RunInput in;
  in.path = path;
  const DatasetKind kind = DetectDataset(path);
  if (kind == DatasetKind::kSynthetic) {
    SyntheticSequence seq = ReadSynthetic(path);
    TruncateSynthetic(&seq, options.max_frames);
    in.name = seq.name.empty() ? fs::path(path).filename().string() : seq.name;
    in.camera = seq.camera;
    in.timestamps = seq.timestamps;
    in.gt_world_from_cam = seq.world_from_cam;
    if (HasSyntheticImages(path) && options.use_images) {
      in.kind = InputKind::kSyntheticImages;
      const std::string images_dir = SyntheticImagesDir(path);
      std::unique_ptr<StereoSource> src = std::make_unique<KittiOdometrySource>(images_dir);
      if (src->size() < static_cast<int>(in.timestamps.size()))
        throw InputError((fs::path(images_dir) / "image_0").string(),
                         "has " + std::to_string(src->size()) + " images but the sequence has " +
                             std::to_string(in.timestamps.size()) + " frames");
      if (src->size() > static_cast<int>(in.timestamps.size()))
        src = std::make_unique<TruncatedSource>(std::move(src), static_cast<int>(in.timestamps.size()));
      in.camera = src->camera();
      in.images = std::move(src);
    } else {
      in.kind = InputKind::kSynthetic;
      in.observations = seq.observations;
    }
    in.synthetic = std::move(seq);
    return in;
  }
  in.color = kind == DatasetKind::kKittiRaw ? ChooseKittiRawPair(path, options.color, &in.notes)
                                            : options.color;
  std::unique_ptr<StereoSource> src = OpenStereoSource(path, {in.color, options.calib, options.gt});
  if (options.max_frames > 0 && options.max_frames < src->size())
    src = std::make_unique<TruncatedSource>(std::move(src), options.max_frames);
  if (src->size() == 0) throw InputError(path, "contains no stereo frames");
  in.name = src->name();
  in.kind = ParseEnum(kInputKindNames, src->kind(), "input kind");
  in.camera = src->camera();
  in.timestamps = src->timestamps();
  in.gt_world_from_cam = src->GroundTruth();
  in.gt_boxes = src->ObjectBoxes();
  in.gt_cross_check = src->CrossCheck();
  in.description_files = src->DescriptionFiles();
  in.images = std::move(src);
  if (in.kind == InputKind::kEuroc) UseSyntheticTruthOfARig(path, options.max_frames, &in);
  return in;
}

RunInput SyntheticRunInput(SyntheticSequence sequence, int max_frames) {
  CheckOption(max_frames >= 0, "max_frames", "must be >= 0 (0 = all frames)", max_frames);
  TruncateSynthetic(&sequence, max_frames);
  RunInput in;
  in.path = "(generated)";
  in.name = sequence.name;
  in.kind = InputKind::kSynthetic;
  in.camera = sequence.camera;
  in.timestamps = sequence.timestamps;
  in.gt_world_from_cam = sequence.world_from_cam;
  in.observations = sequence.observations;
  in.synthetic = std::move(sequence);
  return in;
}

}  // namespace cslam
