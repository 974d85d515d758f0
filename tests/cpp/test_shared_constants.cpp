// `enamel-dem constants` (shared_constants.hpp) prints what the C++ declares: every exit code of exit_codes.hpp,
// the warning bounds of runner.hpp, the seal of output.hpp field by field, the result file of each run status,
// the adaptive rate's bounds and every Choice key's names, each value exactly (the TOML's reals to 17 digits).
#include <gtest/gtest.h>

#include <toml++/toml.h>

#include <string>

#include "base/exit_codes.hpp"
#include "case/case_params.hpp"
#include "io/output.hpp"
#include "kernels/loading_rate.hpp"
#include "run/runner.hpp"
#include "run/shared_constants.hpp"

using namespace enamel;

TEST(SharedConstants, PrintedAreTheDeclared) {
  const toml::table t = toml::parse(sharedConstantsToml());
  const toml::table& codes = *t["exit_codes"].as_table();
  EXPECT_EQ(codes.size(), std::size(exit_code::kExitCodes));
  for (const exit_code::ExitCode& e : exit_code::kExitCodes) EXPECT_EQ(codes[e.name].value<int>(), e.value) << e.name;
  EXPECT_EQ(codes["missing_file"].value<int>(), exit_code::missing_file);
  EXPECT_EQ(t["kinetic_warn"].value<double>(), kKineticWarn);
  EXPECT_EQ(t["balance_warn"].value<double>(), kBalanceWarn);
  EXPECT_EQ(t["loading_rate"]["rho_low"].value<double>(), kRateRhoLow);
  EXPECT_EQ(t["loading_rate"]["rho_low_share"].value<double>(), kRateRhoLowShare);
  EXPECT_EQ(t["loading_rate"]["lower"].value<double>(), kRateLower);

  const toml::node_view<const toml::node> seal = t["result_seal"];
  EXPECT_EQ(seal["magic"].value<std::string>(), std::string(kResultMagic, sizeof kResultMagic));
  EXPECT_EQ(seal["format"].value<std::uint32_t>(), kSealFormat);
  EXPECT_EQ(seal["bytes"].value<std::size_t>(), sizeof(ResultSeal));
  EXPECT_EQ(seal["userblock_bytes"].value<std::size_t>(), kUserblockBytes);
  const toml::array& fields = *seal["fields"].as_array();
  ASSERT_EQ(fields.size(), sealFields().size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const toml::table& f = *fields[i].as_table();
    EXPECT_EQ(f["name"].value<std::string>(), sealFields()[i].name);
    EXPECT_EQ(f["struct"].value<std::string>(), sealFields()[i].structCode);
    EXPECT_EQ(f["offset"].value<std::size_t>(), sealFields()[i].offset);
  }
  EXPECT_EQ(fields[2].as_table()->at("offset").value<std::size_t>(), offsetof(ResultSeal, crc));

  const toml::table& files = *t["result_files"].as_table();
  EXPECT_EQ(files.size(), enumNames<RunStatus>().size());
  for (RunStatus s : {RunStatus::running, RunStatus::completed, RunStatus::failed, RunStatus::interrupted})
    EXPECT_EQ(files[nameOf(s)].value<std::string>(), resultFileName(s)) << nameOf(s);
  EXPECT_EQ(resultFileFor("d", RunStatus::completed), "d/result.h5");

  std::size_t choiceKeys = 0;
  for (const KeySpec& k : caseKeys()) {
    if (k.kind != Kind::Choice) continue;
    ++choiceKeys;
    const toml::array& names = *t["key_choices"][k.name].as_array();
    const auto declared = splitEnumNames(k.choices);
    ASSERT_EQ(names.size(), declared.size()) << k.name;
    for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(names[i].value<std::string>(), declared[i]) << k.name;
  }
  EXPECT_EQ(t["key_choices"].as_table()->size(), choiceKeys);
  EXPECT_EQ(t["key_choices"]["integrator"][1].value<std::string>(), nameOf(IntegratorScheme::lumped));
}

// The JSON is the same object: every key of the TOML appears in it, and it is one JSON object.
TEST(SharedConstants, JsonIsOneObjectWithEveryTable) {
  const std::string json = sharedConstantsJson();
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json[json.find_last_not_of('\n')], '}');
  for (const char* key : {"exit_codes", "kinetic_warn", "balance_warn", "result_seal", "run_statuses", "result_files",
                          "loading_rate", "key_choices", "missing_file", "file_bytes"})
    EXPECT_NE(json.find(std::string("\"") + key + "\""), std::string::npos) << key;
}
