// The typed parameter set (vrflow/base/parameters.hpp): one parser, typed reads that fail
// loudly, and the codec that carries a module's set through shared memory.
#include "vrflow/base/parameters.hpp"

#include <gtest/gtest.h>

#include "vrflow/app/package.hpp"

namespace vrflow::app {
namespace {

ParamSpec spec(std::string name, ParamType type, std::string defaultValue) {
  ParamSpec param;
  param.name = std::move(name);
  param.type = type;
  param.defaultValue = std::move(defaultValue);
  return param;
}

std::vector<ParamSpec> someSpecs() {
  ParamSpec mode = spec("mode", ParamType::Enum, "fifo");
  mode.choices = {"fifo", "latest"};
  ParamSpec count = spec("count", ParamType::Int, "4");
  count.min = 1;
  return {count,
          spec("dt", ParamType::Float, "0.01"),
          spec("sleep", ParamType::Bool, "true"),
          spec("name", ParamType::String, "a b"),
          mode,
          spec("g", ParamType::Vec3, "0 -9.81 0"),
          spec("log", ParamType::File, ""),
          spec("seed", ParamType::Int, "")};
}

Parameters build(const std::vector<Param>& values) {
  auto set = parameterSet(someSpecs(), values, "module 'm' (pkg/type)");
  EXPECT_TRUE(set.ok()) << set.error().message;
  return set.ok() ? std::move(*set) : Parameters();
}

TEST(Parameters, HoldTheApplicationsValuesOverTheDefaultsTyped) {
  const Parameters set = build({{"count", "7", {}}, {"g", "1, 2, 3", {}}, {"mode", "latest", {}}});
  EXPECT_EQ(set.getInt("count"), 7);
  EXPECT_DOUBLE_EQ(set.getFloat("dt"), 0.01);
  EXPECT_TRUE(set.getBool("sleep"));
  EXPECT_EQ(set.getString("name"), "a b");
  EXPECT_EQ(set.getString("mode"), "latest");
  EXPECT_EQ(set.getVec3("g"), (ParamVec3{1, 2, 3}));
  EXPECT_EQ(set.getString("log"), "");
  EXPECT_FALSE(set.firstError().has_value());
}

TEST(Parameters, ReadingAnUndeclaredNameIsAnErrorNamingTheOwnerAndTheParameter) {
  const Parameters set = build({});
  EXPECT_EQ(set.getInt("cuont"), 0);
  ASSERT_TRUE(set.firstError().has_value());
  EXPECT_NE(set.firstError()->message.find("module 'm' (pkg/type): reads parameter 'cuont', "
                                           "which is not declared (declared: count, dt, g,"),
            std::string::npos)
      << set.firstError()->message;
}

TEST(Parameters, ReadingAsAnotherTypeIsAnError) {
  const Parameters set = build({});
  EXPECT_EQ(set.getFloat("count"), 0.0);
  ASSERT_TRUE(set.firstError().has_value());
  EXPECT_EQ(set.firstError()->message,
            "module 'm' (pkg/type): reads parameter 'count' as a float, but it is declared int");
}

TEST(Parameters, ReadingOneWithNeitherValueNorDefaultIsAnError) {
  const Parameters set = build({});
  EXPECT_TRUE(set.declares("seed"));
  EXPECT_FALSE(set.hasValue("seed"));
  set.getInt("seed");
  ASSERT_TRUE(set.firstError().has_value());
  EXPECT_NE(set.firstError()->message.find("parameter 'seed' has no value"), std::string::npos);
  EXPECT_EQ(build({{"seed", "3", {}}}).getInt("seed"), 3);
}

TEST(Parameters, AFailedReadGoesToTheFailureHandlerWhenOneIsSet) {
  static std::string reported;
  Parameters set = build({});
  set.setFailureHandler([](const Error& error) { reported = error.message; });
  set.getBool("missing");
  EXPECT_NE(reported.find("reads parameter 'missing'"), std::string::npos) << reported;
}

TEST(Parameters, SurviveTheirCodecUnchanged) {
  const Parameters set =
      build({{"dt", "0.1", {}}, {"name", "x=y\nz", {}}, {"g", "1e-300 2 3", {}}});
  const auto decoded = decodeParameters(encodeParameters(set));
  ASSERT_TRUE(decoded.ok()) << decoded.error().message;
  EXPECT_EQ(decoded->owner(), "module 'm' (pkg/type)");
  ASSERT_EQ(decoded->entries().size(), set.entries().size());
  for (const auto& [name, entry] : set.entries()) {
    const auto found = decoded->entries().find(name);
    ASSERT_NE(found, decoded->entries().end()) << name;
    EXPECT_EQ(found->second.type, entry.type) << name;
    EXPECT_EQ(found->second.value, entry.value) << name;
  }
  EXPECT_EQ(decoded->getString("name"), "x=y\nz");  // text is carried as is, not as lines
  EXPECT_DOUBLE_EQ(decoded->getFloat("dt"), 0.1);
  EXPECT_FALSE(decoded->hasValue("seed"));
}

TEST(Parameters, CodecRefusesBytesThatAreNotASet) {
  const std::string bytes = encodeParameters(build({}));
  EXPECT_FALSE(decodeParameters("count=4\n").ok());  // the old text form
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    EXPECT_FALSE(decodeParameters(std::string_view(bytes).substr(0, cut)).ok()) << cut;
  }
  EXPECT_FALSE(decodeParameters(bytes + "x").ok());
}

// One rule for a value: the validator's check and the set the module reads use the same parser,
// so a value is refused by both or accepted by both (massspring's modules once took "yes").
TEST(Parameters, AValueTheValidatorRefusesCannotBeBuiltIntoASet) {
  for (const char* text : {"yes", "on", "no", "off", "True", ""}) {
    const ParamSpec flag = spec("pin-corners", ParamType::Bool, "true");
    const auto problem = checkParamValue(flag, text);
    ASSERT_TRUE(problem.has_value()) << text;
    EXPECT_EQ(*problem, "expects a bool (true or false), got '" + std::string(text) + "'");
    const auto set = parameterSet({flag}, {{"pin-corners", text, {}}}, "module 'net'");
    ASSERT_FALSE(set.ok()) << text;
    EXPECT_EQ(set.error().message, "module 'net': parameter 'pin-corners' " + *problem);
  }
  for (const char* text : {"true", "1", "false", "0"}) {
    const ParamSpec flag = spec("pin-corners", ParamType::Bool, "true");
    EXPECT_FALSE(checkParamValue(flag, text).has_value()) << text;
    EXPECT_TRUE(parameterSet({flag}, {{"pin-corners", text, {}}}, "module 'net'").ok()) << text;
  }
}

TEST(Parameters, ASetRefusesANameItsSpecsDoNotDeclare) {
  const auto set = parameterSet(someSpecs(), {{"cuont", "3", {}}}, "filter 'f' (latest)");
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.error().message, "filter 'f' (latest) has no parameter 'cuont'");
}

}  // namespace
}  // namespace vrflow::app
