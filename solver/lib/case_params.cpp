// Case-file parameters: key table, presets, and the layered TOML parser (see case_params.hpp).
#include "case_params.hpp"

#include "exit_codes.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <variant>

namespace enamel {

// ---------------------------------------------------------------------------------------------
// The key table: the one place where keys, defaults, ranges, units and meanings are defined.
// Columns: name, kind, group, required, default, min, max, minOpen, maxOpen, choices, defaultText,
// unit, doc ("short name: details").
// ---------------------------------------------------------------------------------------------
const std::vector<KeySpec>& caseKeys() {
    constexpr double kSeedMax = 2147483647.0;        // 2^31 - 1
    constexpr double kStepsMax = 4611686018427387904.0;  // 2^62
    constexpr bool O = true;   // open bound
    constexpr bool C = false;  // closed bound
    static const std::vector<KeySpec> keys = {
        // --- physics ---
        {"theta_D", Kind::Real, "physics", true, 0, 0, 45, C, C, "", "", "deg",
         "decussation angle: rods at +theta_D in ply 1 and -theta_D in ply 2"},
        {"Er_over_kd", Kind::Real, "physics", true, 0, 0.1, 1000, C, C, "", "", "E_r/(k d)",
         "rod modulus over interface stiffness: E_r / (k d), k = interface stiffness per area"},
        {"sigma_ru_over_sigma0", Kind::Real, "physics", true, 0, 0, 1e6, O, C, "", "", "sigma0",
         "rod strength: mean tensile strength of a rod element / interface strength sigma0"},
        {"cv", Kind::Real, "physics", false, 0, 0, 1, C, O, "", "", "-",
         "strength scatter: coefficient of variation of rod-element strength (normal distribution, "
         "negative draws redrawn)"},
        {"Gamma_k_over_sigma0sq", Kind::Real, "physics", false, 3, 1, 1e4, C, C, "", "", "sigma0^2/k",
         "interface fracture energy: Gamma_i k / sigma0^2 (>= 1 for a trapezoid law; sets the "
         "fracture length)"},
        {"delta0_over_d", Kind::Real, "physics", false, 0.1, 0, 1, O, C, "", "", "d",
         "interface elastic separation: delta0 = sigma0 / k. In linear kinematics it only scales forces and "
         "displacements, so results depend on it only through the loading rate: what is quasi-static is "
         "(v_app/c_d) (h_s / U_c) << 1 with the initiation displacement U_c proportional to delta0 (README, Model)"},
        {"nu_r", Kind::Real, "physics", false, 0.3, 0, 0.5, C, O, "", "", "-",
         "rod Poisson ratio: sets the torsional stiffness G J"},
        {"section", Kind::Choice, "physics", false, 0, 0, 0, C, C, "hexagon|circle", "hexagon", "-",
         "rod cross-section: hexagon = space-filling hexagon of across-flats width d, circle = "
         "circle of diameter d"},
        {"seed", Kind::Integer, "physics", false, 1, 0, kSeedMax, C, C, "", "", "-",
         "random seed: of the rod-element strengths (mt19937_64 + Box-Muller)"},
        {"rods_breakable", Kind::Bool, "physics", false, 1, 0, 0, C, C, "", "", "-",
         "rods breakable: false keeps every rod element intact"},
        {"interfaces_breakable", Kind::Bool, "physics", false, 1, 0, 0, C, C, "", "", "-",
         "interfaces breakable: false keeps every interface on its elastic branch"},
        {"description", Kind::Text, "physics", false, 0, 0, 0, C, C, "", "", "-",
         "description: free text, copied to the output"},
        // --- numerics ---
        {"w_s_over_d", Kind::Real, "numerics", false, 32, 2, 2000, C, C, "", "", "d",
         "specimen width: along x, the crack growth direction"},
        {"h_s_over_d", Kind::Real, "numerics", false, 16, 2, 2000, C, C, "", "", "d",
         "specimen height: along y, the loading direction"},
        {"a0_over_ws", Kind::Real, "numerics", false, 0.5, 0, 1, O, O, "", "", "w_s",
         "pre-crack length: a0 / w_s, on the mid-plane y = h_s/2 from the left edge"},
        {"h_e_over_d", Kind::Real, "numerics", false, 0.3, 0, 1, O, C, "", "", "d",
         "slice spacing: distance h_e between discrete yz layers (paper: 0.3 coarse, 0.15 fine; "
         "h_e larger than d is an error)"},
        {"crisscross_phase", Kind::Real, "numerics", false, 0, 0, 1, C, O, "", "", "d/sin(theta_D)",
         "crisscross phase: position of the first crisscross point ahead of the pre-crack tip, as a "
         "fraction of the crisscross spacing d/sin(theta_D) (no effect at theta_D = 0)"},
        {"v_app_over_cd", Kind::Real, "numerics", false, 1e-3, 0, 0.1, O, C, "", "", "c_d",
         "loading rate: peak applied velocity at the cracked edge / transverse wave speed c_d"},
        {"rate_factor", Kind::Real, "numerics", false, 1, 0, 1e3, O, C, "", "", "-",
         "loading-rate multiplier: v_app = rate_factor x v_app_over_cd x c_d; the pipeline's half-rate "
         "twins (paper: 50% slower loading) use 0.5 on top of the preset's rate"},
        {"ramp_transits", Kind::Real, "numerics", false, 1, 0, 1e3, C, C, "", "", "h_s/c_d",
         "velocity ramp: duration of the smooth ramp from rest, in transit times h_s/c_d"},
        {"zeta", Kind::Real, "numerics", false, 0.2, 0, 1, C, C, "", "", "-",
         "Rayleigh damping: damping ratio at w_min = pi c_d / h_s (C = a M + b K)"},
        {"dt_factor", Kind::Real, "numerics", false, 0.1, 0, 1, O, C, "", "", "smallest element period",
         "time step: dt / smallest element period (integrator paper; paper value 0.1)"},
        {"integrator", Kind::Choice, "numerics", false, 0, 0, 0, C, C, "paper|lumped", "paper", "-",
         "integrator: paper = Newmark beta 0, consistent mass, H = M + dt/2 C factorised (reference); "
         "lumped = explicit, lumped mass"},
        {"damping_cap", Kind::Real, "numerics", false, 1, 0, 2, O, C, "", "", "-",
         "stiffness damping cap (integrator lumped): b' = min(b, damping_cap / omega_max), i.e. the "
         "stiffness-proportional damping ratio at omega_max is at most damping_cap / 2; a lower cap raises "
         "the stable step"},
        {"linear_solver", Kind::Choice, "numerics", false, 0, 0, 0, C, C, "cholmod|umfpack", "cholmod",
         "-", "linear solver: for H = M + dt/2 C (integrator paper): CHOLMOD Cholesky or UMFPACK LU"},
        {"deletion_rule", Kind::Choice, "numerics", false, 0, 0, 0, C, C, "most_overloaded|all",
         "most_overloaded", "-",
         "rod deletion rule: when several rod elements pass their strength in one step, delete the "
         "most overloaded and re-evaluate, or delete all"},
        {"stop_da_over_d", Kind::Real, "numerics", false, 30, 0, 1e4, O, C, "", "", "d",
         "stop crack advance: the run stops when Delta_a reaches this"},
        {"stop_u_over_d", Kind::Real, "numerics", false, 1e3, 0, 1e6, O, C, "", "", "d",
         "stop displacement: the run stops when the applied displacement at the cracked edge "
         "reaches this"},
        {"max_steps", Kind::Integer, "numerics", false, 0, 0, kStepsMax, C, C, "", "", "steps",
         "step limit: the run stops after this many time steps; 0 = no limit"},
        {"history_every", Kind::Integer, "numerics", false, 0, 0, 1e9, C, C, "", "", "steps",
         "history interval: time steps between /history output rows; 0 = automatic"},
        {"frames_da_over_d", Kind::RealList, "numerics", false, 0, 0, 1e4, C, C, "", "[5, 15, 30]", "d",
         "frames: crack advances Delta_a at which geometry and damage frames are written"},
        {"E_transverse_over_Er", Kind::Real, "numerics", false, 0, 0, 10, C, C, "", "", "E_r",
         "transverse modulus: sets c_d = sqrt(E_transverse / rho_r); 0 = measure it with a short "
         "elastic run of the model"},
        {"threads", Kind::Integer, "numerics", false, 0, 0, 1024, C, C, "", "", "-",
         "threads: worker threads; 0 = automatic, one per 30k DOF up to all cores (results do not depend on it)"},
        {"checkpoint_interval_s", Kind::Real, "numerics", false, 0, 0, 1e7, C, C, "", "", "s (wall clock)",
         "checkpoint interval: wall-clock seconds between checkpoints; 0 = none"},
    };
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
    // reduced: dt_factor 0.22 with damping_cap 0.5 is the fastest setting that `make bench` found to leave the
    // error against `paper` unchanged (theta30: L2 1.55% vs 1.49% at dt_factor 0.1; 2.6x faster)
    {"reduced",
     "w_s_over_d = 40\nh_s_over_d = 20\nh_e_over_d = 0.3\nv_app_over_cd = 2.5e-3\nintegrator = \"lumped\"\n"
     "dt_factor = 0.22\ndamping_cap = 0.5\n"
     "stop_da_over_d = 12\nframes_da_over_d = [3, 6, 12]\n"},
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

// ---------------------------------------------------------------------------------------------
// Key -> CaseParams field. Checked against caseKeys() (same names, same order, matching kinds)
// before every parse, so the struct and the table cannot drift apart silently.
// ---------------------------------------------------------------------------------------------
using Field = std::variant<double CaseParams::*, std::int64_t CaseParams::*, bool CaseParams::*,
                           std::string CaseParams::*, std::vector<double> CaseParams::*>;
struct Binding {
    const char* name;
    Field field;
};
const std::vector<Binding>& bindings() {
    using P = CaseParams;
    static const std::vector<Binding> b = {
        {"theta_D", &P::theta_D},
        {"Er_over_kd", &P::Er_over_kd},
        {"sigma_ru_over_sigma0", &P::sigma_ru_over_sigma0},
        {"cv", &P::cv},
        {"Gamma_k_over_sigma0sq", &P::Gamma_k_over_sigma0sq},
        {"delta0_over_d", &P::delta0_over_d},
        {"nu_r", &P::nu_r},
        {"section", &P::section},
        {"seed", &P::seed},
        {"rods_breakable", &P::rods_breakable},
        {"interfaces_breakable", &P::interfaces_breakable},
        {"description", &P::description},
        {"w_s_over_d", &P::w_s_over_d},
        {"h_s_over_d", &P::h_s_over_d},
        {"a0_over_ws", &P::a0_over_ws},
        {"h_e_over_d", &P::h_e_over_d},
        {"crisscross_phase", &P::crisscross_phase},
        {"v_app_over_cd", &P::v_app_over_cd},
        {"rate_factor", &P::rate_factor},
        {"ramp_transits", &P::ramp_transits},
        {"zeta", &P::zeta},
        {"dt_factor", &P::dt_factor},
        {"integrator", &P::integrator},
        {"damping_cap", &P::damping_cap},
        {"linear_solver", &P::linear_solver},
        {"deletion_rule", &P::deletion_rule},
        {"stop_da_over_d", &P::stop_da_over_d},
        {"stop_u_over_d", &P::stop_u_over_d},
        {"max_steps", &P::max_steps},
        {"history_every", &P::history_every},
        {"frames_da_over_d", &P::frames_da_over_d},
        {"E_transverse_over_Er", &P::E_transverse_over_Er},
        {"threads", &P::threads},
        {"checkpoint_interval_s", &P::checkpoint_interval_s},
    };
    return b;
}

std::size_t variantIndexOf(Kind kind) {
    switch (kind) {
        case Kind::Real: return 0;
        case Kind::Integer: return 1;
        case Kind::Bool: return 2;
        case Kind::Choice:
        case Kind::Text: return 3;
        case Kind::RealList: return 4;
    }
    return 99;
}

void checkBindings() {
    const auto& keys = caseKeys();
    const auto& b = bindings();
    if (keys.size() != b.size()) throw std::logic_error("case_params: key table and CaseParams fields differ in number");
    for (std::size_t i = 0; i < keys.size(); ++i)
        if (std::strcmp(keys[i].name, b[i].name) != 0 || variantIndexOf(keys[i].kind) != b[i].field.index())
            throw std::logic_error(std::string("case_params: key table and CaseParams fields differ at '") +
                                   keys[i].name + "'");
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

std::vector<std::string> splitChoices(const char* choices) {
    std::vector<std::string> out;
    std::string s = choices;
    std::size_t start = 0;
    while (start <= s.size()) {
        const std::size_t bar = std::min(s.find('|', start), s.size());
        out.push_back(s.substr(start, bar - start));
        start = bar + 1;
    }
    return out;
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
            const auto c = splitChoices(s.choices);
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

std::string formatDefault(const KeySpec& s) {
    if (s.required) return "required";
    switch (s.kind) {
        case Kind::Real: return formatNumber(s.defaultValue);
        case Kind::Integer: return formatInteger(s.defaultValue);
        case Kind::Bool: return s.defaultValue != 0 ? "true" : "false";
        case Kind::Choice:
        case Kind::Text: return quote(s.defaultText);
        case Kind::RealList: return s.defaultText;
    }
    return "";
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
        // The slice spacing is checked here and again in checkCrossKeys; say why in words.
        const bool slicesTooFar = std::strcmp(s.name, "h_e_over_d") == 0 && x > s.maxValue;
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
void applyKey(CaseParams& p, const KeySpec& s, const Field& field, const toml::node& v, const std::string& src) {
    switch (s.kind) {
        case Kind::Real: p.*std::get<0>(field) = readReal(src, s, v, v); break;
        case Kind::Integer: {
            auto i = v.as_integer();
            if (!i) throwWrongType(src, s, v);
            const std::int64_t x = i->get();
            const auto lo = static_cast<std::int64_t>(s.minValue), hi = static_cast<std::int64_t>(s.maxValue);
            if ((s.minOpen ? x <= lo : x < lo) || (s.maxOpen ? x >= hi : x > hi))
                throwOutOfRange(src, s, v, "is out of range");
            p.*std::get<1>(field) = x;
            break;
        }
        case Kind::Bool: {
            auto b = v.as_boolean();
            if (!b) throwWrongType(src, s, v);
            p.*std::get<2>(field) = b->get();
            break;
        }
        case Kind::Choice: {
            auto str = v.as_string();
            if (!str) throwWrongType(src, s, v);
            const auto c = splitChoices(s.choices);
            if (std::find(c.begin(), c.end(), str->get()) == c.end()) throwOutOfRange(src, s, v, "is not a valid choice");
            p.*std::get<3>(field) = str->get();
            break;
        }
        case Kind::Text: {
            auto str = v.as_string();
            if (!str) throwWrongType(src, s, v);
            p.*std::get<3>(field) = str->get();
            break;
        }
        case Kind::RealList: {
            auto a = v.as_array();
            if (!a) throwWrongType(src, s, v);
            std::vector<double> xs;
            for (const toml::node& element : *a) xs.push_back(readReal(src, s, element, v));
            p.*std::get<4>(field) = xs;
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
        applyKey(p, *it, bindings()[index].field, value, src);
        given[index] = true;
    }
}

// Key defaults as a TOML layer, so that they pass the same checks as any case file.
std::string defaultsToml() {
    std::string out;
    for (const KeySpec& s : caseKeys()) {
        if (s.required) continue;
        std::string value;
        switch (s.kind) {
            case Kind::Real: value = formatTomlReal(s.defaultValue); break;
            case Kind::Integer: value = formatInteger(s.defaultValue); break;
            case Kind::Bool: value = s.defaultValue != 0 ? "true" : "false"; break;
            case Kind::Choice:
            case Kind::Text: value = quote(s.defaultText); break;
            case Kind::RealList: value = s.defaultText; break;
        }
        out += std::string(s.name) + " = " + value + "\n";
    }
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
    if (p.h_e_over_d > 1)
        fail("key 'h_e_over_d' = " + formatNumber(p.h_e_over_d) + " is out of range (h_e larger than d); allowed (0, 1] (d)");
    // Slices at x_k = k h_e for 0 <= x_k <= w_s.
    const double slices = std::floor(p.w_s_over_d / p.h_e_over_d + 1e-9) + 1;
    if (slices < 2)
        fail("w_s_over_d = " + formatNumber(p.w_s_over_d) + " with h_e_over_d = " + formatNumber(p.h_e_over_d) +
             " gives " + formatNumber(slices) + " slice; at least 2 are needed");
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
    const auto& keys = caseKeys();
    std::string group;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const KeySpec& s = keys[i];
        if (group != s.group) out += "\n# --- " + (group = s.group) + " ---\n";
        const Field& f = bindings()[i].field;
        std::string value;
        switch (s.kind) {
            case Kind::Real: value = formatTomlReal(p.*std::get<0>(f)); break;
            case Kind::Integer: value = std::to_string(p.*std::get<1>(f)); break;
            case Kind::Bool: value = p.*std::get<2>(f) ? "true" : "false"; break;
            case Kind::Choice:
            case Kind::Text: value = quote(p.*std::get<3>(f)); break;
            case Kind::RealList: {
                value = "[";
                const auto& xs = p.*std::get<4>(f);
                for (std::size_t j = 0; j < xs.size(); ++j) value += (j ? ", " : "") + formatTomlReal(xs[j]);
                value += "]";
                break;
            }
        }
        out += std::string(s.name) + " = " + value + "\n";
    }
    return out;
}

}  // namespace

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
    checkBindings();
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
