#include "core/options_reader.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace cslam {
namespace {

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(OptionsReader, ReadsTypedValuesAndNestedSections) {
  auto r = OptionsReader::FromString("a: 1.5\nb: 3\nc: true\nd: hi\ne: [1, 2]\nsub: {x: 4}\n", "t.yaml");
  double a = 0;
  int b = 0;
  bool c = false;
  std::string d;
  std::vector<double> e;
  int x = 0, absent = 7;
  r.Read("a", &a);
  r.Read("b", &b);
  r.Read("c", &c);
  r.Read("d", &d);
  r.Read("e", &e);
  r.Read("absent", &absent);
  auto sub = r.Section("sub");
  sub.Read("x", &x);
  EXPECT_NO_THROW(sub.Finish());
  EXPECT_NO_THROW(r.Finish());
  EXPECT_EQ(a, 1.5);
  EXPECT_EQ(b, 3);
  EXPECT_TRUE(c);
  EXPECT_EQ(d, "hi");
  EXPECT_EQ(e, (std::vector<double>{1, 2}));
  EXPECT_EQ(x, 4);
  EXPECT_EQ(absent, 7);
}

TEST(OptionsReader, UnknownKeyIsAnErrorNamingIt) {
  auto r = OptionsReader::FromString("known: 1\nsub: {typo_key: 2}\n", "cfg.yaml");
  int known = 0;
  r.Read("known", &known);
  auto sub = r.Section("sub");
  const std::string msg = MessageOf([&] { sub.Finish(); });
  EXPECT_NE(msg.find("cfg.yaml"), std::string::npos) << msg;
  EXPECT_NE(msg.find("sub.typo_key"), std::string::npos) << msg;
}

TEST(OptionsReader, ANonScalarKeyIsAnUnknownKeyNotACrash) {
  // Regression of fuzz/corpus/options/crash-non_scalar_key.yaml: Finish() converted every key
  // to a string and let yaml-cpp's bad-conversion exception escape (exit 4 instead of 2).
  auto r = OptionsReader::FromString("known: 1\n? [a, b]\n: 2\n", "cfg.yaml");
  int known = 0;
  r.Read("known", &known);
  const std::string msg = MessageOf([&] { r.Finish(); });
  EXPECT_NE(msg.find("cfg.yaml: unknown key: <non-scalar key on line 2>"), std::string::npos) << msg;
}

TEST(OptionsReader, AKeyGivenTwiceIsAnErrorNamingBothLines) {
  // A second section of the same name used to be ignored without a word: the first wins.
  const std::string top = MessageOf([] {
    OptionsReader::FromString("online:\n  window_every: 5\noutput: {}\nonline:\n  reserve_core: false\n",
                              "cfg.yaml");
  });
  EXPECT_NE(top.find("cfg.yaml:4: online given twice (first on line 1)"), std::string::npos) << top;
  // Inside a section, when the section is opened.
  auto r = OptionsReader::FromString("online:\n  window_every: 5\n  window_every: 7\n", "cfg.yaml");
  const std::string nested = MessageOf([&] { r.Section("online"); });
  EXPECT_NE(nested.find("cfg.yaml:3: online.window_every given twice (first on line 2)"),
            std::string::npos)
      << nested;
}

TEST(OptionsReader, WrongTypeNamesTheKey) {
  auto r = OptionsReader::FromString("hac: {epsilon: lots}\n", "cfg.yaml");
  auto hac = r.Section("hac");
  double eps = 0;
  const std::string msg = MessageOf([&] { hac.Read("epsilon", &eps); });
  EXPECT_NE(msg.find("hac.epsilon"), std::string::npos) << msg;
  EXPECT_NE(msg.find("lots"), std::string::npos) << msg;
}

TEST(OptionsReader, MissingFileAndBadYamlAreConfigErrors) {
  EXPECT_THROW(OptionsReader::FromFile("/nonexistent/x.yaml"), ConfigError);
  EXPECT_THROW(OptionsReader::FromString("a: [1, 2\n", "bad.yaml"), ConfigError);
}

struct ToyOptions {
  double epsilon = 90;
  int chunk = 200;
  std::string name = "outdoor";
  std::vector<double> list = {1, 2};
  bool flag = true;
  void Load(OptionsReader& r) {
    r.Read("epsilon", &epsilon);
    auto sub = r.Section("chunking");
    sub.Read("chunk", &chunk);
    sub.Finish();
    r.Read("name", &name);
    r.Read("list", &list);
    r.Read("flag", &flag);
    r.Finish();
  }
};

TEST(OptionsReader, DumpThenLoadReproducesTheEffectiveConfiguration) {
  ToyOptions a;
  a.epsilon = 60;
  a.chunk = 100;
  a.name = "indoor";
  a.list = {3.5};
  a.flag = false;
  auto dump = OptionsReader::ForDump();
  a.Load(dump);
  const std::string text = dump.Dump();
  EXPECT_NE(text.find("chunk: 100"), std::string::npos) << text;
  ToyOptions b;
  auto r = OptionsReader::FromString(text, "dump");
  b.Load(r);
  EXPECT_EQ(b.epsilon, 60);
  EXPECT_EQ(b.chunk, 100);
  EXPECT_EQ(b.name, "indoor");
  EXPECT_EQ(b.list, (std::vector<double>{3.5}));
  EXPECT_FALSE(b.flag);
}

TEST(CheckOption, ExplainsTheRule) {
  const std::string msg = MessageOf([] { CheckOption(false, "hac.epsilon", "must be > 0", -1); });
  EXPECT_EQ(msg, "hac.epsilon: must be > 0, got -1");
}

}  // namespace
}  // namespace cslam
