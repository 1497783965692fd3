#include "system/synthetic/synthetic_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

namespace {

namespace fs = std::filesystem;

constexpr const char* kSequenceFile = "sequence.txt";
constexpr const char* kCameraFile = "camera.txt";
constexpr const char* kTimesFile = "times.txt";
constexpr const char* kCameraPosesFile = "gt_camera.txt";
constexpr const char* kObjectsDir = "gt_objects";
constexpr const char* kLandmarksFile = "gt_landmarks.csv";
constexpr const char* kObservationsFile = "observations.csv";
constexpr const char* kGeometryFile = "gt_geometry.csv";
constexpr const char* kObservationsHeader = "frame,landmark,uL,vL,uR,c00,c01,c02,c11,c12,c22";
constexpr const char* kLandmarksHeader = "landmark,object,x,y,z";
constexpr const char* kGeometryHeader = "object,kind,ox,oy,oz,ux,uy,uz,vx,vy,vz,r,g,b,texture";

/// Shortest decimal text that parses back to exactly `v`.
template <typename T>
std::string Num(T v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

std::string ObjectFile(int object) { return std::string(kObjectsDir) + "/" + std::to_string(object) + ".txt"; }

void WritePoseLine(std::ostream& out, const Pose& pose) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out << (r + c ? " " : "") << Num(pose.matrix()(r, c));
  out << '\n';
}

/// Reads one file line by line, splitting on a separator; errors name the file and the line.
class LineReader {
 public:
  LineReader(const std::string& dir, const std::string& name, char sep)
      : path_((fs::path(dir) / name).string()), in_(path_), sep_(sep) {
    if (!in_) throw InputError(path_, "cannot open (is this a synthetic sequence folder?)");
  }
  /// Next non-blank line not starting with '#', split into fields; false at the end.
  bool Next(std::vector<std::string>* fields) {
    std::string text;
    while (std::getline(in_, text)) {
      ++line_;
      if (!text.empty() && text.back() == '\r') text.pop_back();
      if (text.find_first_not_of(" \t") == std::string::npos || text[0] == '#') continue;
      fields->clear();
      if (sep_ == ' ') {
        std::istringstream s(text);
        for (std::string f; s >> f;) fields->push_back(f);
      } else {
        std::string f;
        std::istringstream s(text);
        while (std::getline(s, f, sep_)) fields->push_back(f);
        if (text.back() == sep_) fields->push_back("");
      }
      return true;
    }
    return false;
  }
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(path_, line_, what); }
  void ExpectFields(const std::vector<std::string>& fields, size_t n, const char* what) const {
    if (fields.size() != n)
      Fail("expected " + std::to_string(n) + " fields (" + what + "), found " +
           std::to_string(fields.size()));
  }
  double Double(const std::string& s, const char* what) const {
    double v = 0;
    const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
    if (res.ec != std::errc() || res.ptr != s.data() + s.size() || !std::isfinite(v))
      Fail(std::string("expected a finite number for ") + what + ", got '" + s + "'");
    return v;
  }
  int Int(const std::string& s, const char* what, int lo, int hi) const {
    int v = 0;
    const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
    if (res.ec != std::errc() || res.ptr != s.data() + s.size())
      Fail(std::string("expected an integer for ") + what + ", got '" + s + "'");
    if (v < lo || v > hi)
      Fail(std::string("expected ") + what + " in [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "], got " + s);
    return v;
  }
  const std::string& path() const { return path_; }
  int line() const { return line_; }

 private:
  std::string path_;
  std::ifstream in_;
  char sep_;
  int line_ = 0;
};

/// "key value" lines into a map; every key in `required` must be present exactly once.
std::map<std::string, std::string> ReadKeyValues(const std::string& dir, const std::string& name,
                                                 const std::vector<std::string>& required,
                                                 std::map<std::string, int>* lines) {
  LineReader in(dir, name, ' ');
  std::map<std::string, std::string> kv;
  std::vector<std::string> f;
  while (in.Next(&f)) {
    in.ExpectFields(f, 2, "key value");
    if (std::find(required.begin(), required.end(), f[0]) == required.end())
      in.Fail("unknown key '" + f[0] + "'");
    if (kv.count(f[0])) in.Fail("key '" + f[0] + "' given twice");
    kv[f[0]] = f[1];
    (*lines)[f[0]] = in.line();
  }
  for (const auto& key : required)
    if (!kv.count(key)) throw InputError(in.path(), "missing key '" + key + "'");
  return kv;
}

std::vector<Pose> ReadPoses(const std::string& dir, const std::string& name, int frames) {
  LineReader in(dir, name, ' ');
  std::vector<Pose> poses;
  std::vector<std::string> f;
  while (in.Next(&f)) {
    if (static_cast<int>(poses.size()) == frames)
      in.Fail("more poses than the " + std::to_string(frames) + " frames of sequence.txt");
    in.ExpectFields(f, 12, "a row-major 3x4 pose");
    Pose pose = Pose::Identity();
    for (int i = 0; i < 12; ++i) pose.matrix()(i / 4, i % 4) = in.Double(f[i], "a pose entry");
    const double err = (pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity())
                           .cwiseAbs().maxCoeff();
    if (err > 1e-6 || pose.linear().determinant() < 0)
      in.Fail("expected a rotation matrix in the first 3 columns");
    poses.push_back(pose);
  }
  if (static_cast<int>(poses.size()) != frames)
    throw InputError(in.path(), in.line(), "expected " + std::to_string(frames) +
                                               " poses (frames in sequence.txt), found " +
                                               std::to_string(poses.size()));
  return poses;
}

}  // namespace

void WriteSynthetic(const SyntheticSequence& seq, const std::string& dir) {
  const int frames = seq.num_frames(), objects = seq.num_objects();
  const int landmarks = static_cast<int>(seq.landmark_object.size());
  auto path = [&](const std::string& name) { return (fs::path(dir) / name).string(); };
  WriteFileAtomically(path(kSequenceFile), [&](std::ostream& out) {
    out << "# clusterslam synthetic sequence (docs/formats.md)\n"
        << "name " << seq.name << "\nframes " << frames << "\nobjects " << objects
        << "\nlandmarks " << landmarks << "\nobservations " << seq.observations.num_observations()
        << '\n';
  });
  WriteFileAtomically(path(kCameraFile), [&](std::ostream& out) {
    const StereoCamera& c = seq.camera;
    out << "# rectified stereo pair: pixels, metres\nfx " << Num(c.fx) << "\nfy " << Num(c.fy)
        << "\ncx " << Num(c.cx) << "\ncy " << Num(c.cy) << "\nbaseline " << Num(c.baseline)
        << "\nwidth " << c.width << "\nheight " << c.height << '\n';
  });
  WriteFileAtomically(path(kTimesFile), [&](std::ostream& out) {
    for (double t : seq.timestamps) out << Num(t) << '\n';
  });
  WriteFileAtomically(path(kCameraPosesFile), [&](std::ostream& out) {
    for (const Pose& p : seq.world_from_cam) WritePoseLine(out, p);
  });
  for (int o = 0; o < objects; ++o)
    WriteFileAtomically(path(ObjectFile(o)), [&](std::ostream& out) {
      for (const Pose& p : seq.world_from_object[o]) WritePoseLine(out, p);
    });
  WriteFileAtomically(path(kLandmarksFile), [&](std::ostream& out) {
    out << kLandmarksHeader << '\n';
    for (int l = 0; l < landmarks; ++l) {
      const Eigen::Vector3d& p = seq.landmark_in_object[l];
      out << l << ',' << seq.landmark_object[l] << ',' << Num(p.x()) << ',' << Num(p.y()) << ','
          << Num(p.z()) << '\n';
    }
  });
  WriteFileAtomically(path(kObservationsFile), [&](std::ostream& out) {
    out << kObservationsHeader << '\n';
    for (int f = 0; f < seq.observations.num_frames(); ++f) {
      for (const ObservationRef& ref : seq.observations.ObservationsAt(f)) {
        const StereoObservation& o = seq.observations.Get(ref);
        out << o.frame << ',' << o.landmark;
        for (int i = 0; i < 3; ++i) out << ',' << Num(o.x(i));
        for (int r = 0; r < 3; ++r)
          for (int c = r; c < 3; ++c) out << ',' << Num(o.cov(r, c));
        out << '\n';
      }
    }
  });
  WriteFileAtomically(path(kGeometryFile), [&](std::ostream& out) {
    out << kGeometryHeader << '\n';
    for (int o = 0; o < static_cast<int>(seq.geometry.bodies.size()); ++o) {
      const SceneBody& body = seq.geometry.bodies[o];
      for (const SceneQuad& q : body.quads) {
        out << o << ',' << body.kind;
        for (const Eigen::Vector3d* v : {&q.origin, &q.edge_u, &q.edge_v})
          for (int i = 0; i < 3; ++i) out << ',' << Num((*v)(i));
        for (int i = 0; i < 3; ++i) out << ',' << Num(q.color(i));
        out << ',' << q.texture << '\n';
      }
    }
  });
}

SyntheticSequence ReadSynthetic(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir, "not a folder");
  SyntheticSequence seq;
  constexpr int kMaxCount = 1 << 30;

  std::map<std::string, int> lines;
  const auto meta = ReadKeyValues(dir, kSequenceFile,
                                  {"name", "frames", "objects", "landmarks", "observations"}, &lines);
  const std::string meta_path = (fs::path(dir) / kSequenceFile).string();
  auto meta_int = [&](const std::string& key, int lo) {
    int v = 0;
    const std::string& s = meta.at(key);
    const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
    if (res.ec != std::errc() || res.ptr != s.data() + s.size() || v < lo)
      throw InputError(meta_path, lines.at(key),
                       "expected an integer >= " + std::to_string(lo) + " for " + key + ", got '" + s + "'");
    return v;
  };
  seq.name = meta.at("name");
  const int frames = meta_int("frames", 1), objects = meta_int("objects", 1);
  const int landmarks = meta_int("landmarks", 0), observations = meta_int("observations", 0);

  {
    const auto cam = ReadKeyValues(dir, kCameraFile,
                                   {"fx", "fy", "cx", "cy", "baseline", "width", "height"}, &lines);
    const std::string camera_path = (fs::path(dir) / kCameraFile).string();
    auto num = [&](const std::string& key) {
      const std::string& s = cam.at(key);
      double v = 0;
      const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
      if (res.ec != std::errc() || res.ptr != s.data() + s.size() || !std::isfinite(v))
        throw InputError(camera_path, lines.at(key), "expected a finite number for " + key + ", got '" + s + "'");
      return v;
    };
    StereoCamera& c = seq.camera;
    c.fx = num("fx"), c.fy = num("fy"), c.cx = num("cx"), c.cy = num("cy");
    c.baseline = num("baseline");
    c.width = static_cast<int>(num("width")), c.height = static_cast<int>(num("height"));
    try {
      c.Check();
    } catch (const ConfigError& e) {
      throw InputError(camera_path, e.what());
    }
  }

  {
    LineReader in(dir, kTimesFile, ' ');
    std::vector<std::string> f;
    while (in.Next(&f)) {
      in.ExpectFields(f, 1, "seconds");
      const double t = in.Double(f[0], "a timestamp");
      if (!seq.timestamps.empty() && !(t > seq.timestamps.back()))
        in.Fail("timestamps must increase");
      seq.timestamps.push_back(t);
    }
    if (static_cast<int>(seq.timestamps.size()) != frames)
      throw InputError(in.path(), in.line(), "expected " + std::to_string(frames) +
                                                 " timestamps (frames in sequence.txt), found " +
                                                 std::to_string(seq.timestamps.size()));
  }
  seq.world_from_cam = ReadPoses(dir, kCameraPosesFile, frames);
  for (int o = 0; o < objects; ++o) seq.world_from_object.push_back(ReadPoses(dir, ObjectFile(o), frames));

  {
    LineReader in(dir, kLandmarksFile, ',');
    std::vector<std::string> f;
    if (!in.Next(&f) || f.size() != 5 || f[0] != "landmark") in.Fail(std::string("expected the header ") + kLandmarksHeader);
    while (in.Next(&f)) {
      in.ExpectFields(f, 5, kLandmarksHeader);
      const int id = in.Int(f[0], "landmark", 0, kMaxCount);
      if (id != static_cast<int>(seq.landmark_object.size()))
        in.Fail("expected landmark id " + std::to_string(seq.landmark_object.size()) + " (ids are dense and in order)");
      if (id >= landmarks) in.Fail("more landmarks than the " + std::to_string(landmarks) + " of sequence.txt");
      seq.landmark_object.push_back(in.Int(f[1], "object id", 0, objects - 1));
      seq.landmark_in_object.emplace_back(in.Double(f[2], "x"), in.Double(f[3], "y"), in.Double(f[4], "z"));
    }
    if (static_cast<int>(seq.landmark_object.size()) != landmarks)
      throw InputError(in.path(), in.line(), "expected " + std::to_string(landmarks) +
                                                 " landmarks (sequence.txt), found " +
                                                 std::to_string(seq.landmark_object.size()));
  }

  {
    LineReader in(dir, kObservationsFile, ',');
    std::vector<std::string> f;
    if (!in.Next(&f) || f.size() != 11 || f[0] != "frame") in.Fail(std::string("expected the header ") + kObservationsHeader);
    std::vector<Pose> cam_from_world(frames);
    for (int k = 0; k < frames; ++k) cam_from_world[k] = seq.world_from_cam[k].inverse();
    int count = 0;
    while (in.Next(&f)) {
      in.ExpectFields(f, 11, kObservationsHeader);
      const int frame = in.Int(f[0], "frame", 0, frames - 1);
      const int landmark = in.Int(f[1], "landmark id (known in gt_landmarks.csv)", 0, landmarks - 1);
      const Eigen::Vector3d x(in.Double(f[2], "uL"), in.Double(f[3], "vL"), in.Double(f[4], "uR"));
      if (!(x(0) - x(2) > 0)) in.Fail("expected a positive disparity uL - uR");
      Eigen::Matrix3d cov;
      int k = 5;
      for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) cov(r, c) = cov(c, r) = in.Double(f[k++], "a covariance entry");
      if (!(cov.diagonal().minCoeff() > 0)) in.Fail("expected a positive covariance diagonal");
      const Eigen::Vector3d p = cam_from_world[frame] * seq.LandmarkInWorld(landmark, frame);
      if (!(p.z() > 0)) in.Fail("the landmark's ground-truth point is behind the camera");
      if (++count > observations)
        in.Fail("more observations than the " + std::to_string(observations) + " of sequence.txt");
      if (!seq.observations.Add(landmark, frame, x, cov))
        in.Fail("a second observation of the landmark in the same frame");
    }
    if (count != observations)
      throw InputError(in.path(), in.line(), "expected " + std::to_string(observations) +
                                                 " observations (sequence.txt), found " + std::to_string(count));
  }

  {
    LineReader in(dir, kGeometryFile, ',');
    std::vector<std::string> f;
    if (!in.Next(&f) || f.size() != 15 || f[0] != "object") in.Fail(std::string("expected the header ") + kGeometryHeader);
    seq.geometry.bodies.resize(objects);
    while (in.Next(&f)) {
      in.ExpectFields(f, 15, kGeometryHeader);
      SceneBody& body = seq.geometry.bodies[in.Int(f[0], "object id", 0, objects - 1)];
      if (body.quads.empty()) body.kind = f[1];
      else if (body.kind != f[1]) in.Fail("the object's kind changed from '" + body.kind + "'");
      SceneQuad q;
      for (int i = 0; i < 3; ++i) {
        q.origin(i) = in.Double(f[2 + i], "origin");
        q.edge_u(i) = in.Double(f[5 + i], "edge_u");
        q.edge_v(i) = in.Double(f[8 + i], "edge_v");
        float c = 0;
        const std::string& s = f[11 + i];
        const auto res = std::from_chars(s.data(), s.data() + s.size(), c);
        if (res.ec != std::errc() || res.ptr != s.data() + s.size() || !(c >= 0 && c <= 1))
          in.Fail("expected a colour component in [0, 1], got '" + s + "'");
        q.color(i) = c;
      }
      if (!(q.Area() > 0)) in.Fail("expected a quad with positive area");
      q.texture = in.Int(f[14], "texture", 0, std::numeric_limits<int>::max());
      body.quads.push_back(q);
    }
  }
  return seq;
}

bool LooksLikeSynthetic(const std::string& dir) {
  const fs::path d(dir);
  std::error_code ec;
  return fs::is_directory(d, ec) && fs::is_regular_file(d / kSequenceFile, ec) &&
         fs::is_regular_file(d / kCameraFile, ec) && fs::is_regular_file(d / kObservationsFile, ec) &&
         fs::is_regular_file(d / kCameraPosesFile, ec);
}

}  // namespace cslam
