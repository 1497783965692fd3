#include "system/io/xml_tree.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/system/kitti_fixtures.h"

namespace cslam {
namespace {

using ::testing::HasSubstr;

TEST(XmlTree, ParsesElementsTextAndLineNumbers) {
  const std::string text =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE x>\n<root a=\"1>2\">\n  <!-- note -->\n"
      "  <item><v>1.5</v><w>a &amp; b</w></item>\n  <item/>\n  <count>2</count>\n</root>\n";
  const XmlElement root = ParseXml(text, "t.xml");
  EXPECT_EQ(root.name, "root");
  EXPECT_EQ(root.line, 3);
  ASSERT_EQ(root.FindAll("item").size(), 2u);
  const XmlElement& item = *root.FindAll("item")[0];
  EXPECT_EQ(item.line, 5);
  EXPECT_EQ(item.Find("v")->text, "1.5");
  EXPECT_EQ(item.Find("w")->text, "a & b");
  EXPECT_EQ(root.Find("count")->line, 7);
  EXPECT_EQ(root.Find("missing"), nullptr);
}

TEST(XmlTree, MalformedMarkupNamesTheFileAndLine) {
  EXPECT_THAT(testing::InputErrorMessage([] { ParseXml("<a>\n<b>\n</c>\n</a>", "t.xml"); }),
              HasSubstr("t.xml:2: malformed XML: the element opened on this line is closed by a tag of another name"));
  EXPECT_THAT(testing::InputErrorMessage([] { ParseXml("<a>\n<b>x</b>\n", "t.xml"); }),
              HasSubstr("t.xml:1: malformed XML: the element opened on this line is not closed"));
  EXPECT_THAT(testing::InputErrorMessage([] { ParseXml("", "t.xml"); }),
              HasSubstr("t.xml:1: malformed XML: expected an XML document"));
  EXPECT_THAT(testing::InputErrorMessage([] { ParseXml("<a></a>\n<b/>", "t.xml"); }),
              HasSubstr("t.xml:2: malformed XML: expected a single root element, got a second <b>"));
  EXPECT_THAT(testing::InputErrorMessage([] { ParseXml("<a>\n\n<b x=1/></a>", "t.xml"); }),
              HasSubstr("t.xml:3: malformed XML"));
}

TEST(XmlTree, TextAroundChildElementsIsConcatenatedAndCdataKept) {
  const XmlElement root = ParseXml("<r>a<c/>b<![CDATA[<x>]]></r>", "t.xml");
  EXPECT_EQ(root.text, "ab<x>");
  ASSERT_EQ(root.children.size(), 1u);
  EXPECT_EQ(root.children[0].name, "c");
}

}  // namespace
}  // namespace cslam
