// The numbers shared with Python (see shared_constants.hpp), gathered into one TOML table and written by toml++.
#include "run/shared_constants.hpp"

#include <toml++/toml.h>

#include <sstream>

#include "base/exit_codes.hpp"
#include "case/case_params.hpp"
#include "io/output.hpp"
#include "kernels/loading_rate.hpp"
#include "run/runner.hpp"

namespace enamel {

namespace {

template <class E>
toml::array namesOf() {
  toml::array out;
  for (const std::string& name : enumNames<E>()) out.push_back(name);
  return out;
}

toml::table resultSeal() {
  toml::array fields;
  for (const SealField& f : sealFields())
    fields.push_back(toml::table{{"name", f.name}, {"struct", f.structCode},
                                 {"offset", static_cast<std::int64_t>(f.offset)},
                                 {"bytes", static_cast<std::int64_t>(f.bytes)}});
  return toml::table{{"magic", std::string(kResultMagic, sizeof kResultMagic)},
                     {"format", static_cast<std::int64_t>(kSealFormat)},
                     {"userblock_bytes", static_cast<std::int64_t>(kUserblockBytes)},
                     {"bytes", static_cast<std::int64_t>(sizeof(ResultSeal))},
                     {"byte_order", "little"},
                     {"fields", fields}};
}

// The allowed values of every Choice key, in the order of their enum.
toml::table keyChoices() {
  toml::table out;
  for (const KeySpec& s : caseKeys()) {
    if (s.kind != Kind::Choice) continue;
    toml::array names;
    for (const std::string& name : splitEnumNames(s.choices)) names.push_back(name);
    out.insert(s.name, names);
  }
  return out;
}

toml::table sharedConstants() {
  toml::table exitCodes, resultFiles;
  for (const exit_code::ExitCode& e : exit_code::kExitCodes) exitCodes.insert(e.name, e.value);
  for (std::size_t i = 0; i < enumNames<RunStatus>().size(); ++i)
    resultFiles.insert(enumNames<RunStatus>()[i], resultFileName(static_cast<RunStatus>(i)));
  return toml::table{
      {"exit_codes", exitCodes},
      {"kinetic_warn", kKineticWarn},
      {"balance_warn", kBalanceWarn},
      {"result_seal", resultSeal()},
      {"run_statuses", namesOf<RunStatus>()},
      {"result_files", resultFiles},
      {"loading_rate", toml::table{{"rho_high", kRateRhoHigh}, {"rho_low", kRateRhoLow},
                                   {"rho_low_share", kRateRhoLowShare}, {"raise", kRateRaise},
                                   {"lower", kRateLower}}},
      {"key_choices", keyChoices()},
  };
}

}  // namespace

std::string sharedConstantsJson() {
  std::ostringstream out;
  out << toml::json_formatter{sharedConstants()} << "\n";
  return out.str();
}

std::string sharedConstantsToml() {
  std::ostringstream out;
  out << sharedConstants() << "\n";
  return out.str();
}

}  // namespace enamel
