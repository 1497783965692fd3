#pragma once
// The XML tree of the data files we read (KITTI tracklet labels), parsed by tinyxml2: elements,
// their text and line numbers; attributes are dropped. Keeps the line of every element so
// readers can report "file:line: what was expected".
#include <string>
#include <vector>

namespace cslam {

/// One XML element with its concatenated text and child elements.
struct XmlElement {
  std::string name;
  std::string text;  ///< character data directly inside this element, entities decoded
  int line = 0;      ///< line of the opening tag, 1-based
  std::vector<XmlElement> children;

  /// First child named `child`, or nullptr.
  const XmlElement* Find(const std::string& child) const;
  /// All children named `child`, in document order.
  std::vector<const XmlElement*> FindAll(const std::string& child) const;
};

/// Parses the XML file at `path` and returns its root element. Throws InputError naming the
/// file and line on unreadable files and malformed markup (unclosed or mismatched tags, ...).
XmlElement ReadXmlFile(const std::string& path);

/// Parses XML text; `path` is only used in error messages.
XmlElement ParseXml(const std::string& text, const std::string& path);

}  // namespace cslam
