#include "system/io/xml_tree.h"

#include <cctype>
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

class XmlParser {
 public:
  XmlParser(const std::string& text, const std::string& path) : s_(text), path_(path) {}

  XmlElement Parse() {
    std::vector<XmlElement> stack;
    bool have_root = false;
    XmlElement root;
    while (pos_ < s_.size()) {
      if (s_[pos_] != '<') {
        const size_t next = s_.find('<', pos_);
        const std::string chunk = s_.substr(pos_, next == std::string::npos ? next : next - pos_);
        if (stack.empty()) {
          if (chunk.find_first_not_of(" \t\r\n") != std::string::npos)
            Fail("expected markup, got text outside the root element");
        } else {
          stack.back().text += Decode(chunk);
        }
        Advance(next == std::string::npos ? s_.size() : next);
        continue;
      }
      if (StartsWith("<?")) {
        SkipPast("?>");
      } else if (StartsWith("<!--")) {
        SkipPast("-->");
      } else if (StartsWith("<![CDATA[")) {
        const int line = line_;
        const size_t end = s_.find("]]>", pos_);
        if (end == std::string::npos) Fail("unterminated CDATA section", line);
        if (stack.empty()) Fail("expected markup, got CDATA outside the root element");
        stack.back().text += s_.substr(pos_ + 9, end - pos_ - 9);
        Advance(end + 3);
      } else if (StartsWith("<!")) {
        SkipPast(">");
      } else if (StartsWith("</")) {
        const int line = line_;
        Advance(pos_ + 2);
        const std::string name = ReadName();
        SkipSpace();
        if (pos_ >= s_.size() || s_[pos_] != '>') Fail("expected '>' closing </" + name, line);
        Advance(pos_ + 1);
        if (stack.empty()) Fail("unexpected closing tag </" + name + ">", line);
        if (stack.back().name != name)
          Fail("expected </" + stack.back().name + "> (opened on line " +
                   std::to_string(stack.back().line) + "), got </" + name + ">",
               line);
        XmlElement done = std::move(stack.back());
        stack.pop_back();
        Close(std::move(done), &stack, &root, &have_root);
      } else {
        XmlElement e;
        e.line = line_;
        Advance(pos_ + 1);
        e.name = ReadName();
        bool self_closing = false;
        // Attributes are skipped, honouring quotes so '>' inside a value does not end the tag.
        for (;;) {
          if (pos_ >= s_.size()) Fail("unterminated tag <" + e.name, e.line);
          const char c = s_[pos_];
          if (c == '"' || c == '\'') {
            const size_t end = s_.find(c, pos_ + 1);
            if (end == std::string::npos) Fail("unterminated attribute value", line_);
            Advance(end + 1);
          } else if (c == '/' && pos_ + 1 < s_.size() && s_[pos_ + 1] == '>') {
            self_closing = true;
            Advance(pos_ + 2);
            break;
          } else if (c == '>') {
            Advance(pos_ + 1);
            break;
          } else {
            Advance(pos_ + 1);
          }
        }
        if (have_root && stack.empty()) Fail("expected a single root element, got a second <" + e.name + ">", e.line);
        if (self_closing)
          Close(std::move(e), &stack, &root, &have_root);
        else
          stack.push_back(std::move(e));
      }
    }
    if (!stack.empty())
      Fail("unexpected end of file: <" + stack.back().name + "> opened on line " +
           std::to_string(stack.back().line) + " is not closed");
    if (!have_root) Fail("expected an XML document; found no element");
    return root;
  }

 private:
  static void Close(XmlElement e, std::vector<XmlElement>* stack, XmlElement* root, bool* have_root) {
    if (stack->empty()) {
      *root = std::move(e);
      *have_root = true;
    } else {
      stack->back().children.push_back(std::move(e));
    }
  }

  [[noreturn]] void Fail(const std::string& what, int line = -1) const {
    throw InputError(path_, line < 0 ? line_ : line, "malformed XML: " + what);
  }

  bool StartsWith(const char* p) const { return s_.compare(pos_, std::char_traits<char>::length(p), p) == 0; }

  // Moves to `to`, counting newlines on the way.
  void Advance(size_t to) {
    for (; pos_ < to && pos_ < s_.size(); ++pos_)
      if (s_[pos_] == '\n') ++line_;
  }

  void SkipPast(const char* marker) {
    const int line = line_;
    const size_t end = s_.find(marker, pos_);
    if (end == std::string::npos) Fail(std::string("expected '") + marker + "' before the end of file", line);
    Advance(end + std::char_traits<char>::length(marker));
  }

  void SkipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) Advance(pos_ + 1);
  }

  std::string ReadName() {
    const size_t start = pos_;
    while (pos_ < s_.size()) {
      const char c = s_[pos_];
      if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ':')
        ++pos_;
      else
        break;
    }
    if (pos_ == start) Fail("expected an element name after '<'");
    return s_.substr(start, pos_ - start);
  }

  std::string Decode(const std::string& t) const {
    std::string out;
    out.reserve(t.size());
    for (size_t i = 0; i < t.size(); ++i) {
      if (t[i] != '&') {
        out += t[i];
        continue;
      }
      static const std::pair<const char*, char> kEntities[] = {
          {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
      bool known = false;
      for (const auto& [name, ch] : kEntities) {
        if (t.compare(i, std::char_traits<char>::length(name), name) == 0) {
          out += ch;
          i += std::char_traits<char>::length(name) - 1;
          known = true;
          break;
        }
      }
      if (!known) Fail("unknown entity in text");
    }
    return out;
  }

  const std::string& s_;
  const std::string& path_;
  size_t pos_ = 0;
  int line_ = 1;
};

}  // namespace

XmlElement ParseXml(const std::string& text, const std::string& path) {
  return XmlParser(text, path).Parse();
}

XmlElement ReadXmlFile(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "XML file");
  std::stringstream s;
  s << in.rdbuf();
  return ParseXml(s.str(), path);
}

}  // namespace cslam
