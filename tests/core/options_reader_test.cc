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

struct SubOptions {
  int x = 0;
  void Load(OptionsReader& r) { r.Read("x", &x); }
};

struct AllTypes {
  double a = 0;
  int b = 0;
  bool c = false;
  std::string d;
  std::vector<double> e;
  int absent = 7;
  SubOptions sub;
  void Load(OptionsReader& r) {
    r.Read("a", &a);
    r.Read("b", &b);
    r.Read("c", &c);
    r.Read("d", &d);
    r.Read("e", &e);
    r.Read("absent", &absent);
    r.ReadSection("sub", &sub);
  }
};

TEST(OptionsReader, ReadsTypedValuesAndNestedSections) {
  auto r = OptionsReader::FromString("a: 1.5\nb: 3\nc: true\nd: hi\ne: [1, 2]\nsub: {x: 4}\n", "t.yaml");
  AllTypes o;
  EXPECT_NO_THROW(r.LoadInto(&o));
  EXPECT_EQ(o.a, 1.5);
  EXPECT_EQ(o.b, 3);
  EXPECT_TRUE(o.c);
  EXPECT_EQ(o.d, "hi");
  EXPECT_EQ(o.e, (std::vector<double>{1, 2}));
  EXPECT_EQ(o.sub.x, 4);
  EXPECT_EQ(o.absent, 7);
}

TEST(OptionsReader, AnUnknownTopLevelKeyNamesFileLineKeyAndTheKnownKeys) {
  auto r = OptionsReader::FromString("a: 1\nbogus: 2\n", "cfg.yaml");
  AllTypes o;
  const std::string msg = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_EQ(msg, "cfg.yaml:2: bogus: unknown key (known: a, b, c, d, e, absent, sub)");
}

TEST(OptionsReader, AnUnknownKeyInANestedSectionNamesItsWholePath) {
  auto r = OptionsReader::FromString("a: 1\nsub:\n  x: 1\n  typo_key: 2\n", "cfg.yaml");
  AllTypes o;
  const std::string msg = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_EQ(msg, "cfg.yaml:4: sub.typo_key: unknown key (known: x)");
}

TEST(OptionsReader, EveryUnknownKeyOfASectionIsNamed) {
  auto r = OptionsReader::FromString("sub: {y: 1, z: 2}\n", "cfg.yaml");
  AllTypes o;
  const std::string msg = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_NE(msg.find("cfg.yaml:1: sub.y: unknown key"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cfg.yaml:1: sub.z: unknown key"), std::string::npos) << msg;
}

TEST(OptionsReader, ANonScalarKeyIsAnUnknownKeyNotACrash) {
  // Regression of fuzz/corpus/options/crash-non_scalar_key.yaml: Finish() converted every key
  // to a string and let yaml-cpp's bad-conversion exception escape (exit 4 instead of 2).
  auto r = OptionsReader::FromString("a: 1\n? [a, b]\n: 2\n", "cfg.yaml");
  AllTypes o;
  const std::string msg = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_NE(msg.find("cfg.yaml:2: <non-scalar key>: unknown key"), std::string::npos) << msg;
}

TEST(OptionsReader, AKeyGivenTwiceIsAnErrorNamingBothLines) {
  // A second section of the same name used to be ignored without a word: the first wins.
  const std::string top = MessageOf([] {
    OptionsReader::FromString("online:\n  window_every: 5\noutput: {}\nonline:\n  reserve_core: false\n",
                              "cfg.yaml");
  });
  EXPECT_NE(top.find("cfg.yaml:4: online given twice (first on line 1)"), std::string::npos) << top;
  // Inside a section, when the section is opened.
  auto r = OptionsReader::FromString("sub:\n  x: 5\n  x: 7\n", "cfg.yaml");
  AllTypes o;
  const std::string nested = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_NE(nested.find("cfg.yaml:3: sub.x given twice (first on line 2)"), std::string::npos)
      << nested;
}

TEST(OptionsReader, WrongTypeNamesTheFileLineAndKeyPath) {
  auto r = OptionsReader::FromString("a: 1\nsub: {x: lots}\n", "cfg.yaml");
  AllTypes o;
  const std::string msg = MessageOf([&] { r.LoadInto(&o); });
  EXPECT_EQ(msg, "cfg.yaml:2: sub.x: expected an integer, got 'lots'");
}

TEST(OptionsReader, LineOfFindsNestedKeys) {
  auto r = OptionsReader::FromString("a: 1\nsub:\n  x: 4\n", "cfg.yaml");
  EXPECT_EQ(r.LineOf("a"), 1);
  EXPECT_EQ(r.LineOf("sub.x"), 3);
  EXPECT_EQ(r.LineOf("sub.y"), 0);
  EXPECT_EQ(r.LineOf("b.x"), 0);
}

enum class Colour { kRed, kLightBlue };
constexpr EnumName<Colour> kColourNames[] = {{Colour::kRed, "red"}, {Colour::kLightBlue, "light-blue"}};

struct Paint {
  Colour colour = Colour::kRed;
  void Load(OptionsReader& r) { r.Read("colour", kColourNames, &colour); }
};

TEST(OptionsReader, AnEnumIsReadByItsTableAndAnyOtherSpellingIsRejected) {
  Paint p;
  auto good = OptionsReader::FromString("colour: light-blue\n", "cfg.yaml");
  good.LoadInto(&p);
  EXPECT_EQ(p.colour, Colour::kLightBlue);
  auto bad = OptionsReader::FromString("colour: light_blue\n", "cfg.yaml");
  EXPECT_EQ(MessageOf([&] { bad.LoadInto(&p); }),
            "cfg.yaml:1: colour: must be one of red, light-blue, got 'light_blue'");
  auto dump = OptionsReader::ForDump();
  dump.LoadInto(&p);
  EXPECT_NE(dump.Dump().find("colour: light-blue"), std::string::npos) << dump.Dump();
}

TEST(OptionsReader, MissingFileAndBadYamlAreConfigErrors) {
  EXPECT_THROW(OptionsReader::FromFile("/nonexistent/x.yaml"), ConfigError);
  EXPECT_THROW(OptionsReader::FromString("a: [1, 2\n", "bad.yaml"), ConfigError);
}

struct ToyOptions {
  double epsilon = 90;
  std::string name = "outdoor";
  std::vector<double> list = {1, 2};
  bool flag = true;
  struct Chunking {
    int chunk = 200;
    void Load(OptionsReader& r) { r.Read("chunk", &chunk); }
  } chunking;
  void Load(OptionsReader& r) {
    r.Read("epsilon", &epsilon);
    r.ReadSection("chunking", &chunking);
    r.Read("name", &name);
    r.Read("list", &list);
    r.Read("flag", &flag);
  }
};

TEST(OptionsReader, DumpThenLoadReproducesTheEffectiveConfiguration) {
  ToyOptions a;
  a.epsilon = 60;
  a.chunking.chunk = 100;
  a.name = "indoor";
  a.list = {3.5};
  a.flag = false;
  auto dump = OptionsReader::ForDump();
  dump.LoadInto(&a);
  const std::string text = dump.Dump();
  EXPECT_NE(text.find("chunk: 100"), std::string::npos) << text;
  ToyOptions b;
  auto r = OptionsReader::FromString(text, "dump");
  r.LoadInto(&b);
  EXPECT_EQ(b.epsilon, 60);
  EXPECT_EQ(b.chunking.chunk, 100);
  EXPECT_EQ(b.name, "indoor");
  EXPECT_EQ(b.list, (std::vector<double>{3.5}));
  EXPECT_FALSE(b.flag);
}

TEST(CheckOption, ExplainsTheRule) {
  const std::string msg = MessageOf([] { CheckOption(false, "epsilon", "must be > 0", -1); });
  EXPECT_EQ(msg, "epsilon: must be > 0, got -1");
}

TEST(CheckSection, PrefixesTheEnclosingSectionsToTheKey) {
  try {
    CheckSection("backend", [] {
      CheckSection("hac", [] { CheckOption(false, "epsilon", "must be > 0", -1); });
    });
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "backend.hac.epsilon: must be > 0, got -1");
    EXPECT_EQ(e.key(), "backend.hac.epsilon");
    EXPECT_EQ(e.rule(), "must be > 0, got -1");
  }
}

}  // namespace
}  // namespace cslam
