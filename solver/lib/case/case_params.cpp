// Case-file parameters: key table, presets, and the layered TOML parser (see case_params.hpp).
#include "case/case_params.hpp"

#include "base/exit_codes.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>
#include <variant>

namespace enamel {

// ---------------------------------------------------------------------------------------------
// The key table: ENAMEL_CASE_KEYS (case_params.hpp) as data.
// ---------------------------------------------------------------------------------------------
namespace {

// Whether end 0 (min) or 1 (max) of `bounds` ("[]", "[)", "(]", "()") is open; any other text does not
// compile (the table below is a constant expression).
constexpr bool isOpenEnd(const char* bounds, int end) {
    const bool valid = (bounds[0] == '[' || bounds[0] == '(') && (bounds[1] == ']' || bounds[1] == ')') &&
                       bounds[2] == '\0';
    return valid ? bounds[end] == (end == 0 ? '(' : ')')
                 : throw std::logic_error("case_params: bounds must be one of \"[]\" \"[)\" \"(]\" \"()\"");
}

// The names of a Choice key's enum, "" for any other kind; a Choice key whose field is not an enum, or an enum
// field of another kind, does not compile.
template <class Field>
constexpr const char* choicesOf(Kind kind) {
    if constexpr (std::is_enum_v<Field>)
        return kind == Kind::Choice ? enumNamesText(Field{})
                                    : throw std::logic_error("case_params: an enum field is a Choice key");
    else
        return kind != Kind::Choice ? "" : throw std::logic_error("case_params: a Choice key's field is an enum");
}

// A Choice key's field as the index of its enumerator, and back.
template <auto Member>
std::size_t getChoice(const CaseParams& p) {
    return static_cast<std::size_t>(p.*Member);
}
template <auto Member>
void setChoice(CaseParams& p, std::size_t index) {
    using Enum = std::remove_reference_t<decltype(p.*Member)>;
    p.*Member = static_cast<Enum>(index);
}

// The KeyField of a member: the member itself, or a ChoiceField for an enum.
template <auto Member>
constexpr KeyField keyFieldOf() {
    using Field = std::remove_reference_t<decltype(std::declval<CaseParams&>().*Member)>;
    if constexpr (std::is_enum_v<Field>)
        return ChoiceField{&getChoice<Member>, &setChoice<Member>};
    else
        return Member;
}

#define ENAMEL_CASE_KEY_SPEC(name, kind, group, need, default_, bounds, min, max, unit, doc)                   \
    KeySpec{#name, Kind::kind, #group, Need::need == Need::required, min, max, isOpenEnd(bounds, 0),       \
            isOpenEnd(bounds, 1), choicesOf<decltype(CaseParams::name)>(Kind::kind), unit, doc,            \
            keyFieldOf<&CaseParams::name>()},
constexpr KeySpec kCaseKeys[] = {ENAMEL_CASE_KEYS(ENAMEL_CASE_KEY_SPEC)};
#undef ENAMEL_CASE_KEY_SPEC

}  // namespace

const std::vector<KeySpec>& caseKeys() {
    static const std::vector<KeySpec> keys(std::begin(kCaseKeys), std::end(kCaseKeys));
    return keys;
}

// ---------------------------------------------------------------------------------------------
// Presets: numerics only (specimen size, mesh, loading rate, stop criterion, frames).
// This is the one table to edit; the README section "Presets" states what each sets and why.
// ---------------------------------------------------------------------------------------------
namespace {
struct Preset {
    const char* name;
    const char* toml;
};
const Preset kPresets[] = {
    // ci: seconds to a minute per case with the lumped scheme; (v_app/c_d) h_s / U_c ~ 0.025
    {"ci",
     "w_s_over_d = 16\nh_s_over_d = 8\nh_e_over_d = 0.3\nv_app_over_cd = 2e-3\nintegrator = \"lumped\"\n"
     "stop_da_over_d = 5\nframes_da_over_d = [1, 2.5, 5]\n"},
    // reduced: dt_factor 0.22 (below the implicit damping's limit 0.30; damping_cap 0.5 keeps it stable for the
    // capped alternative too); the same R-curve as `paper`'s record within 0.3 % (docs/results.md)
    {"reduced",
     "w_s_over_d = 40\nh_s_over_d = 20\nh_e_over_d = 0.3\nv_app_over_cd = 2.5e-3\nintegrator = \"lumped\"\n"
     "dt_factor = 0.22\ndamping_cap = 0.5\n"
     "stop_da_over_d = 12\nframes_da_over_d = [3, 6, 12]\n"},
    // converged: 80 x 80 d, within 2.3 % of 100 d on theta30's mean R but one configuration 12 % below the paper's
    // 200 d (not shown size-converged: docs/results.md), at the paper's loading rate and the fast scheme, from the
    // static elastic solution at 0.95 of the first damage
    {"converged",
     "w_s_over_d = 80\nh_s_over_d = 80\nh_e_over_d = 0.3\nv_app_over_cd = 1e-3\nintegrator = \"lumped\"\n"
     "dt_factor = 0.22\ndamping_cap = 0.5\nstatic_start = 0.95\n"
     "stop_da_over_d = 30\nframes_da_over_d = [5, 15, 30]\n"},
    {"paper",
     "w_s_over_d = 200\nh_s_over_d = 200\nh_e_over_d = 0.3\nv_app_over_cd = 1e-3\nintegrator = \"paper\"\n"
     "stop_da_over_d = 30\nframes_da_over_d = [5, 15, 30]\n"},
};
}  // namespace

std::vector<std::string> presetNames() {
    std::vector<std::string> names;
    for (const Preset& p : kPresets) names.emplace_back(p.name);
    return names;
}

namespace {

// The CaseParams field of key s, as the type of its kind (s.field holds a member of that type).
template <Kind K>
typename KeyValue<K>::type& fieldOf(CaseParams& p, const KeySpec& s) {
    return p.*std::get<typename KeyValue<K>::type CaseParams::*>(s.field);
}
template <Kind K>
const typename KeyValue<K>::type& fieldOf(const CaseParams& p, const KeySpec& s) {
    return p.*std::get<typename KeyValue<K>::type CaseParams::*>(s.field);
}

// ---------------------------------------------------------------------------------------------
// Formatting
// ---------------------------------------------------------------------------------------------

// Shortest text that reads back to x: integers below 1e4 plainly ("1000"), otherwise %g with a
// tidy exponent ("1e6", "1e-05" -> "1e-5").
std::string formatNumber(double x) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    char buf[64];
    if (x == std::floor(x) && std::fabs(x) < 1e4) {
        std::snprintf(buf, sizeof buf, "%.0f", x);
        return buf;
    }
    for (int p = 1; p <= 17; ++p) {
        std::snprintf(buf, sizeof buf, "%.*g", p, x);
        if (std::strtod(buf, nullptr) == x) break;
    }
    std::string s = buf;
    const auto e = s.find('e');
    if (e == std::string::npos) return s;
    std::string mantissa = s.substr(0, e), exponent = s.substr(e + 1);
    std::string sign = exponent[0] == '-' ? "-" : "";
    exponent.erase(0, exponent.find_first_not_of("+-"));
    exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
    return mantissa + "e" + sign + exponent;
}

// A TOML float literal for x (finite): "60" -> "60.0".
std::string formatTomlReal(double x) {
    std::string s = formatNumber(x);
    if (s.find_first_of(".en") == std::string::npos) s += ".0";
    return s;
}

std::string formatInteger(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(x));
    return buf;
}

// A TOML basic string: "..." with escapes.
std::string quote(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            default:
                if (c < 0x20 || c == 0x7f) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += static_cast<char>(c);
                }
        }
    }
    return out + "\"";
}

// A TOML node as the user would have written it, for messages.
std::string renderNode(const toml::node& v) {
    if (auto s = v.as_string()) return quote(s->get());
    if (auto i = v.as_integer()) return std::to_string(i->get());
    if (auto f = v.as_floating_point()) return formatNumber(f->get());
    if (auto b = v.as_boolean()) return b->get() ? "true" : "false";
    if (auto a = v.as_array()) {
        std::string out = "[";
        for (std::size_t i = 0; i < a->size(); ++i) out += (i ? ", " : "") + renderNode(*a->get(i));
        return out + "]";
    }
    if (auto t = v.as_table()) {
        std::string out = "{";
        bool first = true;
        for (auto&& [k, sub] : *t) {
            out += (first ? " " : ", ") + std::string(k.str()) + " = " + renderNode(sub);
            first = false;
        }
        return out + " }";
    }
    std::ostringstream os;  // dates and times
    v.visit([&](auto&& x) { os << x; });
    return os.str();
}

std::string formatBound(const KeySpec& s, double x) {
    return s.kind == Kind::Integer ? formatInteger(x) : formatNumber(x);
}

std::string formatInterval(const KeySpec& s) {
    return std::string(s.minOpen ? "(" : "[") + formatBound(s, s.minValue) + ", " + formatBound(s, s.maxValue) +
           (s.maxOpen ? ")" : "]");
}

// What a key allows, e.g. "[0, 45]", "each in [0, 1e4]", "one of \"paper\", \"lumped\"".
std::string formatAllowed(const KeySpec& s) {
    switch (s.kind) {
        case Kind::Real:
        case Kind::Integer: return formatInterval(s);
        case Kind::RealList: return "each in " + formatInterval(s);
        case Kind::Bool: return "true or false";
        case Kind::Text: return "any string";
        case Kind::Choice: {
            std::string out = "one of ";
            const auto c = splitEnumNames(s.choices);
            for (std::size_t i = 0; i < c.size(); ++i) out += (i ? ", " : "") + quote(c[i]);
            return out;
        }
    }
    return "";
}

std::string unitSuffix(const KeySpec& s) {
    return std::strcmp(s.unit, "-") == 0 ? "" : std::string(" (") + s.unit + ")";
}

std::string formatExpected(const KeySpec& s) {
    switch (s.kind) {
        case Kind::Real: return "a real number in " + formatInterval(s) + unitSuffix(s);
        case Kind::Integer: return "an integer in " + formatInterval(s) + unitSuffix(s);
        case Kind::RealList: return "a list of real numbers, each in " + formatInterval(s) + unitSuffix(s);
        case Kind::Bool: return "true or false";
        case Kind::Text: return "a string";
        case Kind::Choice: return "a string, " + formatAllowed(s);
    }
    return "";
}

// The value of key s in p as TOML text, each real written by formatReal: formatTomlReal in the effective
// case ("32.0", "[5.0, 15.0, 30.0]"), formatNumber in `enamel-dem keys` ("32", "[5, 15, 30]").
std::string formatValue(const CaseParams& p, const KeySpec& s, std::string (*formatReal)(double)) {
    switch (s.kind) {
        case Kind::Real: return formatReal(fieldOf<Kind::Real>(p, s));
        case Kind::Integer: return std::to_string(fieldOf<Kind::Integer>(p, s));
        case Kind::Bool: return fieldOf<Kind::Bool>(p, s) ? "true" : "false";
        case Kind::Choice: return quote(splitEnumNames(s.choices).at(std::get<ChoiceField>(s.field).get(p)));
        case Kind::Text: return quote(fieldOf<Kind::Text>(p, s));
        case Kind::RealList: {
            std::string out = "[";
            const auto& xs = fieldOf<Kind::RealList>(p, s);
            for (std::size_t j = 0; j < xs.size(); ++j) out += (j ? ", " : "") + formatReal(xs[j]);
            return out + "]";
        }
    }
    return "";
}

// The key's default as `enamel-dem keys` shows it: its value in CaseParams{}, or "required".
std::string formatDefault(const KeySpec& s) {
    static const CaseParams defaults;
    return s.required ? "required" : formatValue(defaults, s, formatNumber);
}

std::string shortDoc(const KeySpec& s) {
    const std::string doc = s.doc;
    return doc.substr(0, doc.find(':'));
}

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

// Levenshtein distance, case-insensitive.
std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                              std::tolower(static_cast<unsigned char>(b[j - 1]));
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

// Suggest the key closest to `name` by edit distance when it is close (at most max(2, n/3) edits
// and fewer than n, n = name length), or a key that contains `name` (n >= 3, e.g. "theta").
[[noreturn]] void throwUnknownKey(const std::string& src, const std::string& name) {
    auto lower = [](std::string s) {
        for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return s;
    };
    const KeySpec* best = nullptr;
    std::size_t bestDistance = std::numeric_limits<std::size_t>::max();
    for (const KeySpec& s : caseKeys()) {
        const std::size_t d = editDistance(name, s.name);
        const bool close = d <= std::max<std::size_t>(2, name.size() / 3) && d < name.size();
        const bool contains = name.size() >= 3 && lower(s.name).find(lower(name)) != std::string::npos;
        if ((close || contains) && d < bestDistance) bestDistance = d, best = &s;
    }
    const std::string hint = best ? std::string("did you mean '") + best->name + "'? " : "";
    throw CaseError(exit_code::unknown_key,
                    src + ": unknown key '" + name + "' (" + hint + "'enamel-dem keys' lists all keys)");
}

[[noreturn]] void throwWrongType(const std::string& src, const KeySpec& s, const toml::node& v) {
    throw CaseError(exit_code::wrong_type, src + ": key '" + s.name + "' = " + renderNode(v) +
                                               " has the wrong type; expected " + formatExpected(s));
}

[[noreturn]] void throwOutOfRange(const std::string& src, const KeySpec& s, const toml::node& v,
                                  const std::string& what) {
    throw CaseError(exit_code::out_of_range, src + ": key '" + s.name + "' = " + renderNode(v) + " " + what +
                                                 "; allowed " + formatAllowed(s) + unitSuffix(s));
}

bool inInterval(const KeySpec& s, double x) {
    const bool aboveMin = s.minOpen ? x > s.minValue : x >= s.minValue;
    const bool belowMax = s.maxOpen ? x < s.maxValue : x <= s.maxValue;
    return aboveMin && belowMax;
}

// A real value (integers accepted) of key s, or throw: not a number -> wrong_type; NaN/Inf or
// outside the interval -> out_of_range.
double readReal(const std::string& src, const KeySpec& s, const toml::node& v, const toml::node& shown) {
    double x = 0;
    if (auto i = v.as_integer()) x = static_cast<double>(i->get());
    else if (auto f = v.as_floating_point()) x = f->get();
    else throwWrongType(src, s, shown);
    if (!std::isfinite(x)) throwOutOfRange(src, s, shown, "is not finite");
    if (!inInterval(s, x)) {
        // h_e larger than d: say why in words.
        const bool slicesTooFar = s.field == KeyField(&CaseParams::h_e_over_d) && x > s.maxValue;
        throwOutOfRange(src, s, shown, slicesTooFar ? "is out of range (h_e larger than d)" : "is out of range");
    }
    return x;
}

// ---------------------------------------------------------------------------------------------
// Layers
// ---------------------------------------------------------------------------------------------

toml::table parseToml(const std::string& text, const std::string& src) {
    try {
        return toml::parse(text, src);
    } catch (const toml::parse_error& e) {
        const auto& at = e.source().begin;
        throw CaseError(exit_code::malformed_toml, src + ":" + std::to_string(at.line) + ":" +
                                                       std::to_string(at.column) +
                                                       ": malformed TOML: " + std::string(e.description()));
    }
}

// Set the field of key s from the TOML value v, checking type and range.
void applyKey(CaseParams& p, const KeySpec& s, const toml::node& v, const std::string& src) {
    switch (s.kind) {
        case Kind::Real: fieldOf<Kind::Real>(p, s) = readReal(src, s, v, v); break;
        case Kind::Integer: {
            auto i = v.as_integer();
            if (!i) throwWrongType(src, s, v);
            const std::int64_t x = i->get();
            const auto lo = static_cast<std::int64_t>(s.minValue), hi = static_cast<std::int64_t>(s.maxValue);
            if ((s.minOpen ? x <= lo : x < lo) || (s.maxOpen ? x >= hi : x > hi))
                throwOutOfRange(src, s, v, "is out of range");
            fieldOf<Kind::Integer>(p, s) = x;
            break;
        }
        case Kind::Bool: {
            auto b = v.as_boolean();
            if (!b) throwWrongType(src, s, v);
            fieldOf<Kind::Bool>(p, s) = b->get();
            break;
        }
        case Kind::Choice: {
            auto str = v.as_string();
            if (!str) throwWrongType(src, s, v);
            const auto c = splitEnumNames(s.choices);
            const auto it = std::find(c.begin(), c.end(), str->get());
            if (it == c.end()) throwOutOfRange(src, s, v, "is not a valid choice");
            std::get<ChoiceField>(s.field).set(p, static_cast<std::size_t>(it - c.begin()));
            break;
        }
        case Kind::Text: {
            auto str = v.as_string();
            if (!str) throwWrongType(src, s, v);
            fieldOf<Kind::Text>(p, s) = str->get();
            break;
        }
        case Kind::RealList: {
            auto a = v.as_array();
            if (!a) throwWrongType(src, s, v);
            std::vector<double> xs;
            for (const toml::node& element : *a) xs.push_back(readReal(src, s, element, v));
            fieldOf<Kind::RealList>(p, s) = xs;
            break;
        }
    }
}

// Apply every key of one layer (preset, case file, or one --set). Marks the keys it sets.
void applyLayer(CaseParams& p, std::vector<bool>& given, const toml::table& layer, const std::string& src,
                bool numericsOnly) {
    const auto& keys = caseKeys();
    for (auto&& [key, value] : layer) {
        const std::string name(key.str());
        const auto it = std::find_if(keys.begin(), keys.end(), [&](const KeySpec& s) { return name == s.name; });
        if (it == keys.end()) {
            if (value.is_table())
                throw CaseError(exit_code::unknown_key,
                                src + ": key '" + name + "' is a table; case files are flat ('key = value' lines, "
                                "no [sections] or dotted keys; 'enamel-dem keys' lists all keys)");
            throwUnknownKey(src, name);
        }
        if (numericsOnly && std::strcmp(it->group, "numerics") != 0)
            throw std::logic_error(src + ": presets may set numerics keys only, not '" + name + "'");
        const std::size_t index = static_cast<std::size_t>(it - keys.begin());
        applyKey(p, *it, value, src);
        given[index] = true;
    }
}

// Key defaults (the optional keys' values in CaseParams{}) as a TOML layer, so that they pass the same
// checks as any case file.
std::string defaultsToml() {
    const CaseParams defaults;
    std::string out;
    for (const KeySpec& s : caseKeys())
        if (!s.required) out += std::string(s.name) + " = " + formatValue(defaults, s, formatTomlReal) + "\n";
    return out;
}

// "--set key=value" -> a one-key table. The value is read as TOML; if it is not valid TOML it is
// taken as a string ("integrator=lumped").
toml::table parseSet(const std::string& set) {
    const auto eq = set.find('=');
    auto trim = [](std::string s) {
        const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
        return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    if (eq == std::string::npos)
        throw CaseError(exit_code::usage, "--set '" + set + "': expected key=value (e.g. --set theta_D=15)");
    const std::string key = trim(set.substr(0, eq)), value = trim(set.substr(eq + 1));
    if (key.empty() || key.find_first_of(" \t\"'.[]=#") != std::string::npos)
        throw CaseError(exit_code::usage, "--set '" + set + "': expected key=value with a plain key name");
    try {
        toml::table parsed = toml::parse(quote(key) + " = " + value + "\n");
        if (parsed.size() == 1 && parsed.contains(key)) return parsed;
    } catch (const toml::parse_error&) {
    }
    // Taken as a string: it must still be text that TOML can hold (valid UTF-8), or the effective case
    // (tomlText) would not read back. quote() escapes the control characters.
    try {
        return toml::parse(quote(key) + " = " + quote(value) + "\n");
    } catch (const toml::parse_error&) {
        throw CaseError(exit_code::usage, "--set '" + set + "': not valid UTF-8 text");
    }
}

void checkCrossKeys(const CaseParams& p, const std::string& src) {
    auto fail = [&](const std::string& what) { throw CaseError(exit_code::out_of_range, src + ": " + what); };
    // a0 = a0_over_ws w_s < w_s (guaranteed by the range of a0_over_ws; kept for clarity).
    if (!(p.a0() < p.w_s_over_d))
        fail("pre-crack a0 = " + formatNumber(p.a0()) + " d is not shorter than w_s = " + formatNumber(p.w_s_over_d) + " d");
    // Trapezoid plateau end delta1 = Gamma/sigma0 + (delta0 - L)/2 >= delta0  <=>  L/delta0 <= 2 G - 1.
    const double maxSoftening = 2.0 * p.Gamma_k_over_sigma0sq - 1.0;
    if (!(p.softening_over_delta0 <= maxSoftening))
        fail("key 'softening_over_delta0' = " + formatNumber(p.softening_over_delta0) +
             " is out of range; allowed (0, 2 Gamma_k_over_sigma0sq - 1] = (0, " + formatNumber(maxSoftening) +
             "] with Gamma_k_over_sigma0sq = " + formatNumber(p.Gamma_k_over_sigma0sq) +
             " (above it the plateau end delta1 falls below delta0)");
    // Slices at x_k = k h_e for 0 <= x_k <= w_s.
    const double slices = std::floor(p.w_s_over_d / p.h_e_over_d + 1e-9) + 1;
    if (slices < 2)
        fail("w_s_over_d = " + formatNumber(p.w_s_over_d) + " with h_e_over_d = " + formatNumber(p.h_e_over_d) +
             " gives " + formatNumber(slices) + " slice; at least 2 are needed");
    // A reduced far field needs its full band: at least 1 d on each side of the crack plane.
    if (p.far_field_slices > 1 && !(p.full_half_height_over_d >= 1))
        fail("key 'full_half_height_over_d' = " + formatNumber(p.full_half_height_over_d) +
             " is out of range; allowed [1, 1000] d when far_field_slices = " +
             formatNumber(static_cast<double>(p.far_field_slices)) + " > 1 (the full band around the crack plane)");
}

// The effective case as flat TOML, every key, in table order.
std::string writeToml(const CaseParams& p, const std::vector<std::string>& sets) {
    // Text for a '#' comment line: TOML comments hold no control characters but tab, and only valid
    // UTF-8 (a file name need not be); anything else would make tomlText unreadable.
    auto oneLine = [](std::string s) {
        for (char& c : s)
            if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f) c = ' ';
        try {
            static_cast<void>(toml::parse("#" + s));  // throws on text a comment cannot hold
        } catch (const toml::parse_error&) {
            for (char& c : s)
                if (static_cast<unsigned char>(c) >= 0x80) c = '?';
        }
        return s;
    };
    std::string out = "# enamel-dem effective case (key defaults < preset < case file < --set)\n";
    out += "# source: " + oneLine(p.sourceName) + "\n";
    out += "# preset: " + (p.presetName.empty() ? std::string("(none)") : p.presetName) + "\n";
    for (const std::string& s : sets) out += "# --set " + oneLine(s) + "\n";
    std::string group;
    for (const KeySpec& s : caseKeys()) {
        if (group != s.group) out += "\n# --- " + (group = s.group) + " ---\n";
        out += std::string(s.name) + " = " + formatValue(p, s, formatTomlReal) + "\n";
    }
    return out;
}

}  // namespace

bool isResultNeutral(const std::string& key) {
    for (const char* k : kResultNeutralKeys)
        if (key == k) return true;
    return false;
}

bool isDefaultKeyLine(const std::string& line) {
    static const CaseParams defaults;
    const std::string name = line.substr(0, line.find(" = "));
    for (const KeySpec& s : caseKeys())
        if (name == s.name) return !s.required && line == name + " = " + formatValue(defaults, s, formatTomlReal);
    return false;
}

std::string formatKeysMarkdown() {
    auto cell = [](std::string s) {
        std::string out;
        for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
        return out;
    };
    std::string out = "| key | group | default | allowed | unit / normalisation | meaning |\n"
                      "|---|---|---|---|---|---|\n";
    for (const KeySpec& s : caseKeys())
        out += "| `" + std::string(s.name) + "` | " + s.group + " | " + cell(formatDefault(s)) + " | " +
               cell(formatAllowed(s)) + " | " + cell(s.unit) + " | " + cell(s.doc) + " |\n";
    return out;
}

CaseParams parseCase(const std::string& tomlText, const std::string& sourceName, const std::string& preset,
                     const std::vector<std::string>& sets) {
    const auto& keys = caseKeys();

    const Preset* chosen = nullptr;
    for (const Preset& p : kPresets)
        if (preset == p.name) chosen = &p;
    if (!preset.empty() && !chosen) {
        std::string allowed;
        for (const std::string& n : presetNames()) allowed += (allowed.empty() ? "" : ", ") + n;
        throw CaseError(exit_code::usage, "unknown preset '" + preset + "'; allowed presets: " + allowed);
    }

    CaseParams p;
    std::vector<bool> given(keys.size(), false);
    std::vector<bool> ignored(keys.size(), false);
    applyLayer(p, ignored, parseToml(defaultsToml(), "key defaults"), "key defaults", false);
    if (chosen) applyLayer(p, given, parseToml(chosen->toml, "preset '" + preset + "'"), "preset '" + preset + "'", true);
    applyLayer(p, given, parseToml(tomlText, sourceName), sourceName, false);
    for (const std::string& set : sets) applyLayer(p, given, parseSet(set), "--set " + set, false);

    for (std::size_t i = 0; i < keys.size(); ++i)
        if (keys[i].required && !given[i])
            throw CaseError(exit_code::unknown_key, sourceName + ": missing required key '" + keys[i].name + "' (" +
                                                        shortDoc(keys[i]) +
                                                        (std::strcmp(keys[i].unit, "-") ? ", " + std::string(keys[i].unit) : "") +
                                                        "; allowed " + formatAllowed(keys[i]) + ")");
    checkCrossKeys(p, sourceName);

    p.sourceName = sourceName;
    p.presetName = preset;
    p.tomlText = writeToml(p, sets);
    return p;
}

CaseParams loadCase(const std::string& path, const std::string& preset, const std::vector<std::string>& sets) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw CaseError(exit_code::missing_file, "cannot open case file '" + path + "': " + std::strerror(errno));
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
    const bool failed = std::ferror(f);
    const int err = errno;
    std::fclose(f);
    if (failed) throw CaseError(exit_code::missing_file, "cannot read case file '" + path + "': " + std::strerror(err));
    return parseCase(text, path, preset, sets);
}

}  // namespace enamel
