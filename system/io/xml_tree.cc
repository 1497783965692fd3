#include "system/io/xml_tree.h"

#include <tinyxml2.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "system/io/input_files.h"

namespace cslam {

const XmlElement* XmlElement::Find(const std::string& child) const {
  for (const XmlElement& c : children)
    if (c.name == child) return &c;
  return nullptr;
}

std::vector<const XmlElement*> XmlElement::FindAll(const std::string& child) const {
  std::vector<const XmlElement*> out;
  for (const XmlElement& c : children)
    if (c.name == child) out.push_back(&c);
  return out;
}

namespace {

// tinyxml2 names its errors by enum; a user reading "file:line: malformed XML: …" needs words.
std::string Describe(tinyxml2::XMLError error, const tinyxml2::XMLDocument& doc) {
  switch (error) {
    case tinyxml2::XML_ERROR_EMPTY_DOCUMENT: return "expected an XML document; found no element";
    case tinyxml2::XML_ERROR_MISMATCHED_ELEMENT:
      return "the element opened on this line is closed by a tag of another name";
    // tinyxml2 gives this one, with the opening line, for an element the file never closes.
    case tinyxml2::XML_ERROR_PARSING:
      return "the element opened on this line is not closed (or the markup in it is malformed)";
    case tinyxml2::XML_ERROR_PARSING_ELEMENT: return "an element is malformed or not closed";
    case tinyxml2::XML_ERROR_PARSING_ATTRIBUTE: return "an attribute is malformed";
    case tinyxml2::XML_ERROR_PARSING_TEXT: return "text is malformed (a stray '<' or '&'?)";
    case tinyxml2::XML_ERROR_PARSING_CDATA: return "a CDATA section is not terminated";
    case tinyxml2::XML_ERROR_PARSING_COMMENT: return "a comment is not terminated";
    case tinyxml2::XML_ERROR_PARSING_DECLARATION: return "a declaration is malformed";
    case tinyxml2::XML_ERROR_PARSING_UNKNOWN: return "unknown markup";
    case tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED: return "elements are nested too deeply";
    default: return std::string("expected well-formed XML (") + doc.ErrorName() + ")";
  }
}

// tinyxml2's element depth limit bounds this recursion.
XmlElement Convert(const tinyxml2::XMLElement& in) {
  XmlElement out;
  out.name = in.Name();
  out.line = in.GetLineNum();
  for (const tinyxml2::XMLNode* node = in.FirstChild(); node != nullptr; node = node->NextSibling()) {
    if (const tinyxml2::XMLElement* child = node->ToElement())
      out.children.push_back(Convert(*child));
    else if (const tinyxml2::XMLText* text = node->ToText())
      out.text += text->Value();
  }
  return out;
}

}  // namespace

XmlElement ParseXml(const std::string& text, const std::string& path) {
  tinyxml2::XMLDocument doc(/*processEntities=*/true, tinyxml2::PRESERVE_WHITESPACE);
  const tinyxml2::XMLError error = doc.Parse(text.data(), text.size());
  if (error != tinyxml2::XML_SUCCESS)
    throw InputError(path, std::max(doc.ErrorLineNum(), 1), "malformed XML: " + Describe(error, doc));
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr)
    throw InputError(path, 1, "malformed XML: expected an XML document; found no element");
  if (const tinyxml2::XMLElement* second = root->NextSiblingElement())
    throw InputError(path, second->GetLineNum(),
                     std::string("malformed XML: expected a single root element, got a second <") +
                         second->Name() + ">");
  return Convert(*root);
}

XmlElement ReadXmlFile(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "XML file");
  std::stringstream s;
  s << in.rdbuf();
  return ParseXml(s.str(), path);
}

}  // namespace cslam
