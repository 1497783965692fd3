#include "system/eval/json_fields.h"

#include <gtest/gtest.h>

#include <limits>

namespace cslam {

struct JsonFieldsProbeInner {
  std::optional<double> v_m;
  int id = -1;
};

struct JsonFieldsProbe {
  std::optional<double> x_m;
  std::optional<long long> count;
  std::optional<std::string> note;
  std::string name;
  bool flag = false;
  std::vector<int> frames;
  JsonFieldsProbeInner inner;
  std::vector<JsonFieldsProbeInner> items;
};

template <>
struct JsonFields<JsonFieldsProbeInner> {
  using S = JsonFieldsProbeInner;
  static constexpr auto kFields = std::tuple{JsonField{"v_m", &S::v_m}, JsonField{"id", &S::id}};
};

template <>
struct JsonFields<JsonFieldsProbe> {
  using S = JsonFieldsProbe;
  static constexpr auto kFields = std::tuple{
      JsonField{"x_m", &S::x_m},     JsonField{"count", &S::count}, JsonField{"note", &S::note},
      JsonField{"name", &S::name},   JsonField{"flag", &S::flag},   JsonField{"frames", &S::frames},
      JsonField{"inner", &S::inner}, JsonField{"items", &S::items},
  };
};

namespace {

JsonFieldsProbe Read(const nlohmann::json& j) {
  JsonFieldsProbe p;
  FieldsFromJson(j, p, "probe.json");
  return p;
}

TEST(JsonFields, EmptyNanAndInfiniteOptionalsAreNull) {
  JsonFieldsProbe p;
  nlohmann::json j = FieldsToJson(p);
  EXPECT_TRUE(j["x_m"].is_null());
  EXPECT_TRUE(j["count"].is_null());
  EXPECT_TRUE(j["note"].is_null());
  p.x_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(FieldsToJson(p)["x_m"].is_null());
  p.x_m = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(FieldsToJson(p)["x_m"].is_null());
  p.x_m = 1.5;
  EXPECT_EQ(FieldsToJson(p)["x_m"], 1.5);
}

TEST(JsonFields, EveryKindWritesItsJsonAndReadsBack) {
  JsonFieldsProbe p;
  p.x_m = 0.25;
  p.count = 1LL << 40;
  p.note = "n";
  p.name = "probe";
  p.flag = true;
  p.frames = {3, 4};
  p.inner = {2.0, 7};
  p.items = {{1.0, 1}, {std::nullopt, 2}};
  const nlohmann::json j = FieldsToJson(p);
  EXPECT_EQ(
      j.dump(),
      R"({"count":1099511627776,"flag":true,"frames":[3,4],"inner":{"id":7,"v_m":2.0},)"
      R"("items":[{"id":1,"v_m":1.0},{"id":2,"v_m":null}],"name":"probe","note":"n","x_m":0.25})");
  const JsonFieldsProbe back = Read(j);
  EXPECT_EQ(back.x_m, p.x_m);
  EXPECT_EQ(back.count, p.count);
  EXPECT_EQ(back.note, p.note);
  EXPECT_EQ(back.name, p.name);
  EXPECT_EQ(back.flag, p.flag);
  EXPECT_EQ(back.frames, p.frames);
  EXPECT_EQ(back.inner.id, 7);
  ASSERT_EQ(back.items.size(), 2u);
  EXPECT_EQ(back.items[0].v_m, 1.0);
  EXPECT_FALSE(back.items[1].v_m.has_value());
  EXPECT_EQ(back.items[1].id, 2);
}

TEST(JsonFields, MissingAndNullKeysKeepTheDefaultsAndUnknownKeysAreIgnored) {
  const JsonFieldsProbe p =
      Read({{"inner", nullptr}, {"items", {{{"v_m", nullptr}}}}, {"later", 1}});
  EXPECT_FALSE(p.x_m.has_value());
  EXPECT_EQ(p.inner.id, -1);
  ASSERT_EQ(p.items.size(), 1u);
  EXPECT_EQ(p.items[0].id, -1);
  EXPECT_FALSE(p.flag);
}

TEST(JsonFields, AWrongTypeIsAnInputErrorNamingTheFileAndTheKeyPath) {
  const auto message = [](const nlohmann::json& j) -> std::string {
    try {
      Read(j);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string nested = message({{"items", {{{"id", 1}}, {{"id", "two"}}}}});
  EXPECT_NE(nested.find("probe.json"), std::string::npos) << nested;
  EXPECT_NE(nested.find("items[1].id"), std::string::npos) << nested;
  EXPECT_NE(message({{"inner", 5}}).find("inner: expected a JSON object"), std::string::npos);
  EXPECT_NE(message({{"items", 5}}).find("items: expected a JSON array"), std::string::npos);
  EXPECT_NE(message({{"frames", "three"}}).find("frames: unexpected value type"),
            std::string::npos);
  EXPECT_NE(message(nlohmann::json::array()).find("expected a JSON object"), std::string::npos);
}

}  // namespace
}  // namespace cslam
