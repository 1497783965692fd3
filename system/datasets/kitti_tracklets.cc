#include "system/datasets/kitti_tracklets.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>

#include "core/errors.h"
#include "system/io/xml_tree.h"

namespace cslam {

namespace {

const XmlElement& Required(const XmlElement& parent, const std::string& name,
                           const std::string& path) {
  const XmlElement* e = parent.Find(name);
  if (!e)
    throw InputError(path, parent.line,
                     "<" + parent.name + "> lacks the expected child <" + name + ">");
  return *e;
}

double Number(const XmlElement& parent, const std::string& name, const std::string& path) {
  const XmlElement& e = Required(parent, name, path);
  const char* begin = e.text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  const bool rest_blank =
      end != begin && std::string(end).find_first_not_of(" \t\r\n") == std::string::npos;
  if (!rest_blank || !std::isfinite(v))
    throw InputError(path, e.line, "<" + name + ">: expected a finite number, got '" + e.text + "'");
  return v;
}

int Integer(const XmlElement& parent, const std::string& name, const std::string& path) {
  const double v = Number(parent, name, path);
  if (v != std::floor(v) || std::abs(v) > 1e9)
    throw InputError(path, Required(parent, name, path).line,
                     "<" + name + ">: expected a whole number");
  return static_cast<int>(v);
}

// Boost serialisation writes <count>N</count> followed by N <item>s.
std::vector<const XmlElement*> CountedItems(const XmlElement& list, const std::string& path) {
  const int count = Integer(list, "count", path);
  std::vector<const XmlElement*> items = list.FindAll("item");
  if (static_cast<int>(items.size()) != count)
    throw InputError(path, list.line,
                     "<" + list.name + ">: <count> says " + std::to_string(count) + " but " +
                         std::to_string(items.size()) + " <item>s follow");
  return items;
}

}  // namespace

std::vector<std::vector<ObjectBox>> ReadTrackletLabels(const std::string& xml_path,
                                                       const Pose& cam_from_velo, int num_frames) {
  const XmlElement root = ReadXmlFile(xml_path);
  const XmlElement* tracklets = root.name == "tracklets" ? &root : root.Find("tracklets");
  if (!tracklets)
    throw InputError(xml_path, root.line, "expected a <tracklets> element in <" + root.name + ">");
  std::vector<std::vector<ObjectBox>> boxes(static_cast<size_t>(std::max(num_frames, 0)));
  const std::vector<const XmlElement*> objects = CountedItems(*tracklets, xml_path);
  for (size_t id = 0; id < objects.size(); ++id) {
    const XmlElement& obj = *objects[id];
    ObjectBox box;
    box.track_id = static_cast<int>(id);
    box.type = Required(obj, "objectType", xml_path).text;
    if (box.type.empty())
      throw InputError(xml_path, Required(obj, "objectType", xml_path).line,
                       "<objectType>: expected a type name");
    box.h = Number(obj, "h", xml_path);
    box.w = Number(obj, "w", xml_path);
    box.l = Number(obj, "l", xml_path);
    if (!(box.h > 0 && box.w > 0 && box.l > 0))
      throw InputError(xml_path, obj.line, "object " + std::to_string(id) +
                                               ": expected positive box sizes h, w, l");
    const int first_frame = Integer(obj, "first_frame", xml_path);
    const XmlElement& poses = Required(obj, "poses", xml_path);
    const std::vector<const XmlElement*> items = CountedItems(poses, xml_path);
    if (first_frame < 0 || first_frame + static_cast<int>(items.size()) > num_frames)
      throw InputError(xml_path, obj.line,
                       "object " + std::to_string(id) + ": expected frames within [0, " +
                           std::to_string(num_frames) + "), got " + std::to_string(first_frame) +
                           " + " + std::to_string(items.size()) + " poses");
    for (size_t k = 0; k < items.size(); ++k) {
      const XmlElement& p = *items[k];
      Pose velo_from_box = Pose::Identity();
      velo_from_box.translation() = Eigen::Vector3d(Number(p, "tx", xml_path),
                                                    Number(p, "ty", xml_path),
                                                    Number(p, "tz", xml_path));
      velo_from_box.linear() =
          (Eigen::AngleAxisd(Number(p, "rz", xml_path), Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(Number(p, "ry", xml_path), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(Number(p, "rx", xml_path), Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
      box.cam_from_box = cam_from_velo * velo_from_box;
      boxes[static_cast<size_t>(first_frame) + k].push_back(box);
    }
  }
  return boxes;
}

}  // namespace cslam
