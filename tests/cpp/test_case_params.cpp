// Case-file parsing: one test per error class (exit code + a message naming key, value, range),
// the layering order, the key table's own consistency, and round-tripping the effective case.
#include "base/exit_codes.hpp"
#include "case/case_params.hpp"
#include "kernels/loading_rate.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#ifndef ENAMEL_SOURCE_DIR
#define ENAMEL_SOURCE_DIR "."  // standalone compile: run from the repository root
#endif

using enamel::CaseError;
using enamel::CaseParams;
using enamel::KeySpec;
using enamel::Kind;
using enamel::parseCase;
using namespace enamel;  // the choices' enums (choices.hpp)
namespace exit_code = enamel::exit_code;

namespace {

// The three required physics keys.
const std::string kPhysics = "theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n";

CaseParams parse(const std::string& extra, const std::string& preset = "",
                 const std::vector<std::string>& sets = {}) {
    return parseCase(kPhysics + extra, "case.toml", preset, sets);
}

// Run f, which must throw CaseError; return it.
CaseError caseErrorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const CaseError& e) {
        return e;
    }
    ADD_FAILURE() << "expected a CaseError";
    return CaseError(-1, "");
}

// The message is one line and contains every piece.
void expectMessage(const CaseError& e, const std::vector<std::string>& pieces) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    for (const std::string& p : pieces) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
}

std::string writeTempFile(const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + name;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return path;
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
    return path;
}

// Lines of a TOML text that are not comments or blank: the key = value part.
std::string keyLines(const std::string& toml) {
    std::istringstream in(toml);
    std::string line, out;
    while (std::getline(in, line))
        if (!line.empty() && line[0] != '#') out += line + "\n";
    return out;
}

}  // namespace

// Derived quantities are exact arithmetic on the inputs: compare to 1e-12 relative (rounding only).
constexpr double kArithmeticTol = 1e-12;

TEST(CaseParams, MinimalCaseTakesDefaultsAndDerivedQuantities) {
    const CaseParams p = parse("");
    EXPECT_EQ(p.theta_D, 30.0);
    EXPECT_EQ(p.Er_over_kd, 10.0);
    EXPECT_EQ(p.sigma_ru_over_sigma0, 21.4);
    EXPECT_EQ(p.cv, 0.0);
    EXPECT_EQ(p.Gamma_k_over_sigma0sq, 9.0);
    EXPECT_EQ(p.crisscross_at_tip, CrisscrossAtTip::cut);
    EXPECT_EQ(p.section, SectionShape::hexagon);
    EXPECT_EQ(p.seed, 1);
    EXPECT_TRUE(p.rods_breakable);
    EXPECT_TRUE(p.interfaces_breakable);
    EXPECT_EQ(p.w_s_over_d, 32.0);
    EXPECT_EQ(p.h_s_over_d, 16.0);
    EXPECT_EQ(p.h_e_over_d, 0.3);
    EXPECT_EQ(p.integrator, IntegratorScheme::paper);
    EXPECT_EQ(p.linear_solver, LinearSolver::cholmod);
    EXPECT_EQ(p.deletion_rule, DeletionRule::most_overloaded);
    EXPECT_EQ(p.max_steps, 0);
    EXPECT_EQ(p.frames_da_over_d, (std::vector<double>{5, 15, 30}));
    EXPECT_EQ(p.sourceName, "case.toml");
    EXPECT_EQ(p.presetName, "");
    // k = 1/10, sigma0 = delta0 k = 0.1 k, Gamma = 9 sigma0^2 / k, sigma_ru = 21.4 sigma0, a0 = 0.5 x 32.
    EXPECT_NEAR(p.k(), 0.1, kArithmeticTol * 0.1);
    EXPECT_NEAR(p.sigma0(), 1e-2, kArithmeticTol * 1e-2);
    EXPECT_NEAR(p.Gamma(), 9e-3, kArithmeticTol * 9e-3);
    EXPECT_NEAR(p.sigma_ru(), 21.4e-2, kArithmeticTol * 21.4e-2);
    EXPECT_NEAR(p.a0(), 16.0, kArithmeticTol * 16.0);
}

TEST(CaseParams, UnknownKeySuggestsClosestKey) {
    const auto e = caseErrorOf([] {
        parseCase("theta = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "", {});
    });
    EXPECT_EQ(e.exitCode, exit_code::unknown_key);
    EXPECT_STREQ(e.what(), "case.toml: unknown key 'theta' (did you mean 'theta_D'? 'enamel-dem keys' lists all keys)");
    // Nothing close: no suggestion.
    const auto far = caseErrorOf([] { parse("qqqqqqqqqq = 1\n"); });
    EXPECT_EQ(far.exitCode, exit_code::unknown_key);
    expectMessage(far, {"case.toml", "'qqqqqqqqqq'", "'enamel-dem keys'"});
    EXPECT_EQ(std::string(far.what()).find("did you mean"), std::string::npos) << far.what();
    // A one-letter key is not "close" to a two-letter one; a fragment of a key name is.
    const auto oneLetter = caseErrorOf([] { parse("d = 1\n"); });
    EXPECT_EQ(std::string(oneLetter.what()).find("did you mean"), std::string::npos) << oneLetter.what();
    const auto fragment = caseErrorOf([] { parse("w_s = 10\n"); });
    expectMessage(fragment, {"'w_s'", "did you mean 'w_s_over_d'?"});
    const auto wrongCase = caseErrorOf([] { parse("CV = 0.1\n"); });
    expectMessage(wrongCase, {"'CV'", "did you mean 'cv'?"});
}

TEST(CaseParams, WrongTypeNamesKeyValueAndExpectedRange) {
    const auto e = caseErrorOf([] {
        parseCase("theta_D = \"thirty\"\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "", {});
    });
    EXPECT_EQ(e.exitCode, exit_code::wrong_type);
    EXPECT_STREQ(e.what(),
                 "case.toml: key 'theta_D' = \"thirty\" has the wrong type; expected a real number in [0, 45] (deg)");
    const auto integer = caseErrorOf([] { parse("seed = 1.5\n"); });
    EXPECT_EQ(integer.exitCode, exit_code::wrong_type);
    expectMessage(integer, {"'seed'", "1.5", "integer", "[0, 2147483647]"});
    const auto boolean = caseErrorOf([] { parse("rods_breakable = 1\n"); });
    EXPECT_EQ(boolean.exitCode, exit_code::wrong_type);
    expectMessage(boolean, {"'rods_breakable'", "= 1", "true or false"});
    const auto list = caseErrorOf([] { parse("frames_da_over_d = 5\n"); });
    EXPECT_EQ(list.exitCode, exit_code::wrong_type);
    expectMessage(list, {"'frames_da_over_d'", "= 5", "list", "[0, 1e4]"});
}

TEST(CaseParams, OutOfRangeNamesKeyValueAndRange) {
    const auto e = caseErrorOf([] {
        parseCase("theta_D = 60\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "", {});
    });
    EXPECT_EQ(e.exitCode, exit_code::out_of_range);
    EXPECT_STREQ(e.what(), "case.toml: key 'theta_D' = 60 is out of range; allowed [0, 45] (deg)");
    // An open bound is excluded and shown as such.
    const auto open = caseErrorOf([] {
        parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 0\n", "case.toml", "", {});
    });
    EXPECT_EQ(open.exitCode, exit_code::out_of_range);
    expectMessage(open, {"'sigma_ru_over_sigma0'", "= 0", "(0, 1e6]"});
    const auto choice = caseErrorOf([] { parse("integrator = \"fast\"\n"); });
    EXPECT_EQ(choice.exitCode, exit_code::out_of_range);
    expectMessage(choice, {"'integrator'", "\"fast\"", "\"paper\"", "\"lumped\""});
    const auto integer = caseErrorOf([] { parse("seed = -1\n"); });
    EXPECT_EQ(integer.exitCode, exit_code::out_of_range);
    expectMessage(integer, {"'seed'", "-1", "[0, 2147483647]"});
    const auto element = caseErrorOf([] { parse("frames_da_over_d = [5, -1]\n"); });
    EXPECT_EQ(element.exitCode, exit_code::out_of_range);
    expectMessage(element, {"'frames_da_over_d'", "[5, -1]", "each in [0, 1e4]"});
}

TEST(CaseParams, IntegerBoundsAreExact) {
    EXPECT_EQ(parse("max_steps = 4611686018427387904\n").max_steps, 4611686018427387904LL);  // 2^62 allowed
    const auto e = caseErrorOf([] { parse("max_steps = 4611686018427387905\n"); });
    EXPECT_EQ(e.exitCode, exit_code::out_of_range);
    expectMessage(e, {"'max_steps'", "4611686018427387905", "[0, 4611686018427387904]"});
}

TEST(CaseParams, NonFiniteValueIsOutOfRange) {
    for (const std::string value : {"nan", "inf", "-inf"}) {
        const auto e = caseErrorOf([&] { parse("v_app_over_cd = " + value + "\n"); });
        EXPECT_EQ(e.exitCode, exit_code::out_of_range);
        expectMessage(e, {"'v_app_over_cd'", "= " + value, "is not finite", "(0, 0.1]"});
    }
    const auto list = caseErrorOf([] { parse("frames_da_over_d = [1, nan]\n"); });
    EXPECT_EQ(list.exitCode, exit_code::out_of_range);
    expectMessage(list, {"'frames_da_over_d'", "is not finite"});
}

TEST(CaseParams, NegativeSizeIsOutOfRange) {
    const auto e = caseErrorOf([] { parse("w_s_over_d = -5\n"); });
    EXPECT_EQ(e.exitCode, exit_code::out_of_range);
    EXPECT_STREQ(e.what(), "case.toml: key 'w_s_over_d' = -5 is out of range; allowed [2, 2000] (d)");
}

TEST(CaseParams, SliceSpacingLargerThanDIsAnError) {
    const auto e = caseErrorOf([] { parse("h_e_over_d = 1.5\n"); });
    EXPECT_EQ(e.exitCode, exit_code::out_of_range);
    expectMessage(e, {"case.toml", "'h_e_over_d'", "= 1.5", "h_e larger than d", "(0, 1]"});
    EXPECT_EQ(parse("h_e_over_d = 1\n").h_e_over_d, 1.0);  // h_e = d itself is allowed
}

TEST(CaseParams, MissingRequiredKey) {
    const auto e = caseErrorOf([] { parseCase("Er_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "", {}); });
    EXPECT_EQ(e.exitCode, exit_code::unknown_key);
    EXPECT_STREQ(e.what(), "case.toml: missing required key 'theta_D' (decussation angle, deg; allowed [0, 45])");
    // A --set override can supply it.
    const CaseParams p = parseCase("Er_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "", {"theta_D=15"});
    EXPECT_EQ(p.theta_D, 15.0);
}

TEST(CaseParams, MissingFile) {
    const std::string path = ::testing::TempDir() + "no_such_dir/x.toml";
    const auto e = caseErrorOf([&] { enamel::loadCase(path, "", {}); });
    EXPECT_EQ(e.exitCode, exit_code::missing_file);
    EXPECT_EQ(std::string(e.what()), "cannot open case file '" + path + "': No such file or directory");
    // A directory opens but cannot be read.
    const auto dir = caseErrorOf([] { enamel::loadCase(::testing::TempDir(), "", {}); });
    EXPECT_EQ(dir.exitCode, exit_code::missing_file);
    expectMessage(dir, {"case file", ::testing::TempDir()});
}

TEST(CaseParams, MalformedToml) {
    const auto e = caseErrorOf([] { parseCase("theta_D = 30\nEr_over_kd = = 10\n", "case.toml", "", {}); });
    EXPECT_EQ(e.exitCode, exit_code::malformed_toml);
    expectMessage(e, {"case.toml:2:", ": malformed TOML: "});
    const auto duplicate = caseErrorOf([] { parse("theta_D = 15\n"); });
    EXPECT_EQ(duplicate.exitCode, exit_code::malformed_toml);
    expectMessage(duplicate, {"case.toml:4:", "malformed TOML", "theta_D"});
}

TEST(CaseParams, NestedTableIsAnError) {
    const auto e = caseErrorOf([] { parseCase("[physics]\ntheta_D = 30\n", "case.toml", "", {}); });
    EXPECT_EQ(e.exitCode, exit_code::unknown_key);
    expectMessage(e, {"case.toml", "'physics'", "is a table"});
    const auto dotted = caseErrorOf([] { parse("numerics.zeta = 0.1\n"); });
    EXPECT_EQ(dotted.exitCode, exit_code::unknown_key);
    expectMessage(dotted, {"'numerics'", "is a table"});
    const auto known = caseErrorOf([] { parse("zeta = { a = 1 }\n"); });
    EXPECT_EQ(known.exitCode, exit_code::wrong_type);
    expectMessage(known, {"'zeta'", "a = 1", "[0, 1]"});
}

TEST(CaseParams, BadSetOverride) {
    const auto noEquals = caseErrorOf([] { parse("", "", {"theta_D"}); });
    EXPECT_EQ(noEquals.exitCode, exit_code::usage);
    expectMessage(noEquals, {"--set", "'theta_D'", "key=value"});
    const auto noKey = caseErrorOf([] { parse("", "", {"=3"}); });
    EXPECT_EQ(noKey.exitCode, exit_code::usage);
    const auto unknown = caseErrorOf([] { parse("", "", {"theta=15"}); });
    EXPECT_EQ(unknown.exitCode, exit_code::unknown_key);
    expectMessage(unknown, {"--set theta=15", "'theta'", "did you mean 'theta_D'"});
    const auto range = caseErrorOf([] { parse("", "", {"theta_D=99"}); });
    EXPECT_EQ(range.exitCode, exit_code::out_of_range);
    EXPECT_STREQ(range.what(), "--set theta_D=99: key 'theta_D' = 99 is out of range; allowed [0, 45] (deg)");
    const auto type = caseErrorOf([] { parse("", "", {"theta_D=thirty"}); });
    EXPECT_EQ(type.exitCode, exit_code::wrong_type);
    expectMessage(type, {"'theta_D'", "\"thirty\"", "[0, 45]"});
}

TEST(CaseParams, UnknownPreset) {
    const auto e = caseErrorOf([] { parse("", "fast"); });
    EXPECT_EQ(e.exitCode, exit_code::usage);
    EXPECT_STREQ(e.what(), "unknown preset 'fast'; allowed presets: ci, reduced, converged, paper");
}

TEST(CaseParams, LayeringDefaultsPresetFileSet) {
    // defaults
    EXPECT_EQ(parse("").w_s_over_d, 32.0);
    // preset > defaults
    const CaseParams preset = parse("", "reduced");
    EXPECT_EQ(preset.presetName, "reduced");
    EXPECT_EQ(preset.w_s_over_d, 40.0);
    EXPECT_EQ(preset.h_s_over_d, 20.0);
    EXPECT_EQ(preset.frames_da_over_d, (std::vector<double>{3, 6, 12}));
    EXPECT_EQ(preset.zeta, 0.2);  // not in the preset: default
    // case file > preset
    const CaseParams file = parse("w_s_over_d = 50\n", "reduced");
    EXPECT_EQ(file.w_s_over_d, 50.0);
    EXPECT_EQ(file.h_s_over_d, 20.0);
    // --set > case file, later --set > earlier
    const CaseParams set = parse("w_s_over_d = 50\n", "reduced", {"w_s_over_d=60", "w_s_over_d = 70"});
    EXPECT_EQ(set.w_s_over_d, 70.0);
    EXPECT_EQ(set.h_s_over_d, 20.0);
}

TEST(CaseParams, SetValuesAreTomlValues) {
    const CaseParams p = parse("", "", {"theta_D=15", "integrator=lumped", "linear_solver=\"umfpack\"",
                                        "frames_da_over_d=[1,2.5]", "rods_breakable=false", "seed=7",
                                        "description=a free text"});
    EXPECT_EQ(p.theta_D, 15.0);
    EXPECT_EQ(p.integrator, IntegratorScheme::lumped);  // not valid TOML: taken as a string
    EXPECT_EQ(p.linear_solver, LinearSolver::umfpack);
    EXPECT_EQ(p.frames_da_over_d, (std::vector<double>{1, 2.5}));
    EXPECT_FALSE(p.rods_breakable);
    EXPECT_EQ(p.seed, 7);
    EXPECT_EQ(p.description, "a free text");
}

TEST(CaseParams, PresetsParseAndSetNumericsOnly) {
    const auto names = enamel::presetNames();
    ASSERT_EQ(names, (std::vector<std::string>{"ci", "reduced", "converged", "paper"}));
    const CaseParams none = parse("");
    for (const std::string& name : names) {
        // A preset that set a physics key would throw std::logic_error here.
        const CaseParams p = parse("", name);
        EXPECT_EQ(p.presetName, name);
        EXPECT_EQ(p.theta_D, none.theta_D);
        EXPECT_EQ(p.cv, none.cv);
        EXPECT_EQ(p.Gamma_k_over_sigma0sq, none.Gamma_k_over_sigma0sq);
        EXPECT_EQ(p.seed, none.seed);
    }
    const CaseParams ci = parse("", "ci");
    EXPECT_EQ(ci.v_app_over_cd, 2e-3);
    EXPECT_EQ(ci.stop_da_over_d, 5.0);
    EXPECT_EQ(ci.frames_da_over_d, (std::vector<double>{1, 2.5, 5}));
    const CaseParams converged = parse("", "converged");   // the square size converged at the default G
    EXPECT_EQ(converged.w_s_over_d, 80.0);
    EXPECT_EQ(converged.h_s_over_d, 80.0);
    EXPECT_EQ(converged.v_app_over_cd, 1e-3);
    EXPECT_EQ(converged.integrator, IntegratorScheme::lumped);
    EXPECT_EQ(converged.static_start, 0.95);
    EXPECT_EQ(converged.stop_da_over_d, 30.0);
    const CaseParams paper = parse("", "paper");
    EXPECT_EQ(paper.w_s_over_d, 200.0);
    EXPECT_EQ(paper.h_s_over_d, 200.0);
}

// A field added to CaseParams by hand, outside ENAMEL_CASE_KEYS, would be a key that no case file can set
// and that neither the effective case nor `enamel-dem keys` shows. The key fields are declared by the
// table itself, so the only way to make that mistake is to add a field beside the three provenance
// strings: this fails to compile when CaseParams holds anything more than the table's fields and those.
namespace {
struct TableFieldsOnly {
    ENAMEL_CASE_KEYS(ENAMEL_CASE_FIELD)
};
#define COUNT_KEY(...) +1
constexpr std::size_t kTableRows = 0 ENAMEL_CASE_KEYS(COUNT_KEY);
#undef COUNT_KEY
}  // namespace
static_assert(sizeof(CaseParams) == sizeof(TableFieldsOnly) + 3 * sizeof(std::string),
              "CaseParams has a field that is not a row of ENAMEL_CASE_KEYS (case_params.hpp): add the key there");

TEST(CaseParams, KeyTableHasOneRowPerKeyWithUnitMeaningAndDefaultInRange) {
    const auto& keys = enamel::caseKeys();
    ASSERT_EQ(keys.size(), kTableRows);
    ASSERT_GE(keys.size(), 30u);
    const CaseParams defaults;
    std::set<std::string> names;
    for (const KeySpec& s : keys) {
        SCOPED_TRACE(s.name);
        EXPECT_TRUE(names.insert(s.name).second) << "duplicate key";
        const std::string group = s.group, doc = s.doc, unit = s.unit, choices = s.choices;
        EXPECT_TRUE(group == "physics" || group == "numerics");
        EXPECT_FALSE(unit.empty());
        EXPECT_GT(doc.find(':'), 0u) << "doc needs 'short name: details'";
        EXPECT_NE(doc.find(':'), std::string::npos) << "doc needs 'short name: details'";
        EXPECT_GT(doc.size(), doc.find(':') + 2) << "doc needs details after the short name";
        EXPECT_EQ(choices.empty(), s.kind != Kind::Choice) << "choices are for Choice keys only";
        const bool ranged = s.kind == Kind::Real || s.kind == Kind::Integer || s.kind == Kind::RealList;
        if (ranged) {
            EXPECT_LT(s.minValue, s.maxValue) << "empty range";
        } else {
            EXPECT_TRUE(s.minValue == 0 && s.maxValue == 0 && !s.minOpen && !s.maxOpen) << "range on an unranged kind";
        }
        if (s.kind == Kind::Integer) {
            EXPECT_EQ(s.minValue, std::floor(s.minValue));
            EXPECT_EQ(s.maxValue, std::floor(s.maxValue));
        }
        if (s.required) {
            EXPECT_EQ(group, "physics");
            continue;
        }
        auto inRange = [&](double x) {
            return (s.minOpen ? x > s.minValue : x >= s.minValue) && (s.maxOpen ? x < s.maxValue : x <= s.maxValue);
        };
        switch (s.kind) {
            case Kind::Real: EXPECT_TRUE(inRange(defaults.*std::get<double CaseParams::*>(s.field))); break;
            case Kind::Integer:
                EXPECT_TRUE(inRange(static_cast<double>(defaults.*std::get<std::int64_t CaseParams::*>(s.field))));
                break;
            case Kind::RealList: {
                const auto& xs = defaults.*std::get<std::vector<double> CaseParams::*>(s.field);
                EXPECT_FALSE(xs.empty());
                for (const double x : xs) EXPECT_TRUE(inRange(x)) << x;
                break;
            }
            case Kind::Choice:
                EXPECT_LT(std::get<enamel::ChoiceField>(s.field).get(defaults), enamel::splitEnumNames(choices).size());
                break;
            case Kind::Bool:
            case Kind::Text: break;
        }
    }
    // Every default together passes the parser's own checks (the defaults are parsed as a case layer).
    EXPECT_NO_THROW(parse(""));
}

// The fuzzer's dictionary and its all-keys seed are copies of the key list made from `enamel-dem keys`:
// they must name exactly the keys of the table (and the dictionary every choice value).
TEST(CaseParams, FuzzDictionaryAndSeedNameEveryKey) {
    auto readFile = [](const std::string& path) {
        std::string text;
        if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
            char buf[4096];
            std::size_t n;
            while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
            std::fclose(f);
        }
        return text;
    };
    const std::string dict = readFile(std::string(ENAMEL_SOURCE_DIR) + "/tests/fuzz/toml.dict");
    const std::string seed = readFile(std::string(ENAMEL_SOURCE_DIR) + "/tests/fuzz/corpus/all_keys_effective.toml");
    ASSERT_FALSE(dict.empty());
    ASSERT_FALSE(seed.empty());
    std::set<std::string> tableNames, dictNames;
    for (const KeySpec& s : enamel::caseKeys()) tableNames.insert(s.name);
    std::istringstream lines(dict);
    std::string line;
    while (std::getline(lines, line))
        if (line.rfind("key_", 0) == 0) dictNames.insert(line.substr(4, line.find('=') - 4));
    EXPECT_EQ(dictNames, tableNames);
    for (const KeySpec& s : enamel::caseKeys()) {
        for (const std::string& choice : enamel::splitEnumNames(s.choices))
            EXPECT_NE(dict.find("=\"\\\"" + choice + "\\\"\"\n"), std::string::npos) << s.name << ": " << choice;
    }
    const CaseParams all = parseCase(seed, "all_keys_effective.toml", "", {});
    std::set<std::string> seedNames;
    std::istringstream seedLines(keyLines(seed));
    while (std::getline(seedLines, line)) seedNames.insert(line.substr(0, line.find(' ')));
    EXPECT_EQ(seedNames, tableNames);
    EXPECT_EQ(keyLines(all.tomlText), keyLines(seed)) << "the seed is an effective case: it reads back to itself";
}

TEST(CaseParams, FormatKeysMarkdownListsEveryKey) {
    const std::string md = enamel::formatKeysMarkdown();
    std::size_t rows = 0;
    for (char c : md) rows += c == '\n';
    EXPECT_EQ(rows, enamel::caseKeys().size() + 2);  // header + separator + one row per key
    for (const KeySpec& s : enamel::caseKeys())
        EXPECT_NE(md.find("| `" + std::string(s.name) + "` | " + s.group + " | "), std::string::npos) << s.name;
    EXPECT_NE(md.find("| `theta_D` | physics | required | [0, 45] | deg |"), std::string::npos) << md;
    EXPECT_NE(md.find("\"paper\", \"lumped\""), std::string::npos);
    EXPECT_NE(md.find("sigma0^2/k"), std::string::npos);
}

TEST(CaseParams, EffectiveTomlRoundTrips) {
    const CaseParams p = parse("description = \"quote \\\" and\\nnewline\"\ncv = 0.1\n", "reduced",
                               {"integrator=lumped", "frames_da_over_d=[1, 2.5]", "max_steps=12345"});
    EXPECT_NE(p.tomlText.find("# preset: reduced"), std::string::npos);
    EXPECT_NE(p.tomlText.find("# --set integrator=lumped"), std::string::npos);
    const CaseParams q = parseCase(p.tomlText, "effective.toml", "", {});
    EXPECT_EQ(keyLines(q.tomlText), keyLines(p.tomlText));
    EXPECT_EQ(q.description, "quote \" and\nnewline");
    EXPECT_EQ(q.cv, 0.1);
    EXPECT_EQ(q.w_s_over_d, 40.0);
    EXPECT_EQ(q.integrator, IntegratorScheme::lumped);
    EXPECT_EQ(q.frames_da_over_d, (std::vector<double>{1, 2.5}));
    EXPECT_EQ(q.max_steps, 12345);
    EXPECT_EQ(q.sigma_ru_over_sigma0, 21.4);  // shortest round-trip formatting keeps every bit
    EXPECT_EQ(q.delta0_over_d, 0.1);
}

TEST(CaseParams, LoadCaseReadsFileAndRecordsSource) {
    const std::string path = writeTempFile("case_params_load.toml", kPhysics + "cv = 0.2\n");
    const CaseParams p = enamel::loadCase(path, "ci", {"seed=3"});
    EXPECT_EQ(p.sourceName, path);
    EXPECT_EQ(p.cv, 0.2);
    EXPECT_EQ(p.seed, 3);
    EXPECT_EQ(p.w_s_over_d, 16.0);
    std::remove(path.c_str());
}

TEST(CaseParams, SmallTestCasesLoad) {
    for (const double theta : {0.0, 30.0}) {
        const std::string path = std::string(ENAMEL_SOURCE_DIR) + "/tests/cases/small_theta" +
                                 std::to_string(static_cast<int>(theta)) + ".toml";
        const CaseParams p = enamel::loadCase(path, "ci", {});  // case file sizes win over the preset
        EXPECT_EQ(p.theta_D, theta);
        EXPECT_EQ(p.Er_over_kd, 10.0);
        EXPECT_EQ(p.sigma_ru_over_sigma0, 21.4);
        EXPECT_EQ(p.w_s_over_d, 6.0);
        EXPECT_EQ(p.h_s_over_d, 4.0);
        EXPECT_EQ(p.h_e_over_d, 0.3);
        EXPECT_LT(p.stop_da_over_d, p.w_s_over_d - p.a0());
    }
}

// Fuzz findings (tests/fuzz/regressions/set-*.toml): the effective case must always read back. A --set value
// that is not valid UTF-8 is refused as a usage error; control characters in a --set are escaped, so that
// parseCase(tomlText) gives the same case again.
TEST(CaseParams, SetValuesThatTomlCannotHoldAreRefusedOrEscaped) {
    const std::string base = "theta_D = 0\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n";
    try {
        enamel::parseCase(base, "case", "", {"description=caf\xe9"});
        FAIL() << "invalid UTF-8 in --set was accepted";
    } catch (const CaseError& e) {
        EXPECT_EQ(e.exitCode, enamel::exit_code::usage);
        EXPECT_NE(std::string(e.what()).find("UTF-8"), std::string::npos) << e.what();
    }
    const enamel::CaseParams p = enamel::parseCase(base, "case", "", {"description=a\x01" "b"});
    EXPECT_EQ(p.description, "a\x01" "b");
    const enamel::CaseParams again = enamel::parseCase(p.tomlText, "again", "", {});
    EXPECT_EQ(again.description, p.description);
    auto keysPart = [](const std::string& t) { return t.substr(t.find("# --- physics")); };  // comments differ
    EXPECT_EQ(keysPart(again.tomlText), keysPart(p.tomlText));
}

// softening_over_delta0: allowed (0, 2 Gamma_k_over_sigma0sq - 1]; the upper bound depends on another key, so
// it is a cross-key check, still one line naming the key, the value and the allowed range.
TEST(CaseParams, SofteningOverDelta0RangeDependsOnGamma) {
    EXPECT_EQ(parse("").softening_over_delta0, 1.0);
    EXPECT_EQ(parse("Gamma_k_over_sigma0sq = 10\nsoftening_over_delta0 = 19\n").softening_over_delta0, 19.0);  // the triangle
    EXPECT_EQ(parse("softening_over_delta0 = 5\nGamma_k_over_sigma0sq = 3\n").softening_over_delta0, 5.0);
    const auto high = caseErrorOf([] { parse("Gamma_k_over_sigma0sq = 10\n", "", {"softening_over_delta0=20"}); });
    EXPECT_EQ(high.exitCode, exit_code::out_of_range);
    expectMessage(high, {"'softening_over_delta0'", "= 20", "(0, 19]", "Gamma_k_over_sigma0sq = 10"});
    const auto highAt3 = caseErrorOf([] { parse("Gamma_k_over_sigma0sq = 3\n", "", {"softening_over_delta0=6"}); });
    EXPECT_EQ(highAt3.exitCode, exit_code::out_of_range);
    expectMessage(highAt3, {"'softening_over_delta0'", "= 6", "(0, 5]", "Gamma_k_over_sigma0sq = 3"});
    const auto zero = caseErrorOf([] { parse("softening_over_delta0 = 0\n"); });
    EXPECT_EQ(zero.exitCode, exit_code::out_of_range);
    expectMessage(zero, {"'softening_over_delta0'", "= 0", "(0, "});
    const auto nan = caseErrorOf([] { parse("softening_over_delta0 = nan\n"); });
    EXPECT_EQ(nan.exitCode, exit_code::out_of_range);
    expectMessage(nan, {"'softening_over_delta0'", "nan"});
}

TEST(CaseParams, RodStressChoices) {
    EXPECT_EQ(parse("").rod_stress, RodStress::axial_bending);
    EXPECT_EQ(parse("", "", {"rod_stress=principal"}).rod_stress, RodStress::principal);
    EXPECT_EQ(parse("rod_stress = \"axial\"\n").rod_stress, RodStress::axial);
    const auto e = caseErrorOf([] { parse("rod_stress = \"von_mises\"\n"); });
    EXPECT_EQ(e.exitCode, exit_code::out_of_range);
    expectMessage(e, {"'rod_stress'", "\"von_mises\"", "\"axial_bending\"", "\"axial\"", "\"principal\""});
}

// The open readings of the model: shear_strength_ratio (0, 10], grip_constraint uy|uxuy, grip_profile
// to_right_edge|about_centre; defaults 1, "uy", "to_right_edge"; a bad value is one line naming the key, the
// value and what is allowed.
TEST(CaseParams, ModelReadingKeysDefaultsAndBadValues) {
    const CaseParams d = parse("");
    EXPECT_EQ(d.shear_strength_ratio, 1.0);
    EXPECT_EQ(d.grip_constraint, GripConstraint::uy);
    EXPECT_EQ(d.grip_profile, GripProfile::to_right_edge);
    const CaseParams set = parse("shear_strength_ratio = 2.5\ngrip_constraint = \"uxuy\"\ngrip_profile = \"about_centre\"\n");
    EXPECT_EQ(set.shear_strength_ratio, 2.5);
    EXPECT_EQ(set.grip_constraint, GripConstraint::uxuy);
    EXPECT_EQ(set.grip_profile, GripProfile::about_centre);
    EXPECT_EQ(parse("", "", {"shear_strength_ratio=10"}).shear_strength_ratio, 10.0);
    for (const char* bad : {"0", "-1", "10.5", "nan"}) {
        const auto e = caseErrorOf([&] { parse("", "", {std::string("shear_strength_ratio=") + bad}); });
        EXPECT_EQ(e.exitCode, exit_code::out_of_range) << bad;
        expectMessage(e, {"'shear_strength_ratio'", std::string("= ") + bad, "(0, 10]"});
    }
    const auto constraint = caseErrorOf([] { parse("grip_constraint = \"ux\"\n"); });
    EXPECT_EQ(constraint.exitCode, exit_code::out_of_range);
    expectMessage(constraint, {"'grip_constraint'", "\"ux\"", "\"uy\", \"uxuy\""});
    const auto profile = caseErrorOf([] { parse("grip_profile = \"centre\"\n"); });
    EXPECT_EQ(profile.exitCode, exit_code::out_of_range);
    expectMessage(profile, {"'grip_profile'", "\"centre\"", "\"to_right_edge\", \"about_centre\""});
    const auto type = caseErrorOf([] { parse("grip_profile = 1\n"); });
    EXPECT_EQ(type.exitCode, exit_code::wrong_type);
    expectMessage(type, {"'grip_profile'", "wrong type"});
}

// Every Choice key parses to its enum (choices.hpp): each allowed value, from a case file and from --set, gives
// the field the enumerator of that name, and the effective case writes the name back; the enumerators are the
// names in order. No Choice key is left a string.
TEST(CaseParams, EveryChoiceParsesToTheEnumeratorOfItsName) {
    std::size_t choiceKeys = 0;
    for (const KeySpec& s : enamel::caseKeys()) {
        if (s.kind != Kind::Choice) continue;
        SCOPED_TRACE(s.name);
        ++choiceKeys;
        ASSERT_TRUE(std::holds_alternative<enamel::ChoiceField>(s.field)) << "a Choice key's field is its enum";
        const auto names = enamel::splitEnumNames(s.choices);
        ASSERT_GE(names.size(), 2u);
        for (std::size_t i = 0; i < names.size(); ++i) {
            const std::string line = std::string(s.name) + " = \"" + names[i] + "\"";
            const CaseParams fromFile = parse(line + "\n");
            const CaseParams fromSet = parse("", "", {std::string(s.name) + "=" + names[i]});
            EXPECT_EQ(std::get<enamel::ChoiceField>(s.field).get(fromFile), i) << names[i];
            EXPECT_EQ(std::get<enamel::ChoiceField>(s.field).get(fromSet), i) << names[i];
            EXPECT_NE(fromFile.tomlText.find("\n" + line + "\n"), std::string::npos) << fromFile.tomlText;
        }
    }
    EXPECT_GE(choiceKeys, 9u);  // at least nine: none dropped, a new one needs no edit here
    EXPECT_EQ(parse("rate_adapt_rule = \"margin\"\n").rate_adapt_rule, RateAdaptRule::margin);
    EXPECT_EQ(parse("").rate_adapt_velocity, RateAdaptVelocity::keep);
    EXPECT_EQ(parse("").rate_adapt_rho_high, enamel::kRateRhoHigh);  // the rule's own bound is the key's default
    EXPECT_EQ(parse("rate_adapt_rho_high = 0.04\n").rate_adapt_rho_high, 0.04);
    EXPECT_EQ(parse("rate_adapt_velocity = \"quasi_static\"\n").rate_adapt_velocity, RateAdaptVelocity::quasi_static);
    EXPECT_EQ(parse("deletion_rule = \"all\"\n").deletion_rule, DeletionRule::all);
    EXPECT_EQ(parse("far_field_rod_breaks = \"allow\"\n").far_field_rod_breaks, FarFieldRodBreaks::allow);
    EXPECT_EQ(parse("").far_field_rod_breaks, FarFieldRodBreaks::stop);
    EXPECT_EQ(parse("crisscross_at_tip = \"cut\"\n").crisscross_at_tip, CrisscrossAtTip::cut);
    EXPECT_EQ(parse("section = \"circle\"\n").section, SectionShape::circle);
    EXPECT_EQ(parse("", "", {"linear_solver=umfpack"}).linear_solver, LinearSolver::umfpack);
}

// A value that is not one of a Choice key's names: one line naming the source, the key, the value and every
// allowed value, exit status out_of_range; a name differing only in case is not one of them.
TEST(CaseParams, BadChoiceIsOneLineNamingKeyValueAndAllowedValues) {
    for (const KeySpec& s : enamel::caseKeys()) {
        if (s.kind != Kind::Choice) continue;
        SCOPED_TRACE(s.name);
        const auto names = enamel::splitEnumNames(s.choices);
        std::string upper = names[0];
        for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        for (const std::string& bad : {std::string("no_such_value"), upper}) {
            const auto e = caseErrorOf([&] { parse(std::string(s.name) + " = \"" + bad + "\"\n"); });
            EXPECT_EQ(e.exitCode, exit_code::out_of_range);
            std::vector<std::string> pieces = {"case.toml: key '" + std::string(s.name) + "' = \"" + bad + "\"",
                                               "is not a valid choice; allowed one of "};
            for (const std::string& n : names) pieces.push_back("\"" + n + "\"");
            expectMessage(e, pieces);
        }
    }
    const auto e = caseErrorOf([] { parse("", "", {"integrator=leapfrog"}); });
    EXPECT_EQ(std::string(e.what()),
              "--set integrator=leapfrog: key 'integrator' = \"leapfrog\" is not a valid choice; allowed one of "
              "\"paper\", \"lumped\"");
}

// The names of a named enum are the text of its enumerators, in order; a name parses back to its enumerator.
TEST(NamedEnum, NamesAreTheEnumeratorsInOrder) {
    EXPECT_EQ(enamel::splitEnumNames("a, b_c,  d"), (std::vector<std::string>{"a", "b_c", "d"}));
    EXPECT_EQ(enamel::enumNames<RodStress>(), (std::vector<std::string>{"axial_bending", "axial", "principal"}));
    EXPECT_EQ(nameOf(RodStress::principal), "principal");
    EXPECT_EQ(nameOf(GripProfile::about_centre), "about_centre");
    EXPECT_EQ(nameOf(static_cast<RodStress>(3)), "?");
    EXPECT_EQ(enamel::enumFromName<DeletionRule>("all"), DeletionRule::all);
    EXPECT_EQ(enamel::enumFromName<DeletionRule>("most_overloaded"), DeletionRule::most_overloaded);
    EXPECT_FALSE(enamel::enumFromName<DeletionRule>("All").has_value());
    EXPECT_FALSE(enamel::enumFromName<DeletionRule>("").has_value());
}

// A key at its default counts as not given in a checkpoint's identity (isDefaultKeyLine): every optional key's
// line of the defaults' effective case is a default line, the same key with another value is not, required keys
// never are, and other lines are not key lines of the table.
TEST(CaseParams, DefaultKeyLinesAreThoseOfTheDefaults) {
    const CaseParams d = parse("");
    std::istringstream lines(d.tomlText);
    std::string line;
    std::set<std::string> atDefault;
    while (std::getline(lines, line))
        if (enamel::isDefaultKeyLine(line)) atDefault.insert(line.substr(0, line.find(" = ")));
    for (const KeySpec& s : enamel::caseKeys()) EXPECT_EQ(atDefault.count(s.name), s.required ? 0u : 1u) << s.name;
    EXPECT_TRUE(enamel::isDefaultKeyLine("shear_strength_ratio = 1.0"));
    EXPECT_TRUE(enamel::isDefaultKeyLine("grip_profile = \"to_right_edge\""));
    EXPECT_FALSE(enamel::isDefaultKeyLine("shear_strength_ratio = 2.0"));
    EXPECT_FALSE(enamel::isDefaultKeyLine("grip_constraint = \"uxuy\""));
    EXPECT_FALSE(enamel::isDefaultKeyLine("grip_profile = \"about_centre\""));
    EXPECT_FALSE(enamel::isDefaultKeyLine("theta_D = 0.0"));
    EXPECT_FALSE(enamel::isDefaultKeyLine("# preset: ci"));
    EXPECT_FALSE(enamel::isDefaultKeyLine("not_a_key = 1.0"));
}
