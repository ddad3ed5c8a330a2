// The effect catalogue as `plumb effects` shows it.
#include "plumb/report/catalogue.h"

#include <gtest/gtest.h>

#include "plumb/core/error.h"

namespace plumb::report {
namespace {

TEST(Catalogue, TextListsEveryEffectWithTermAndUnits) {
  const auto& registry = model::Registry::Global();
  const std::string text = CatalogueText(registry);
  for (const auto& name : registry.Names()) {
    const auto info = registry.Make(name)->info();
    EXPECT_NE(text.find(info.name), std::string::npos) << name;
    EXPECT_NE(text.find(info.term), std::string::npos) << name;
    for (int i = 0; i < info.size(); ++i) {
      EXPECT_NE(text.find(info.ParameterName(i)), std::string::npos) << info.ParameterName(i);
    }
  }
  EXPECT_NE(text.find("rad/s per m/s^2"), std::string::npos);
}

TEST(Catalogue, OneEffectOnly) {
  const std::string text = CatalogueText(model::Registry::Global(), "gyro_g_sensitivity");
  EXPECT_NE(text.find("gyro_g_sensitivity.G.zy"), std::string::npos);
  EXPECT_EQ(text.find("accel_linear"), std::string::npos);
}

TEST(Catalogue, UnknownEffectThrowsNamingIt) {
  try {
    CatalogueText(model::Registry::Global(), "no_such_effect");
    ADD_FAILURE() << "expected plumb::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_effect"), std::string::npos) << e.what();
  }
}

TEST(Catalogue, JsonHasOneEntryPerEffectWithParameterUnits) {
  const auto& registry = model::Registry::Global();
  const auto j = CatalogueJson(registry);
  ASSERT_EQ(j.size(), registry.Names().size());
  EXPECT_EQ(j[0]["name"], "accel_linear");
  EXPECT_EQ(j[0]["base"], true);
  EXPECT_EQ(j[0]["parameters"][6]["name"], "accel.bias.x");
  EXPECT_EQ(j[0]["parameters"][6]["unit"], "m/s^2");
}

}  // namespace
}  // namespace plumb::report
