// nestingDepth() counts levels as the recursive parsers it guards would nest: JSON and YAML flow
// brackets, XML elements, and nothing inside a string.

#include "common/nesting_depth.hpp"

#include <string>

#include <gtest/gtest.h>

namespace surroundd {
namespace {

TEST(NestingDepth, CountsBracketsAsAJsonOrYamlParserNestsThem) {
  EXPECT_EQ(nestingDepth(""), 0u);
  EXPECT_EQ(nestingDepth("plain: 1\nother: text"), 0u);
  EXPECT_EQ(nestingDepth(R"({"a": [1, 2, {"b": [3]}], "c": {}})"), 4u);
  EXPECT_EQ(nestingDepth("k: [[1, 2], [3, 4]]\nm: {a: [5]}"), 2u);
  EXPECT_EQ(nestingDepth(std::string(100000, '[')), 100000u);
  // A stray closer first does not hide the levels opened after it.
  EXPECT_EQ(nestingDepth("]]]]" + std::string(5, '[')), 5u);
}

TEST(NestingDepth, SkipsStringsWithTheirEscapesUpToTheirEndOrTheLinesEnd) {
  EXPECT_EQ(nestingDepth(R"({"name": "[[[{{{", "x": ["\"[[["]})"), 2u);
  // JSON strings end on their line: a stray quote cannot hide the brackets of the lines after.
  EXPECT_EQ(nestingDepth("a: x\"\n[[[[[[[[ ]]]]]]]]"), 8u);
}

TEST(NestingDepth, CountsXmlElements) {
  EXPECT_EQ(nestingDepth("<?xml version=\"1.0\"?>\n<opencv_storage><K type_id=\"opencv-matrix\">"
                         "<rows>3</rows><data>1 2</data></K><e/></opencv_storage>"),
            3u);
  std::string deep;
  for (int i = 0; i < 1000; ++i) deep += "<a>";
  EXPECT_EQ(nestingDepth(deep), 1000u);
  EXPECT_EQ(nestingDepth("a < b and c <2"), 0u);
}

}  // namespace
}  // namespace surroundd
